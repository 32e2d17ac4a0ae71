// The view's state and its drawing: the scene (Scene.to_dict() JSON), the camera, the packed frame the server
// sent for that scene, and one draw of the ray caster into the canvas (or an XR view: xr.js calls drawView).
// A changed scene asks the server for its frame (tables, grids, illumination volumes, uniforms); a moved
// camera or light changes only the camera's and the lights' uniforms, drawn at once. A light moved away from
// where its illumination volume was built is drawn without that volume's shadows until the new one arrives.
// Every picture is ray cast linear into an offscreen target and shown through the display transform
// (display.js: the frame's resolved Display, its exposure given or metered on that picture).

import { postBinary } from './api.js';
import { lightUniforms, packCamera } from './camera.js';
import { LinearTarget, readRGBA } from './gl.js';

/** @import { Camera, Light, LightUniforms, PackedCamera } from './camera.js' */
/** @import { DisplayConstants, DisplayPass } from './display.js' */
/** @import { Textures } from './gl.js' */
/** @import { RaycastProgram, Uniforms } from './program.js' */
/** @import { Vec3 } from './linalg.js' */
/**
 * @typedef {object} TransferFunction  TransferFunction.to_dict(): control points [value, ...] of each channel
 * @property {string} [name]
 * @property {number[][]} color
 * @property {number[][]} opacity
 */
/**
 * @typedef {object} Display  Display.to_dict(): the curve ('auto', 'linear', 'aces') and the exposure (stops;
 *   null: metered)
 * @property {string} tonemap
 * @property {number | null} exposure
 */
/**
 * @typedef {object} Scene  Scene.to_dict(), with the fields the page reads or edits (the others pass through)
 * @property {string} mode
 * @property {TransferFunction} transfer
 * @property {{mode: string}} shading
 * @property {Light[]} lights
 * @property {{value: number}} isosurface
 * @property {{crop: number[] | null, crop_space: string}} clipping
 * @property {Display} display
 * @property {{samples_per_voxel: number}} sampling
 */
/**
 * @typedef {object} VolumeInfo  the served volume (web._served.ServedVolume.info)
 * @property {number[]} shape  (nz, ny, nx)
 * @property {number[]} spacing
 * @property {number[][]} affine  4 x 4, rows
 * @property {Vec3} center
 * @property {number} diagonal
 * @property {number[]} value_range
 * @property {{level: number, width: number}} window
 */
/**
 * @typedef {object} Info  info.json
 * @property {VolumeInfo} volume
 * @property {Scene} scene
 * @property {Camera} camera
 * @property {string[]} presets
 * @property {Record<string, TransferFunction>} transfers
 * @property {number} shift
 * @property {string[]} notices
 * @property {DisplayConstants} display
 * @property {{max_lights: number, max_planes: number, budget_mb: number}} limits
 */
/** @typedef {{u_nlights: number, u_lvm: number[], u_lpos: number[]} & Uniforms} FrameUniforms */
/**
 * @typedef {object} FrameHeader  the header of a /frame.bin answer (web._frames.pack_frame)
 * @property {Record<string, number>} defines
 * @property {FrameUniforms} uniforms
 * @property {Display} display  resolved: the curve is 'linear' or 'aces'
 */
/** @typedef {'scene' | 'camera' | 'drawn' | 'error'} Change */
/** @typedef {(w: number, h: number) => PackedCamera} PackFor  the packed camera for a picture of w x h pixels */

export const REDUCED_FRACTION = 0.5;   // picture scale while dragging (notebook/_loop.py)
const LATTICE = 1;                     // raycast._params: an illumination volume's kind

export class Viewer {
  /**
   * @param {object} parts
   * @param {WebGL2RenderingContext & {canvas: HTMLCanvasElement}} parts.gl
   * @param {RaycastProgram} parts.program
   * @param {DisplayPass} parts.display
   * @param {Textures} parts.textures
   * @param {Info} parts.info
   * @param {number} parts.max3d  the browser's 3-D texture size, sent with every request for the volume
   */
  constructor({ gl, program, display, textures, info, max3d }) {
    this.gl = gl;
    this.program = program;
    this.display = display;
    this.textures = textures;
    this.info = info;
    this.max3d = max3d;
    this.scene = info.scene;
    this.camera = info.camera;
    /** @type {FrameHeader | null} the last frame received */
    this.frame = null;
    this.seq = 0;               // frames asked for
    this.pending = 0;           // frames asked for and not yet received
    this.interacting = false;
    this.xrActive = false;      // an XR session draws (xr.js), not the canvas's animation frames
    this.fixedSize = false;     // the canvas's size is set by window.volumen.show, not fitted to the page
    this.scheduled = false;     // an animation frame is requested
    this.linear = new LinearTarget(gl);
    /** @type {{tonemap: string, exposure: number} | null} of the last picture drawn */
    this.shown = null;
    /** @type {((what: Change) => void)[]} */
    this.listeners = [];
    /** @type {(() => void)[]} */
    this.waiters = [];
    /** @type {(() => void)[]} */
    this.idleWaiters = [];
    /** @type {string | null} */
    this.error = null;
    this.lastDraw = { ms: 0, size: [0, 0], scale: 1 };
  }

  get maxLights() { return this.info.limits.max_lights; }

  /** @param {(what: Change) => void} fn */
  onChange(fn) { this.listeners.push(fn); }

  // a new scene (or a part of it): ask for its frame; the picture follows when it arrives
  /** @param {Scene} scene */
  setScene(scene) {
    this.scene = scene;
    this.requestFrame();
    this.listeners.forEach((fn) => fn('scene'));
  }

  /** @param {Camera} camera */
  setCamera(camera) {
    this.camera = camera;
    if (this.needsFrameForCamera()) this.requestFrame();
    this.redraw();
    this.listeners.forEach((fn) => fn('camera'));
  }

  // lights attached to the camera cast their shadows from where the camera is
  needsFrameForCamera() {
    return !this.interacting && ['shadows', 'scattering'].includes(this.scene.shading.mode)
      && this.scene.lights.some((lt) => lt.attach === 'camera');
  }

  async requestFrame() {
    const seq = ++this.seq;
    this.pending++;
    const canvas = this.gl.canvas;
    try {
      const { header, arrays } = await postBinary('frame.bin', { scene: this.scene, camera: this.camera,
        size: [canvas.width, canvas.height], max3d: this.max3d, seq });
      if (seq === this.seq) {   // answers to older requests are dropped
        this.textures.setFrame(arrays);
        this.frame = /** @type {FrameHeader} */ (header);
        this.error = null;
      }
    } catch (e) {
      if (seq === this.seq) this.error = String((e instanceof Error && e.message) || e);
      this.listeners.forEach((fn) => fn('error'));
    } finally {
      this.pending--;
      if (this.pending === 0) this.idleWaiters.splice(0).forEach((resolve) => resolve());
      this.redraw();
    }
  }

  redraw() {
    if (this.scheduled) return;
    this.scheduled = true;
    requestAnimationFrame(() => {
      this.scheduled = false;
      if (!this.xrActive) this.drawCanvas();
    });
  }

  // resolves when no frame asked for is still on its way
  /** @returns {Promise<void>} */
  idle() {
    if (this.pending === 0) return Promise.resolve();
    return new Promise((resolve) => this.idleWaiters.push(resolve));
  }

  // resolves after the picture of the current state is on the canvas
  /** @returns {Promise<void>} */
  settled() {
    return new Promise((resolve) => { this.waiters.push(resolve); this.redraw(); });
  }

  // every uniform of one picture: `frame`'s, the camera's (`packed`, packCamera's), the lights' and the
  // textures'; `origin` the framebuffer pixel of the picture's bottom-left corner
  /**
   * @param {FrameHeader} frame @param {PackedCamera} packed @param {Camera} camera @param {number[]} origin
   * @returns {Uniforms}
   */
  uniforms(frame, packed, camera, origin) {
    const lit = frame.uniforms.u_nlights > 0;
    const lights = lightUniforms(this.scene, camera, lit, this.maxLights);
    /** @type {Uniforms} */
    const u = { ...frame.uniforms, ...packed, ...lights, ...this.textures.bind(), u_origin: origin };
    u.u_lvm = staleVolumesOff(frame.uniforms, lights, this.maxLights);
    return u;
  }

  // draw the ray caster into framebuffer `target`'s region `viewport` = [x, y, w, h]: ray cast linear into the
  // offscreen target at the viewport's size (`scaleDown` < 1: smaller, stretched when shown: reduced
  // resolution), then shown through the display transform with `stops` of exposure (null: the frame's Display,
  // given or metered on this picture). `shift` moves the picture's centre by that fraction of its size (an XR
  // eye's off-axis projection); `opaque` leaves the target's alpha as it is (an XR layer, cleared opaque: the
  // picture over black, as a headset shows it). Returns the exposure used (both XR eyes are shown with one).
  /**
   * @param {WebGLFramebuffer | null} target @param {number[]} viewport @param {PackFor} packedFor
   * @param {Camera} camera @param {number} [scaleDown] @param {number[]} [shift] @param {boolean} [opaque]
   * @param {number | null} [stops]
   * @returns {number}
   */
  drawView(target, viewport, packedFor, camera, scaleDown = 1, shift = [0, 0], opaque = false, stops = null) {
    const frame = this.frame;
    if (!frame) throw new Error('drawView before the first frame arrived');
    const [, , w, h] = viewport;
    const p = this.program.variant(frame.defines);
    const s = Math.min(scaleDown, 1);
    const rw = Math.max(1, Math.round(w * s)), rh = Math.max(1, Math.round(h * s));
    this.linear.use(rw, rh);
    this.program.set(p, this.uniforms(frame, packedFor(rw, rh), camera, [shift[0] * rw, shift[1] * rh]));
    this.program.draw();
    const display = frame.display;
    const ev = stops ?? this.display.stops(display, this.linear);
    this.display.draw(this.linear, target, viewport, display.tonemap, ev, opaque);
    this.shown = { tonemap: display.tonemap, exposure: ev };
    return ev;
  }

  drawCanvas() {
    const gl = this.gl;
    const w = gl.canvas.width, h = gl.canvas.height;
    if (this.frame && this.textures.ready) {
      const t0 = performance.now();
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      gl.viewport(0, 0, w, h);
      gl.clearColor(0, 0, 0, 0);
      gl.clear(gl.COLOR_BUFFER_BIT);
      const scale = this.interacting ? REDUCED_FRACTION : 1;
      this.drawView(null, [0, 0, w, h], (pw, ph) => packCamera(this.camera, pw, ph), this.camera, scale);
      this.lastDraw = { ms: performance.now() - t0, size: [w, h], scale };
    }
    this.listeners.forEach((fn) => fn('drawn'));
    if (this.pending === 0 && this.frame) {
      const done = this.waiters.splice(0);
      done.forEach((resolve) => resolve());
    }
  }

  // the canvas as RGBA8, rows from the top
  read() {
    const gl = this.gl;
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    return readRGBA(gl, [0, 0, gl.canvas.width, gl.canvas.height]);
  }

  // the last picture before the display transform: premultiplied linear RGBA (Float32Array), rows from the top
  readLinear() {
    const { rgba, size: [w, h] } = this.linear.read();
    const out = new Float32Array(rgba.length);
    for (let r = 0; r < h; r++) out.set(rgba.subarray((h - 1 - r) * w * 4, (h - r) * w * 4), r * w * 4);
    return { rgba: out, width: w, height: h };
  }

  // milliseconds per picture: the median of `n` pictures drawn back to back, each finished (a pixel read
  // back) before the next
  /** @param {number} n @returns {number} */
  timeFrames(n) {
    const gl = this.gl;
    const w = gl.canvas.width, h = gl.canvas.height;
    const one = new Uint8Array(4), ms = [];
    for (let i = 0; i < n; i++) {
      const t0 = performance.now();
      this.drawView(null, [0, 0, w, h], (pw, ph) => packCamera(this.camera, pw, ph), this.camera);
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, one);
      ms.push(performance.now() - t0);
    }
    return ms.sort((a, b) => a - b)[Math.floor(n / 2)];
  }
}

// the frame's illumination-volume meta rows, with the kind of every light that moved away from where its
// lattice was built set to none (drawn unshadowed until the server sends the new lattice)
/** @param {FrameUniforms} frameUniforms @param {LightUniforms} lights @param {number} maxLights */
function staleVolumesOff(frameUniforms, lights, maxLights) {
  const lvm = Float32Array.from(frameUniforms.u_lvm);
  const built = frameUniforms.u_lpos;
  for (let i = 0; i < Math.min(lights.u_nlights, maxLights); i++) {
    if (lvm[16 * i] !== LATTICE) continue;
    const moved = [0, 1, 2].some((c) => Math.abs(built[3 * i + c] - lights.u_lpos[3 * i + c]) > 1e-3);
    if (moved) lvm[16 * i] = 0;
  }
  return lvm;
}
