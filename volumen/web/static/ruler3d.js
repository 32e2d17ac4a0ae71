// The 3-D picture's ruler: with it on, two clicks on the picture pick two points of the first visible surface
// under them (pick.json: the server casts the clicked pixel's ray through the served volume, the one this page
// draws, with the page's scene and camera: volumen.measure.pick) and make a ruler between them, drawn over the
// rendering with its length, and on the slice views that cut it (measure.js).

import { postJSON } from './api.js';
import { project } from './camera.js';
import { add } from './linalg.js';
import { caption } from './measure.js';

/** @import { SliceMeasures } from './measure.js' */
/** @import { Viewer } from './viewer.js' */
/** @import { Vec3 } from './linalg.js' */
/** @import { Size } from './camera.js' */

const SVG = 'http://www.w3.org/2000/svg';

export class PictureRuler {
  /**
   * @param {Viewer} viewer
   * @param {SliceMeasures} measures  where the rulers are kept
   * @param {HTMLElement} root  the 3-D view's element (its canvas, the button and the drawing go there)
   */
  constructor(viewer, measures, root) {
    this.viewer = viewer;
    this.measures = measures;
    this.active = false;
    /** @type {Vec3 | null} the first point picked, until the second */
    this.pending = null;
    this.picking = Promise.resolve();
    this.button = document.createElement('button');
    this.button.className = 'ruler3d';
    this.button.textContent = '3-D ruler';
    this.button.addEventListener('click', () => this.setActive(!this.active));
    this.svg = /** @type {SVGSVGElement} */ (document.createElementNS(SVG, 'svg'));
    this.svg.classList.add('ruler3d-layer');
    root.append(this.svg, this.button);
    root.addEventListener('pointerdown', (e) => this.down(e), { capture: true });   // before the orbit gesture
    viewer.onChange((what) => { if (what === 'drawn' || what === 'camera') this.draw(); });
    measures.drawn.push(() => this.draw());
  }

  /** @param {boolean} on */
  setActive(on) {
    this.active = on;
    this.pending = null;
    this.button.classList.toggle('on', on);
    this.draw();
  }

  /** @param {PointerEvent} e */
  down(e) {
    if (!this.active || e.button !== 0 || e.target !== this.viewer.gl.canvas) return;
    e.stopPropagation();
    e.preventDefault();
    const canvas = /** @type {HTMLCanvasElement} */ (this.viewer.gl.canvas), box = canvas.getBoundingClientRect();
    const x = Math.floor((e.clientX - box.left) * canvas.width / box.width) + 0.5;   // the pixel's centre
    const y = Math.floor((e.clientY - box.top) * canvas.height / box.height) + 0.5;
    this.picking = this.pick(x, y);
  }

  /** @param {number} x @param {number} y picture pixels */
  pick(x, y) {
    const v = this.viewer, canvas = v.gl.canvas;
    return this.ask({ scene: v.scene, camera: v.camera, size: [canvas.width, canvas.height], max3d: v.max3d }, x, y);
  }

  // the first visible surface along a ray (volume mm): a controller's in the headset (xrruler.js)
  /** @param {Vec3} position @param {Vec3} direction */
  pickRay(position, direction) {
    const v = this.viewer;
    const up = Math.abs(direction[2]) < 0.9 ? [0, 0, 1] : [0, 1, 0];
    const camera = { ...v.camera, position, target: add(position, direction), up, projection: 'perspective' };
    this.picking = this.ask({ scene: v.scene, camera, size: [1, 1], max3d: v.max3d }, 0.5, 0.5);
    return this.picking;
  }

  // pick.json's point for `frame` at (x, y): the ruler's first end, or its second (the ruler is made)
  /** @param {object} frame @param {number} x @param {number} y */
  async ask(frame, x, y) {
    const { point } = await postJSON('pick.json', { frame, x, y });
    if (!point) return;
    if (!this.pending) { this.pending = point; this.draw(); return; }
    this.measures.items.push({ kind: 'distance', points: [this.pending, point], plane: null, shape: '',
      stats: null, label: '' });
    this.pending = null;
    this.measures.draw();
  }

  // the rulers over the picture, in the element's CSS pixels
  draw() {
    const v = this.viewer, canvas = /** @type {HTMLCanvasElement} */ (v.gl.canvas);
    /** @type {Size} */
    const size = [canvas.width, canvas.height];
    const box = canvas.getBoundingClientRect();
    /** @type {(p: Vec3) => number[]} */
    const at = (p) => {
      const [c, r, z] = project(v.camera, p, size);
      return [c * box.width / size[0], r * box.height / size[1], z];
    };
    this.svg.replaceChildren();
    /** @type {(name: string, attrs: Record<string, string | number>) => SVGElement} */
    const el = (name, attrs) => {
      const e = /** @type {SVGElement} */ (document.createElementNS(SVG, name));
      for (const [k, val] of Object.entries(attrs)) e.setAttribute(k, String(val));
      this.svg.append(e);
      return e;
    };
    for (const m of this.measures.items) {
      if (m.kind !== 'distance') continue;
      const [a, b] = m.points.map(at);
      if (a[2] <= 0 || b[2] <= 0) continue;   // behind the eye
      el('line', { x1: a[0], y1: a[1], x2: b[0], y2: b[1] });
      for (const p of [a, b]) el('circle', { cx: p[0], cy: p[1], r: 3 });
      el('text', { x: Math.max(a[0], b[0]) + 6, y: Math.min(a[1], b[1]) - 4 }).textContent = caption(m);
    }
    if (this.pending) {
      const p = at(this.pending);
      el('circle', { cx: p[0], cy: p[1], r: 5, class: 'pending' });
    }
  }
}
