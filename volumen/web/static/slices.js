// The three slice views (axial, coronal, sagittal) through the crosshair, with a window: pictures drawn by the
// server (web/_slices.py, radiological orientation), and over each the lines where the two other planes cut
// it, in those planes' colours (the application's). A click on a picture moves the crosshair to the world
// point under it (the picture's pixel -> world map comes with it).

import { getSlice } from './api.js';

/** @import { Slice } from './api.js' */
/** @import { Vec3 } from './linalg.js' */
/** @import { Info } from './viewer.js' */
/**
 * @typedef {object} View  one plane's picture and lines
 * @property {HTMLImageElement} img
 * @property {Slice['map'] | null} map
 * @property {Slice['cross'] | null} cross
 * @property {HTMLDivElement} rowLine
 * @property {HTMLDivElement} colLine
 */

export const PLANES = ['axial', 'coronal', 'sagittal'];
/** @type {Record<string, string>} */
export const PLANE_COLOURS = { axial: 'rgb(60, 120, 255)', coronal: 'rgb(230, 60, 60)', sagittal: 'rgb(60, 200, 60)' };

// the picture's box inside its element (object-fit: contain): [left, top, scale] in CSS pixels, and the
// element's box
/** @param {HTMLImageElement} img @returns {[number, number, number, DOMRect]} */
export function fitted(img) {
  const box = img.getBoundingClientRect();
  const s = Math.min(box.width / img.naturalWidth, box.height / img.naturalHeight);
  return [(box.width - s * img.naturalWidth) / 2, (box.height - s * img.naturalHeight) / 2, s, box];
}

export class SliceViews {
  /**
   * @param {HTMLElement} root
   * @param {object} options
   * @param {Info} options.info
   * @param {number} options.max3d  the browser's 3-D texture size (the server slices the volume it sends)
   * @param {(crosshair: Vec3) => void} options.onCrosshair  called when a click moved the crosshair
   */
  constructor(root, { info, max3d, onCrosshair }) {
    this.info = info;
    this.max3d = max3d;
    this.onCrosshair = onCrosshair;
    const v = info.volume;
    this.window = { ...v.window };  // the server's first window (core.default_window), as the app's
    this.crosshair = v.center.slice();
    /** @type {Record<string, View>} by plane */
    this.views = {};
    this.seq = 0;
    this.suppressClick = false;   // set by a measurement drag (measure.js): its click leaves the crosshair
    /** @type {() => void} called after the pictures or their lines are drawn (the measurements follow) */
    this.onDrawn = () => {};
    /** @type {Promise<void>} */
    this.latest = Promise.resolve();
    for (const plane of PLANES) {
      const fig = document.createElement('figure');
      const img = document.createElement('img');
      img.alt = `${plane} slice`;
      img.dataset.plane = plane;
      const cap = document.createElement('figcaption');
      cap.textContent = plane;
      const rowLine = document.createElement('div'), colLine = document.createElement('div');
      rowLine.className = 'line row';
      colLine.className = 'line col';
      fig.append(img, rowLine, colLine, cap);
      root.append(fig);
      img.addEventListener('click', (e) => this.click(plane, e));
      new ResizeObserver(() => this.drawLines()).observe(fig);
      this.views[plane] = { img, map: null, cross: null, rowLine, colLine };
    }
  }

  /** @param {string} plane @param {MouseEvent} e */
  click(plane, e) {
    const { img, map } = this.views[plane];
    if (this.suppressClick) { this.suppressClick = false; return; }
    if (!map) return;
    const [x0, y0, s, box] = fitted(img);
    const col = (e.clientX - box.left - x0) / s - 0.5, row = (e.clientY - box.top - y0) / s - 0.5;
    this.crosshair = [0, 1, 2].map((a) => map[0][a] + col * map[1][a] + row * map[2][a]);
    this.update();
    this.onCrosshair(this.crosshair);
  }

  /** @param {number} level @param {number} width */
  setWindow(level, width) {
    this.window = { level, width };
    this.update();
  }

  // resolves once the slices of the latest state are shown (an update overtaken by a newer one waits for it)
  /** @returns {Promise<void>} */
  update() {
    this.latest = this.show(++this.seq);
    return this.latest;
  }

  /** @param {number} seq @returns {Promise<void>} */
  async show(seq) {
    const [x, y, z] = this.crosshair;
    const shots = await Promise.all(PLANES.map((plane) => getSlice({ plane, x, y, z, level: this.window.level,
      width: this.window.width, max3d: this.max3d })));
    if (seq !== this.seq) { shots.forEach((s) => URL.revokeObjectURL(s.url)); return this.latest; }
    await Promise.all(PLANES.map((plane, i) => {
      const v = this.views[plane];
      if (v.img.src) URL.revokeObjectURL(v.img.src);
      v.img.src = shots[i].url;
      v.map = shots[i].map;
      v.cross = shots[i].cross;
      return v.img.decode().catch(() => null);
    }));
    this.drawLines();
  }

  // the other planes' lines over each picture, at the crosshair, whatever the picture's scale
  drawLines() {
    for (const v of Object.values(this.views)) {
      if (!v.cross || !v.img.naturalWidth) continue;
      const [x0, y0, s] = fitted(v.img);
      Object.assign(v.rowLine.style, { top: `${y0 + (v.cross.row + 0.5) * s}px`, left: `${x0}px`,
        width: `${s * v.img.naturalWidth}px`, background: PLANE_COLOURS[v.cross.row_plane] });
      Object.assign(v.colLine.style, { left: `${x0 + (v.cross.col + 0.5) * s}px`, top: `${y0}px`,
        height: `${s * v.img.naturalHeight}px`, background: PLANE_COLOURS[v.cross.col_plane] });
    }
    this.onDrawn();
  }
}
