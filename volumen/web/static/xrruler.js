// The ruler in the headset: B / Y on a controller picks the first visible surface along its ray (the 3-D
// ruler's pick: ruler3d.js, pick.json), two picks make a ruler, and each eye's picture shows every ruler with
// its length beside it, in millimetres. Drawn into the XR layer with scissored clears (a line of small squares,
// the digits as seven segments), so no second shader program is needed.

import { project } from './camera.js';
import { norm, sub } from './linalg.js';

/** @import { PictureRuler } from './ruler3d.js' */
/** @import { XRView } from './xr.js' */
/** @import { Camera } from './camera.js' */
/** @import { Vec3 } from './linalg.js' */

const COLOUR = [1, 0.92, 0.24, 1];
const DOT = 3;          // px: the line's squares
const DIGITS = 40;      // a digit is the eye picture's height over this (at least 10 px; its width is half)
// the seven segments (a top, b top right, c bottom right, d bottom, e bottom left, f top left, g middle) of
// each character drawn; 'm' is three legs under a bar
/** @type {Record<string, string>} */
const GLYPHS = { 0: 'abcdef', 1: 'bc', 2: 'abged', 3: 'abgcd', 4: 'fgbc', 5: 'afgcd', 6: 'afgedc', 7: 'abc',
  8: 'abcdefg', 9: 'abcdfg', m: 'gec', '-': 'g' };

export class XRRuler {
  /** @param {XRView} xr @param {PictureRuler} ruler */
  constructor(xr, ruler) {
    this.ruler = ruler;
    xr.onRay = ({ position, direction }) => ruler.pickRay(position, direction);
    xr.overlays.push((gl, eye, shift) => this.drawEye(gl, eye.viewport, eye.camera, shift, eye.eye));
    /** @type {Record<string, {ends: number[][], text: string}[]>} by eye: what the last frame drew (viewport px
     * from the top left) */
    this.drawn = {};
  }

  /**
   * @param {WebGL2RenderingContext} gl
   * @param {number[]} viewport  [x, y, w, h] in the layer's framebuffer
   * @param {Camera} camera  the eye's
   * @param {number[]} shift  the eye's off-axis shift (fractions of the viewport: viewer.drawView's)
   * @param {string} eye
   */
  drawEye(gl, viewport, camera, shift, eye) {
    const [vx, vy, w, h] = viewport;
    /** @type {(p: Vec3) => number[]} viewport px from the top left, and the depth */
    const at = (p) => {
      const [c, r, z] = project(camera, p, [w, h]);
      return [c + shift[0] * w, r - shift[1] * h, z];
    };
    const drawn = [];
    gl.enable(gl.SCISSOR_TEST);
    gl.clearColor(COLOUR[0], COLOUR[1], COLOUR[2], COLOUR[3]);
    /** @type {(x: number, y: number, sw: number, sh: number) => void} a filled box, viewport px from the top
     * left, cut to the viewport (the other eye's picture is beside it in the layer) */
    const box = (x, y, sw, sh) => {
      const x0 = Math.max(0, Math.round(x)), x1 = Math.min(w, Math.round(x + Math.max(sw, 1)));
      const y0 = Math.max(0, Math.round(y)), y1 = Math.min(h, Math.round(y + Math.max(sh, 1)));
      if (x1 <= x0 || y1 <= y0) return;
      gl.scissor(vx + x0, vy + h - y1, x1 - x0, y1 - y0);
      gl.clear(gl.COLOR_BUFFER_BIT);
    };
    for (const m of this.ruler.measures.items) {
      if (m.kind !== 'distance') continue;
      const [a, b] = m.points.map(at);
      if (a[2] <= 0 || b[2] <= 0) continue;   // behind the eye
      const n = Math.ceil(Math.hypot(b[0] - a[0], b[1] - a[1]) / (DOT / 2)) + 1;
      for (let k = 0; k < n; k++) {
        const t = n > 1 ? k / (n - 1) : 0;
        box(a[0] + t * (b[0] - a[0]) - DOT / 2, a[1] + t * (b[1] - a[1]) - DOT / 2, DOT, DOT);
      }
      const text = `${norm(sub(m.points[1], m.points[0])).toFixed(1)} mm`;
      const digit = Math.max(10, Math.round(h / DIGITS)), wide = text.length * (digit / 2 + 3);
      const right = Math.max(a[0], b[0]) + 6;   // beside the ruler, on its left where the right has no room
      const left = right + wide <= w ? right : Math.max(0, Math.min(a[0], b[0]) - 6 - wide);
      this.text(box, text, left, Math.max(0, Math.min(a[1], b[1]) - digit - 4), digit);
      drawn.push({ ends: [a.slice(0, 2), b.slice(0, 2)], text });
    }
    gl.scissor(vx, vy, w, h);
    gl.disable(gl.SCISSOR_TEST);
    this.drawn[eye] = drawn;
  }

  /**
   * @param {(x: number, y: number, w: number, h: number) => void} box
   * @param {string} text  digits, '.', ' ', 'm'
   * @param {number} x @param {number} y  its top left, viewport px
   * @param {number} digit  a digit's height, px
   */
  text(box, text, x, y, digit) {
    const W = digit / 2, H = digit / 2, s = Math.max(1, Math.round(digit / 6));
    /** @type {Record<string, number[]>} each segment's box [x, y, w, h] in a character's cell */
    const seg = { a: [0, 0, W, s], b: [W - s, 0, s, H], c: [W - s, H, s, H], d: [0, 2 * H - s, W, s],
      e: [0, H, s, H], f: [0, 0, s, H], g: [0, H - s / 2, W, s] };
    for (const ch of text) {
      if (ch === '.') { box(x, y + 2 * H - s, s, s); x += s + 2; continue; }
      if (ch === ' ') { x += W / 2; continue; }
      const segments = GLYPHS[ch] ?? '';
      for (const name of segments) {
        const [sx, sy, sw, sh] = seg[name];
        box(x + sx, y + sy, sw, sh);
      }
      if (ch === 'm') box(x + W / 2 - s / 2, y + H, s, H);   // the middle leg
      x += W + 3;
    }
  }
}
