// Small vector and matrix helpers (plain arrays, float64): 3-vectors, quaternions (x, y, z, w) and 4x4
// matrices stored column-major as WebGL and WebXR give them (m[col * 4 + row]).

/** @typedef {number[]} Vec3  a 3-vector (also a point), mm or m */
/** @typedef {ArrayLike<number>} Mat4  a 4x4 matrix, column-major (an array, or WebXR's Float32Array) */

/** @type {(a: Vec3, b: Vec3) => Vec3} */

export const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
/** @type {(a: Vec3, b: Vec3) => Vec3} */
export const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
/** @type {(a: Vec3, s: number) => Vec3} */
export const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
/** @type {(a: Vec3, b: Vec3) => number} */
export const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
/** @type {(a: Vec3, b: Vec3) => Vec3} */
export const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
/** @type {(a: Vec3) => number} */
export const norm = (a) => Math.sqrt(dot(a, a));
/** @type {(a: Vec3) => Vec3} */
export const unit = (a) => scale(a, 1 / norm(a));

// v turned by `degrees` about the unit axis k (right-hand rule, Rodrigues): core.gestures.rotate
/** @param {Vec3} v @param {Vec3} axis @param {number} degrees @returns {Vec3} */
export function rotate(v, axis, degrees) {
  const k = unit(axis);
  const a = degrees * Math.PI / 180;
  const c = Math.cos(a), s = Math.sin(a);
  return add(add(scale(v, c), scale(cross(k, v), s)), scale(k, dot(k, v) * (1 - c)));
}

/** @returns {number[]} */
export function identity() {
  return [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
}

/** @param {Mat4} a @param {Mat4} b @returns {number[]} a * b */
export function multiply(a, b) {
  const out = new Array(16).fill(0);
  for (let c = 0; c < 4; c++) {
    for (let r = 0; r < 4; r++) {
      let s = 0;
      for (let k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k];
      out[c * 4 + r] = s;
    }
  }
  return out;
}

// inverse of a similarity transform (rotation * uniform scale, then translation)
/** @param {Mat4} m @returns {number[]} */
export function invertSimilarity(m) {
  const s2 = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
  const out = identity();
  for (let r = 0; r < 3; r++) for (let c = 0; c < 3; c++) out[c * 4 + r] = m[r * 4 + c] / s2;
  const t = [m[12], m[13], m[14]];
  for (let r = 0; r < 3; r++) out[12 + r] = -(out[r] * t[0] + out[4 + r] * t[1] + out[8 + r] * t[2]);
  return out;
}

/** @type {(m: Mat4, p: Vec3) => Vec3} */
export const transformPoint = (m, p) => [0, 1, 2].map((r) => m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r]);
/** @type {(m: Mat4, v: Vec3) => Vec3} */
export const transformVector = (m, v) => [0, 1, 2].map((r) => m[r] * v[0] + m[4 + r] * v[1] + m[8 + r] * v[2]);
/** @type {(m: Mat4, c: number) => Vec3} */
export const column = (m, c) => [m[c * 4], m[c * 4 + 1], m[c * 4 + 2]];

/** @param {Vec3} t @returns {number[]} */
export function fromTranslation(t) {
  const m = identity();
  m[12] = t[0]; m[13] = t[1]; m[14] = t[2];
  return m;
}

/** @param {number} s @returns {number[]} */
export function fromScale(s) {
  const m = identity();
  m[0] = m[5] = m[10] = s;
  return m;
}

/** @param {number[]} q @returns {number[]} the rotation matrix of the unit quaternion q = (x, y, z, w) */
export function fromQuaternion(q) {
  const [x, y, z, w] = q;
  return [1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w), 0,
    2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w), 0,
    2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y), 0,
    0, 0, 0, 1];
}

// angle (degrees) of the rotation part of a similarity transform
/** @param {Mat4} m @returns {number} */
export function rotationAngle(m) {
  const s = Math.sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
  const tr = (m[0] + m[5] + m[10]) / s;
  return Math.acos(Math.min(1, Math.max(-1, (tr - 1) / 2))) * 180 / Math.PI;
}

/** @type {(m: Mat4) => number} */
export const uniformScale = (m) => Math.sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
