// The display transform on the page (volumen/core/_tonemap.py; docs/design.md sections 5 and 10): every picture
// is ray cast linear into a LinearTarget (gl.js) and shown by the display pass (display.glsl), which applies the
// exposure, the tone curve and the sRGB encoding of the frame's Display, resolved by the server (`auto`: aces
// for the lit shading models, linear for the others). The curve's constants are the Python module's, served in
// info.json (`shader_constants()`), not written here.
//
// Metered exposure (Display.exposure null with the aces curve): `meter` below is core._tonemap.meter on the
// linear picture read back from the GPU: every pixel of a picture of at most METER_PIXELS pixels (the same
// exposure as the CPU picture's, to the half floats' rounding), else a nearest-neighbour subsample of that many.
// It is metered on each picture drawn; in VR on the first eye of each frame, and both eyes are shown with it.

import { RaycastProgram } from './program.js';

/** @import { LinearTarget } from './gl.js' */
/** @import { Display } from './viewer.js' */
/**
 * @typedef {object} DisplayConstants  core._tonemap.shader_constants(), served in info.json
 * @property {number[]} luma  the luminance's weights of R, G, B
 * @property {number} grey  the linear value the aces curve shows as middle grey (a metered subject's median)
 * @property {number[]} range  the metered exposure's (min, max), stops
 * @property {number[]} aces  the aces curve's constants
 * @property {number[]} srgb  the sRGB encoding's constants
 */

export const METER_PIXELS = 128 * 128;
/** @type {Record<string, number>} */
const TONEMAPS = { linear: 0, aces: 1 };

// core._tonemap.meter: the exposure (stops) that shows the median luminance of the subject (pixels of alpha >
// 0.5, else of alpha > 0) as middle grey, clamped to the range; `rgba` premultiplied linear, `k` the constants
/** @param {Float32Array} rgba @param {DisplayConstants} k @returns {number} */
export function meter(rgba, k) {
  /** @param {(alpha: number) => boolean} sel @returns {number[]} */
  const lum = (sel) => {
    const out = [];
    for (let i = 0; i < rgba.length; i += 4) {
      const a = rgba[i + 3];
      if (sel(a)) out.push((k.luma[0] * rgba[i] + k.luma[1] * rgba[i + 1] + k.luma[2] * rgba[i + 2]) / a);
    }
    return out;
  };
  let v = lum((a) => a > 0.5);
  if (!v.length) v = lum((a) => a > 0);
  if (!v.length) return 0;
  const sorted = Float64Array.from(v).sort();
  const m = sorted.length >> 1;
  const med = sorted.length % 2 ? sorted[m] : (sorted[m - 1] + sorted[m]) / 2;
  if (!(med > 0)) return k.range[1];
  return Math.min(Math.max(Math.log2(k.grey / med), k.range[0]), k.range[1]);
}

export class DisplayPass {
  /**
   * @param {WebGL2RenderingContext} gl @param {import('./program.js').StageSources} sources
   * @param {DisplayConstants} constants
   */
  constructor(gl, sources, constants) {
    this.gl = gl;
    this.k = constants;
    this.program = new RaycastProgram(gl, sources, 'display.glsl');
  }

  // the exposure (stops) to show the picture in `linear` (a LinearTarget) with, by `display` ({tonemap,
  // exposure} resolved): the given one, else metered (aces) or 0 (linear), as Display.stops
  /** @param {Display} display @param {LinearTarget} linear @returns {number} */
  stops(display, linear) {
    if (display.exposure !== null && display.exposure !== undefined) return display.exposure;
    if (display.tonemap !== 'aces') return 0;
    return meter(linear.read(METER_PIXELS).rgba, this.k);
  }

  // show `linear` in framebuffer `target`'s region `viewport` = [x, y, w, h] through the curve `tonemap`
  // with `stops` of exposure; `opaque` leaves the target's alpha as it is (an XR layer)
  /**
   * @param {LinearTarget} linear @param {WebGLFramebuffer | null} target @param {number[]} viewport
   * @param {string} tonemap @param {number} stops @param {boolean} [opaque]
   */
  draw(linear, target, viewport, tonemap, stops, opaque = false) {
    const gl = this.gl;
    const [x, y, w, h] = viewport;
    gl.bindFramebuffer(gl.FRAMEBUFFER, target);
    gl.viewport(x, y, w, h);
    if (opaque) gl.colorMask(true, true, true, false);
    const p = this.program.variant({});
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, linear.tex);
    this.program.set(p, { u_linear: 0, u_viewport: viewport, u_tonemap: TONEMAPS[tonemap], u_gain: 2 ** stops,
      u_aces: this.k.aces, u_srgb: this.k.srgb });
    this.program.draw();
    gl.colorMask(true, true, true, true);
  }
}
