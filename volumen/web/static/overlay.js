// What the 3-D view draws over the picture (a 2-D canvas on top of the WebGL one), as the application does
// (app/_overlays.py): each world light as a cone pointing where it shines (the selected one larger), the crop
// box's edges, and the crosshair's three axes across the volume. Everything goes through camera.project.

import { basis, lightInWorld, project } from './camera.js';
import { add, cross, dot, scale, sub, unit } from './linalg.js';

/** @import { Camera, Light, Size } from './camera.js' */
/** @import { Vec3 } from './linalg.js' */
/** @import { Info, Scene } from './viewer.js' */
/** @typedef {number[]} Point  a point on the screen: [x, y] pixels */

const CONE_DEGREES = 25;
const AXIS_COLOURS = ['#e33', '#3c3', '#37f'];

/** @type {(info: Info) => number} the length of a light's cone, mm */
export const lightLength = (info) => 0.08 * info.volume.diagonal;

// the cone of `light` on the screen: {apex, outline (convex hull), visible}
/**
 * @param {Light} light @param {Camera} cam @param {Size} size @param {number} length
 * @returns {{apex: Vec3, outline: Point[], visible: boolean}}
 */
export function lightCone(light, cam, size, length) {
  const [pos, d] = lightInWorld(light, cam);
  const radius = length * Math.tan(CONE_DEGREES * Math.PI / 180);
  const a = unit(cross(d, Math.abs(d[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0]));
  const b = cross(d, a);
  const pts3 = [pos];
  for (let i = 0; i < 16; i++) {
    const t = 2 * Math.PI * i / 16;
    pts3.push(add(add(pos, scale(d, length)), add(scale(a, radius * Math.cos(t)), scale(b, radius * Math.sin(t)))));
  }
  const { f } = basis(cam);
  const pts = pts3.map((p) => project(cam, p, size));
  const visible = pts.every((p) => p[2] > 0 && Number.isFinite(p[0]) && Number.isFinite(p[1]))
    && (cam.projection !== 'perspective' || pts3.every((p) => dot(sub(p, cam.position), f) > 1e-3));
  return { apex: pts[0], outline: visible ? hull(pts.map((p) => [p[0], p[1]])) : [], visible };
}

// the convex hull, counter-clockwise (monotone chain)
/** @param {Point[]} points @returns {Point[]} */
function hull(points) {
  const pts = points.slice().sort((p, q) => p[0] - q[0] || p[1] - q[1]);
  /** @param {Point[]} seq */
  const half = (seq) => {
    const out = [];
    for (const p of seq) {
      while (out.length >= 2) {
        const [o, q] = [out[out.length - 2], out[out.length - 1]];
        if ((q[0] - o[0]) * (p[1] - o[1]) - (q[1] - o[1]) * (p[0] - o[0]) > 0) break;
        out.pop();
      }
      out.push(p);
    }
    return out;
  };
  const lower = half(pts), upper = half(pts.slice().reverse());
  return lower.slice(0, -1).concat(upper.slice(0, -1));
}

/** @param {Point[]} poly convex @param {Point} p @returns {boolean} */
function inside(poly, p) {
  if (poly.length < 3) return false;
  let pos = true, neg = true;
  for (let i = 0; i < poly.length; i++) {
    const a = poly[i], b = poly[(i + 1) % poly.length];
    const c = (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
    pos = pos && c >= 0; neg = neg && c <= 0;
  }
  return pos || neg;
}

// index of the world light whose cone is under (x, y) or within 10 px of its apex, else null (pick_light)
/**
 * @param {Light[]} lights @param {Camera} cam @param {Size} size @param {number} length
 * @param {number} x @param {number} y @returns {number | null}
 */
export function pickLight(lights, cam, size, length, x, y) {
  /** @type {number | null} */
  let best = null;
  let bestD = Infinity;
  lights.forEach((lt, i) => {
    if (lt.kind === 'headlight' || lt.attach === 'camera') return;
    const c = lightCone(lt, cam, size, length);
    if (!c.visible) return;
    let d = Math.hypot(c.apex[0] - x, c.apex[1] - y);
    if (inside(c.outline, [x, y])) d = Math.min(d, 5);
    if (d <= 10 && d < bestD) { best = i; bestD = d; }
  });
  return best;
}

// world corners of a crop box (Clipping.crop: voxel indices or world mm) as 12 edges
/** @param {Info} info @param {Scene['clipping']} clipping @returns {Vec3[][]} */
function cropEdges(info, clipping) {
  const c = clipping.crop;
  if (!c) return [];
  const a = info.volume.affine;
  /** @type {(p: Vec3) => Vec3} */
  const world = clipping.crop_space === 'world' ? (p) => p
    : (p) => [0, 1, 2].map((r) => a[r][0] * p[0] + a[r][1] * p[1] + a[r][2] * p[2] + a[r][3]);
  const corner = (/** @type {number} */ i) => world([c[i & 1 ? 1 : 0], c[i & 2 ? 3 : 2], c[i & 4 ? 5 : 4]]);
  const edges = [];
  for (let i = 0; i < 8; i++) for (const bit of [1, 2, 4]) if (!(i & bit)) edges.push([corner(i), corner(i | bit)]);
  return edges;
}

// draw on the 2-D canvas `canvas` (cleared first) for the scene seen by `camera`; `selected` the index of the
// selected light (or null), `crosshair` the slice views' world point (or null)
/**
 * @param {HTMLCanvasElement} canvas
 * @param {{info: Info, scene: Scene, camera: Camera, selected: number | null, crosshair: Vec3 | null}} state
 */
export function drawOverlay(canvas, { info, scene, camera, selected, crosshair }) {
  const ctx = canvas.getContext('2d');
  if (!ctx) return;
  /** @type {Size} */
  const size = [canvas.width, canvas.height];
  ctx.clearRect(0, 0, size[0], size[1]);
  /** @param {Vec3} p @param {Vec3} q @param {string} colour */
  const line = (p, q, colour) => {
    const a = project(camera, p, size), b = project(camera, q, size);
    if (a[2] <= 0 || b[2] <= 0) return;
    ctx.strokeStyle = colour;
    ctx.beginPath(); ctx.moveTo(a[0], a[1]); ctx.lineTo(b[0], b[1]); ctx.stroke();
  };
  ctx.lineWidth = 1;
  for (const [p, q] of cropEdges(info, scene.clipping)) line(p, q, 'rgba(255, 210, 0, 0.8)');
  if (crosshair) {
    const [lo, hi] = bounds(info);
    for (let ax = 0; ax < 3; ax++) {
      const p = crosshair.slice(), q = crosshair.slice();
      p[ax] = lo[ax]; q[ax] = hi[ax];
      line(p, q, AXIS_COLOURS[ax]);
    }
  }
  const length = lightLength(info);
  scene.lights.forEach((lt, i) => {
    if (lt.kind === 'headlight' || lt.attach === 'camera') return;
    const c = lightCone(lt, camera, size, length * (i === selected ? 1.6 : 1));
    if (!c.visible) return;
    ctx.fillStyle = i === selected ? 'rgba(255, 230, 80, 0.55)' : 'rgba(255, 255, 255, 0.35)';
    ctx.strokeStyle = i === selected ? '#ffd84a' : '#fff';
    ctx.beginPath();
    c.outline.forEach(([x, y], k) => (k ? ctx.lineTo(x, y) : ctx.moveTo(x, y)));
    ctx.closePath(); ctx.fill(); ctx.stroke();
  });
}

// world box of the voxel centres (Volume.bounds)
/** @param {Info} info @returns {[Vec3, Vec3]} */
export function bounds(info) {
  const a = info.volume.affine, [nz, ny, nx] = info.volume.shape;
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (const i of [0, nx - 1]) for (const j of [0, ny - 1]) for (const k of [0, nz - 1]) {
    for (let r = 0; r < 3; r++) {
      const v = a[r][0] * i + a[r][1] * j + a[r][2] * k + a[r][3];
      lo[r] = Math.min(lo[r], v); hi[r] = Math.max(hi[r], v);
    }
  }
  return [lo, hi];
}
