// Rulers and regions on the slice views: place with a tool (ruler, rectangle, ellipse) by a drag, move by a drag
// on an end or corner, delete by a right click there. The value is drawn beside each and follows the drag: a
// ruler's length from its world points, a region's statistics from the server (region.json: the scan's own
// voxels, volumen.measure.roi_stats). Every view draws what its slice cuts: the whole measurement where it lies
// in the slice (within half a voxel), the crossing points elsewhere. The measurements are volumen.measure's
// JSON (`toDicts`), which `volumen measure export` reads.

import { postJSON } from './api.js';
import { add, cross, dot, norm, scale, sub, unit } from './linalg.js';
import { fitted } from './slices.js';

/** @import { SliceViews } from './slices.js' */
/** @import { Vec3 } from './linalg.js' */
/**
 * @typedef {{origin: Vec3, u: Vec3, v: Vec3}} Plane
 * @typedef {{kind: string, lo?: number[], hi?: number[], center?: number[], radii?: number[]}} Shape
 * @typedef {{mean: number, sd: number, min: number, max: number, median: number, area_mm2: number,
 *   voxels: number, units: string}} Stats
 * @typedef {{kind: string, points: Vec3[], plane: Plane | null, shape: string, stats: Stats | null,
 *   label: string}} Measurement  a ruler (points: its ends) or a region (points: two opposite corners)
 */

export const TOOLS = ['ruler', 'rectangle', 'ellipse'];
const GRAB = 7;   // px: how near a press must be to an end or corner to grab it
const SVG = 'http://www.w3.org/2000/svg';
const ELLIPSE_POINTS = 72;

/** @param {number} v @param {string} units */
const valueText = (v, units) => (units.toUpperCase().startsWith('HU') ? String(Math.round(v)) : v.toPrecision(4));

/** A measurement's (s, t) box on its plane, and its shape (volumen.measure's JSON). */
/** @param {Measurement} m @returns {{lo: number[], hi: number[], shape: Shape}} */
function boxOf(m) {
  const p = /** @type {Plane} */ (m.plane);
  const st = m.points.map((w) => [dot(sub(w, p.origin), p.u), dot(sub(w, p.origin), p.v)]);
  const lo = [Math.min(st[0][0], st[1][0]), Math.min(st[0][1], st[1][1])];
  const hi = [Math.max(st[0][0], st[1][0], lo[0] + 1e-3), Math.max(st[0][1], st[1][1], lo[1] + 1e-3)];
  const shape = m.shape === 'rectangle' ? { kind: 'rectangle', lo, hi }
    : { kind: 'ellipse', center: [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2],
      radii: [(hi[0] - lo[0]) / 2, (hi[1] - lo[1]) / 2] };
  return { lo, hi, shape };
}

/** A measurement's outline in world mm: a ruler's ends, a region's closed outline. */
/** @param {Measurement} m @returns {Vec3[]} */
function outline(m) {
  if (m.kind === 'distance') return m.points;
  const p = /** @type {Plane} */ (m.plane), { lo, hi } = boxOf(m);
  /** @type {(s: number, t: number) => Vec3} */
  const at = (s, t) => add(p.origin, add(scale(p.u, s), scale(p.v, t)));
  if (m.shape === 'rectangle') return [at(lo[0], lo[1]), at(hi[0], lo[1]), at(hi[0], hi[1]), at(lo[0], hi[1]),
    at(lo[0], lo[1])];
  const c = [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2], r = [(hi[0] - lo[0]) / 2, (hi[1] - lo[1]) / 2];
  return Array.from({ length: ELLIPSE_POINTS + 1 }, (_, k) => {
    const a = (2 * Math.PI * k) / ELLIPSE_POINTS;
    return at(c[0] + r[0] * Math.cos(a), c[1] + r[1] * Math.sin(a));
  });
}

/** The value drawn beside a measurement. */
/** @param {Measurement} m */
export function caption(m) {
  if (m.kind === 'distance') return `${norm(sub(m.points[1], m.points[0])).toFixed(1)} mm`;
  const s = m.stats;
  if (!s) return '...';
  const u = s.units ? ` ${s.units}` : '';
  return `mean ${valueText(s.mean, s.units)}${u}  SD ${valueText(s.sd, s.units)}  ${s.area_mm2.toFixed(1)} mm\u00b2`;
}

export class SliceMeasures {
  /** @param {SliceViews} slices  the tool buttons go on the axial view */
  constructor(slices) {
    this.slices = slices;
    /** @type {string | null} */
    this.tool = null;
    /** @type {Measurement[]} */
    this.items = [];
    /** @type {{index: number, handle: number, plane: string} | null} */
    this.drag = null;
    this.seq = 0;
    /** @type {(() => void)[]} called after the measurements are drawn (the 3-D picture's rulers follow) */
    this.drawn = [];
    /** @type {Record<string, SVGSVGElement>} by plane */
    this.layers = {};
    const bar = this.bar = document.createElement('div');
    bar.className = 'measure-tools';
    for (const tool of [null, ...TOOLS]) {
      const b = document.createElement('button');
      b.textContent = tool ?? 'crosshair';
      b.dataset.tool = tool ?? '';
      b.addEventListener('click', () => this.setTool(tool));
      bar.append(b);
    }
    /** @type {HTMLElement} */ (slices.views.axial.img.parentElement).append(bar);
    for (const [plane, v] of Object.entries(slices.views)) {
      const svg = /** @type {SVGSVGElement} */ (document.createElementNS(SVG, 'svg'));
      svg.classList.add('measures');
      svg.dataset.plane = plane;
      /** @type {HTMLElement} */ (v.img.parentElement).append(svg);
      this.layers[plane] = svg;
      v.img.addEventListener('pointerdown', (e) => this.down(plane, e));
      v.img.addEventListener('contextmenu', (e) => e.preventDefault());
    }
    slices.onDrawn = () => this.draw();
    addEventListener('pointermove', (e) => this.move(e));
    addEventListener('pointerup', () => { this.drag = null; });
    this.setTool(null);
  }

  /** @param {string | null} tool */
  setTool(tool) {
    this.tool = tool;
    this.bar.querySelectorAll('button').forEach((b) => b.classList.toggle('on', b.dataset.tool === (tool ?? '')));
  }

  /** @param {string} plane @param {number} clientX @param {number} clientY @returns {Vec3 | null} */
  worldAt(plane, clientX, clientY) {
    const { img, map } = this.slices.views[plane];
    if (!map) return null;
    const [x0, y0, s, box] = fitted(img);
    const col = (clientX - box.left - x0) / s - 0.5, row = (clientY - box.top - y0) / s - 0.5;
    return add(map[0], add(scale(map[1], col), scale(map[2], row)));
  }

  /** World mm -> [x, y] in the view's element (CSS px) and the signed distance from its slice in mm. */
  /** @param {string} plane @param {Vec3} w @returns {[number, number, number]} */
  toView(plane, w) {
    const { img, map } = this.slices.views[plane];
    const m = /** @type {number[][]} */ (map);
    const [x0, y0, s] = fitted(img);
    const d = sub(w, m[0]);
    const col = dot(d, m[1]) / dot(m[1], m[1]), row = dot(d, m[2]) / dot(m[2], m[2]);
    return [x0 + (col + 0.5) * s, y0 + (row + 0.5) * s, dot(d, unit(cross(m[1], m[2])))];
  }

  /** Half a voxel's width along a view's normal (mm): how near a measurement must be to lie in its slice. */
  /** @param {string} plane */
  halfSlice(plane) {
    const m = /** @type {number[][]} */ (this.slices.views[plane].map);
    const n = unit(cross(m[1], m[2])), a = this.slices.info.volume.affine;
    return 0.5 * [0, 1, 2].reduce((sum, c) => sum + Math.abs(n[0] * a[0][c] + n[1] * a[1][c] + n[2] * a[2][c]), 0);
  }

  /** @param {string} plane @param {PointerEvent} e */
  down(plane, e) {
    const grabbed = this.grabbed(plane, e.clientX, e.clientY);
    if (e.button === 2 && grabbed) {
      this.items.splice(grabbed.index, 1);
      this.draw();
      return;
    }
    if (e.button !== 0 || !(grabbed || this.tool)) return;
    e.preventDefault();
    e.stopImmediatePropagation();
    this.slices.suppressClick = true;
    if (grabbed) { this.drag = { ...grabbed, plane }; return; }
    const w = /** @type {Vec3} */ (this.worldAt(plane, e.clientX, e.clientY));
    const map = /** @type {number[][]} */ (this.slices.views[plane].map);
    const region = this.tool !== 'ruler';
    this.items.push({ kind: region ? 'region' : 'distance', points: [w, w.slice()], label: '', stats: null,
      shape: region ? /** @type {string} */ (this.tool) : '',
      plane: region ? { origin: map[0], u: unit(map[1]), v: unit(map[2]) } : null });
    this.drag = { index: this.items.length - 1, handle: 1, plane };
    this.draw();
  }

  /** @param {PointerEvent} e */
  move(e) {
    if (!this.drag) return;
    const { index, handle, plane } = this.drag, m = this.items[index];
    let w = this.worldAt(plane, e.clientX, e.clientY);
    if (!w) return;
    if (m.plane) {   // a region's corner stays on its plane
      const p = m.plane, d = sub(w, p.origin);
      w = add(p.origin, add(scale(p.u, dot(d, p.u)), scale(p.v, dot(d, p.v))));
    }
    m.points[handle] = w;
    if (m.kind === 'region') this.askStats(m);
    this.draw();
  }

  /** The region's statistics from the server; the latest request wins. */
  /** @param {Measurement} m */
  async askStats(m) {
    const seq = ++this.seq;
    try {
      const stats = await postJSON('region.json', { plane: m.plane, shape: boxOf(m).shape });
      if (seq === this.seq || !this.drag) { m.stats = stats; this.draw(); }
    } catch {
      // a region that holds no voxel yet: its value waits for the drag
    }
  }

  /** @param {string} plane @param {number} x client px @param {number} y @returns {{index: number, handle: number} | null} */
  grabbed(plane, x, y) {
    const box = this.slices.views[plane].img.getBoundingClientRect();
    let best = null, bestD = GRAB;
    this.items.forEach((m, index) => {
      if (!this.part(plane, m)) return;
      m.points.forEach((w, handle) => {
        const [vx, vy] = this.toView(plane, w);
        const d = Math.hypot(vx + box.left - x, vy + box.top - y);
        if (d < bestD) { best = { index, handle }; bestD = d; }
      });
    });
    return best;
  }

  /** What a view shows of a measurement: the whole outline, its crossing points, or nothing. */
  /** @param {string} plane @param {Measurement} m @returns {{whole: boolean, xy: number[][]} | null} */
  part(plane, m) {
    if (!this.slices.views[plane].map) return null;
    const pts = outline(m).map((w) => this.toView(plane, w)), h = this.halfSlice(plane);
    if (pts.every((p) => Math.abs(p[2]) <= h)) return { whole: true, xy: pts };
    const xy = [];
    for (let k = 0; k + 1 < pts.length; k++) {
      const [a, b] = [pts[k], pts[k + 1]];
      if (a[2] * b[2] < 0 || a[2] === 0) {
        const t = a[2] === 0 ? 0 : a[2] / (a[2] - b[2]);
        xy.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
      }
    }
    return xy.length ? { whole: false, xy } : null;
  }

  // every view's measurements, drawn again
  draw() {
    for (const [plane, svg] of Object.entries(this.layers)) {
      svg.replaceChildren();
      for (const m of this.items) {
        const part = this.part(plane, m);
        if (part) this.drawOne(svg, m, part);
      }
    }
    this.drawn.forEach((fn) => fn());
  }

  /** @param {SVGSVGElement} svg @param {Measurement} m @param {{whole: boolean, xy: number[][]}} part */
  drawOne(svg, m, { whole, xy }) {
    /** @type {(name: string, attrs: Record<string, string | number>) => SVGElement} */
    const el = (name, attrs) => {
      const e = /** @type {SVGElement} */ (document.createElementNS(SVG, name));
      for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
      svg.append(e);
      return e;
    };
    const pts = xy.map(([x, y]) => `${x},${y}`).join(' ');
    if (whole || m.kind !== 'distance') el('polyline', { points: pts, class: whole ? 'whole' : 'cut' });
    if (!whole) for (const [x, y] of xy) el('path', { d: `M${x - 4},${y - 4}l8,8m0,-8l-8,8`, class: 'cut' });
    if (!whole && m.kind !== 'distance') return;   // a region's value is drawn where it lies whole, not by a chord
    const x = Math.max(...xy.map((p) => p[0])) + 6;
    let y = Math.min(...xy.map((p) => p[1])) - 4;
    /** @type {number[][]} */
    const taken = [];
    svg.querySelectorAll('text').forEach((t) => taken.push([Number(t.getAttribute('x')), Number(t.getAttribute('y'))]));
    while (taken.some(([tx, ty]) => Math.abs(ty - y) < 13 && Math.abs(tx - x) < 160)) y += 14;   // under one there
    const text = /** @type {SVGTextElement} */ (el('text', { x, y }));
    text.textContent = caption(m);
    const wide = text.getComputedTextLength();   // kept inside the view
    if (x + wide > svg.clientWidth) text.setAttribute('x', String(Math.max(0, svg.clientWidth - wide - 2)));
  }

  // add volumen.measure's JSON (Measurements.to_dicts: rulers and rectangle or ellipse regions; what else it
  // holds is left out), as `toDicts` writes it; returns how many were added
  /** @param {Record<string, any>[]} dicts */
  fromDicts(dicts) {
    let n = 0;
    for (const d of dicts) {
      if (d.kind === 'distance') {
        this.items.push({ kind: 'distance', points: [d.start, d.end], plane: null, shape: '', stats: null,
          label: d.label ?? '' });
      } else if (d.kind === 'region' && ['rectangle', 'ellipse'].includes(d.shape.kind)) {
        const s = d.shape, p = d.plane;
        const lo = s.lo ?? [s.center[0] - s.radii[0], s.center[1] - s.radii[1]];
        const hi = s.hi ?? [s.center[0] + s.radii[0], s.center[1] + s.radii[1]];
        /** @type {(st: number[]) => Vec3} */
        const at = (st) => add(p.origin, add(scale(p.u, st[0]), scale(p.v, st[1])));
        const { mean, sd, min, max, median, area_mm2, voxels, units } = d;
        this.items.push({ kind: 'region', points: [at(lo), at(hi)], plane: p, shape: s.kind, label: d.label ?? '',
          stats: { mean, sd, min, max, median, area_mm2, voxels, units } });
      } else continue;
      n++;
    }
    this.draw();
    return n;
  }

  // the measurements as volumen.measure's JSON (Measurements.to_dicts)
  toDicts() {
    return this.items.map((m) => {
      if (m.kind === 'distance') return { kind: 'distance', start: m.points[0], end: m.points[1], label: m.label,
        scan: {} };
      return { kind: 'region', plane: m.plane, shape: boxOf(m).shape, label: m.label, scan: {},
        ...(m.stats ?? {}) };
    });
  }
}
