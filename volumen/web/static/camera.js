// Camera and gestures: the page's mirror of volumen.core.Camera, volumen.core.gestures and the packing of the
// ray caster's camera and lights (raycast._geometry.pack_camera, raycast._shade.pack_lights), so a drag on
// the page moves the camera exactly as the same drag does in the application and the notebook.
// A camera is the JSON of Camera.to_dict(): {position, target, up, fov, projection, parallel_scale, near, far}.

import { add, cross, dot, norm, rotate, scale, sub, unit } from './linalg.js';

/** @import { Vec3 } from './linalg.js' */
/**
 * @typedef {object} Camera  Camera.to_dict()
 * @property {Vec3} position
 * @property {Vec3} target
 * @property {Vec3} up
 * @property {number} fov  vertical field, degrees
 * @property {string} projection  'perspective' or 'orthographic'
 * @property {number} parallel_scale  half the height of an orthographic view, mm
 * @property {number | null} near
 * @property {number | null} far
 */
/**
 * @typedef {object} Light  Light.to_dict()
 * @property {Vec3} position  mm (in the camera's axes when attached to it)
 * @property {Vec3} direction
 * @property {number} intensity
 * @property {Vec3} color
 * @property {number} exponent
 * @property {string | null} kind  'point', 'spot', 'headlight'
 * @property {string} attach  'world' or 'camera'
 * @property {number} radius
 */
/**
 * @typedef {object} PackedCamera  the ray caster's camera uniforms for a picture of u_wh pixels
 * @property {Vec3} u_eye
 * @property {Vec3} u_right
 * @property {Vec3} u_up
 * @property {Vec3} u_fwd
 * @property {boolean} u_ortho
 * @property {number} u_half
 * @property {number[]} u_wh
 * @property {number} u_near
 * @property {number} u_far
 */
/**
 * @typedef {object} LightUniforms
 * @property {number} u_nlights
 * @property {Float32Array} u_lpos
 * @property {Float32Array} u_ldir
 * @property {Float32Array} u_lcol
 * @property {Float32Array} u_lexp
 */
/** @typedef {[number, number]} Size  a picture's width and height, pixels */

export const DEGREES_PER_PIXEL = 0.5;   // core.gestures
export const ZOOM_PER_PIXEL = 0.01;
export const WHEEL_ZOOM = 1.1;
const FAR = 1e30;                       // raycast._geometry._FAR

// unit vectors {r, u, f}: right, true up, forward (Camera.basis)
/** @param {Camera} cam @returns {{r: Vec3, u: Vec3, f: Vec3}} */
export function basis(cam) {
  const f = unit(sub(cam.target, cam.position));
  const r = unit(cross(f, cam.up));
  return { r, u: cross(r, f), f };
}

/** @type {(cam: Camera) => number} */
export const distance = (cam) => norm(sub(cam.target, cam.position));

// uniforms of the packed camera for a picture of w x h pixels (pack_camera)
/** @param {Camera} cam @param {number} w @param {number} h @returns {PackedCamera} */
export function packCamera(cam, w, h) {
  const { r, u, f } = basis(cam);
  const ortho = cam.projection === 'orthographic';
  return {
    u_eye: cam.position, u_right: r, u_up: u, u_fwd: f, u_ortho: ortho,
    u_half: ortho ? cam.parallel_scale : Math.tan(cam.fov * Math.PI / 360),
    u_wh: [w, h], u_near: cam.near ?? 0, u_far: Math.min(cam.far ?? FAR, FAR),
  };
}

// an eye of an XR view as a packed camera: `eye` position and axes (right, up, forward) in world mm, the
// vertical half field `half` (tan), a picture of w x h pixels; and the same eye as a Camera (JSON)
/**
 * @param {Vec3} eye @param {Vec3} right @param {Vec3} up @param {Vec3} forward @param {number} half
 * @param {number} w @param {number} h
 * @returns {{packed: PackedCamera, camera: Camera}}
 */
export function eyeCamera(eye, right, up, forward, half, w, h) {
  const packed = { u_eye: eye, u_right: right, u_up: up, u_fwd: forward, u_ortho: false, u_half: half,
    u_wh: [w, h], u_near: 0, u_far: FAR };
  const camera = { position: eye, target: add(eye, scale(forward, 100)), up, fov: 360 * Math.atan(half) / Math.PI,
    projection: 'perspective', parallel_scale: 100, near: null, far: null };
  return { packed, camera };
}

// gestures.orbit: -dx deg/px about up, then -dy about the turned right axis, through the target
/** @param {Camera} cam @param {number} dx @param {number} dy @returns {Camera} */
export function orbit(cam, dx, dy) {
  const { r, u } = basis(cam);
  const yaw = -dx * DEGREES_PER_PIXEL, pitch = -dy * DEGREES_PER_PIXEL;
  let back = rotate(sub(cam.position, cam.target), u, yaw);
  const r2 = rotate(r, u, yaw);
  back = rotate(back, r2, pitch);
  return { ...cam, position: add(cam.target, back), up: rotate(u, r2, pitch) };
}

// the size of a pixel (mm) at `depth` mm along the view (default: the target's distance; orthographic: the same
// at every depth)
/** @param {Camera} cam @param {Size} size @param {number} [depth] @returns {number} */
export function mmPerPixel(cam, size, depth) {
  if (cam.projection === 'orthographic') return 2 * cam.parallel_scale / size[1];
  const d = depth ?? distance(cam);
  return 2 * d * Math.tan(cam.fov * Math.PI / 360) / size[1];
}

/** @param {Camera} cam @param {number} dx @param {number} dy @param {Size} size @returns {Camera} */
export function pan(cam, dx, dy, size) {
  const { r, u } = basis(cam);
  const shift = scale(add(scale(r, -dx), scale(u, dy)), mmPerPixel(cam, size));
  return { ...cam, position: add(cam.position, shift), target: add(cam.target, shift) };
}

/** @param {Camera} cam @param {number} factor @returns {Camera} */
export function zoom(cam, factor) {
  if (cam.projection === 'orthographic') return { ...cam, parallel_scale: cam.parallel_scale / factor };
  const back = scale(sub(cam.position, cam.target), 1 / factor);
  if (norm(back) < 1e-3) return cam;
  return { ...cam, position: add(cam.target, back) };
}

/** @type {(cam: Camera, dy: number) => Camera} */
export const dragZoom = (cam, dy) => zoom(cam, Math.exp(-dy * ZOOM_PER_PIXEL));
/** @type {(cam: Camera, notches: number) => Camera} */
export const wheelZoom = (cam, notches) => zoom(cam, WHEEL_ZOOM ** notches);

// ---- lights (Light.to_dict() JSON) ----

// (position, unit direction) in world mm for the camera (Light.in_world)
/** @param {Light} light @param {Camera} cam @returns {[Vec3, Vec3]} */
export function lightInWorld(light, cam) {
  const { r, u, f } = basis(cam);
  const d = unit(light.direction);
  if (light.kind === 'headlight') return [cam.position, f];
  if (light.attach === 'camera') {
    const m = (/** @type {Vec3} */ v) => add(add(scale(r, v[0]), scale(u, v[1])), scale(f, v[2]));
    return [add(cam.position, m(light.position)), m(d)];
  }
  return [light.position, d];
}

// the light uniforms of the frame's shading for the camera (pack_frame's _lights and pack_lights): none when
// the frame is unlit, the headlight, or the scene's lights
/**
 * @param {import('./viewer.js').Scene} scene @param {Camera} cam @param {boolean} lit @param {number} maxLights
 * @returns {LightUniforms}
 */
export function lightUniforms(scene, cam, lit, maxLights) {
  /** @type {Light[]} */
  const rows = !lit ? [] : scene.shading.mode === 'headlight' ? [{ kind: 'headlight', position: [0, 0, 0],
    direction: [0, 0, 1], intensity: 1, color: [1, 1, 1], exponent: 0, attach: 'world', radius: 0 }] : scene.lights;
  const pos = new Float32Array(3 * maxLights), dir = new Float32Array(3 * maxLights);
  const col = new Float32Array(3 * maxLights), exp = new Float32Array(maxLights);
  rows.slice(0, maxLights).forEach((lt, i) => {
    const [p, d] = lightInWorld(lt, cam);
    pos.set(p, 3 * i);
    dir.set(d, 3 * i);
    col.set(scale(lt.color, lt.intensity), 3 * i);
    exp[i] = lt.kind === 'point' ? 0 : lt.exponent;
  });
  return { u_nlights: rows.length, u_lpos: pos, u_ldir: dir, u_lcol: col, u_lexp: exp };
}

// gestures.light_at_camera: a spot light at the eye shining where the camera looks
/** @param {Camera} cam @returns {Light} */
export function lightAtCamera(cam) {
  const { f } = basis(cam);
  return { position: [...cam.position], direction: f, intensity: 1, color: [1, 1, 1], exponent: 10, kind: 'spot',
    attach: 'world', radius: 0 };
}

// gestures.move_light: a world light follows a drag in the view plane at its own depth
/**
 * @param {Light} light @param {Camera} cam @param {number} dx @param {number} dy @param {Size} size
 * @returns {Light}
 */
export function moveLight(light, cam, dx, dy, size) {
  const { r, u, f } = basis(cam);
  if (light.attach === 'camera') {
    const s = mmPerPixel(cam, size, Math.max(light.position[2], 1));
    return { ...light, position: add(light.position, [dx * s, -dy * s, 0]) };
  }
  const depth = dot(sub(light.position, cam.position), f);
  const s = mmPerPixel(cam, size, Math.max(depth, 1));
  return { ...light, position: add(light.position, scale(sub(scale(r, dx), scale(u, dy)), s)) };
}

// gestures.aim_light: the spot axis turned by a drag
/** @param {Light} light @param {Camera} cam @param {number} dx @param {number} dy @returns {Light} */
export function aimLight(light, cam, dx, dy) {
  const { r, u } = light.attach === 'camera' ? { r: [1, 0, 0], u: [0, 1, 0] } : basis(cam);
  const d = rotate(rotate(light.direction, u, dx * DEGREES_PER_PIXEL), r, dy * DEGREES_PER_PIXEL);
  return { ...light, direction: d };
}

// project a world point for a w x h picture: [col, row, depth] (Camera.project)
/** @param {Camera} cam @param {Vec3} p @param {Size} size @returns {Vec3} */
export function project(cam, p, size) {
  const { r, u, f } = basis(cam);
  const v = sub(p, cam.position);
  const x = dot(v, r), y = dot(v, u), z = dot(v, f);
  let sx, sy;
  if (cam.projection === 'orthographic') {
    sx = x / cam.parallel_scale; sy = y / cam.parallel_scale;
  } else {
    const half = Math.tan(cam.fov * Math.PI / 360);
    sx = x / (z * half); sy = y / (z * half);
  }
  return [size[0] / 2 + sx * size[1] / 2, size[1] / 2 - sy * size[1] / 2, z];
}

// Mouse gestures on an element, as in the application (app/_view3d.py): left drag orbits, shift + left or
// middle drag pans, right drag zooms, a wheel notch (100 units) zooms; a left drag that starts on a light's
// cone (`pick(x, y)` gives its index or null) moves the light, ctrl + left drag aims it. `on(kind, dx, dy,
// light)` gets each step; `end()` is called when the button is released.
/** @typedef {'orbit' | 'pan' | 'zoom' | 'wheel' | 'light' | 'aim'} Gesture */
/**
 * @param {HTMLElement} el
 * @param {(x: number, y: number) => number | null} pick
 * @param {(kind: Gesture, dx: number, dy: number, light: number | null) => void} on
 * @param {() => void} end
 */
export function attachGestures(el, pick, on, end) {
  /** @type {number[] | null} */
  let last = null;
  /** @type {Gesture} */
  let kind = 'orbit';
  /** @type {number | null} */
  let light = null;
  el.addEventListener('contextmenu', (e) => e.preventDefault());
  el.addEventListener('pointerdown', (e) => {
    const box = el.getBoundingClientRect();
    light = e.button === 0 ? pick(e.clientX - box.left, e.clientY - box.top) : null;
    if (light !== null) kind = e.ctrlKey ? 'aim' : 'light';
    else if (e.button === 0) kind = e.shiftKey ? 'pan' : 'orbit';
    else kind = e.button === 1 ? 'pan' : 'zoom';
    last = [e.clientX, e.clientY];
    el.setPointerCapture?.(e.pointerId);
  });
  el.addEventListener('pointermove', (e) => {
    if (!last) return;
    const dx = e.clientX - last[0], dy = e.clientY - last[1];
    last = [e.clientX, e.clientY];
    if (dx || dy) on(kind, dx, dy, light);
  });
  const up = () => { if (last) { last = null; end(); } };
  el.addEventListener('pointerup', up);
  el.addEventListener('pointercancel', up);
  el.addEventListener('wheel', (e) => {
    e.preventDefault();
    on('wheel', 0, -e.deltaY / 100, null);
    end();
  }, { passive: false });
}
