// The immersive-vr session: each eye ray cast with its XR view's pose and projection, the volume placed in
// the room (table-top or life size), controllers to grab it and to place, drag and delete lights, and a
// frame-time governor.
//
// Placement: `model` maps the volume's world mm (RAS+) to the 'local' reference space (metres, y up); an eye
// seen from the volume is model^-1 * view.transform, so the ray caster marches in mm as everywhere else.
// Controllers (xr-standard gamepads): squeeze (grip) grabs the volume and moves and turns it with the hand,
// both grips scale it; the trigger places a spot light at the controller, pointing along its ray, and drags
// it while held; A / X deletes the light nearest the controller; B / Y hands the controller's ray to `onRay`
// (the ruler's pick: xrruler.js); the thumbstick pushed left or right cycles the presets. What `overlays` draw
// goes over each eye's picture. Governor: past the display's frame time the step grows (samples per voxel halve, down to a
// quarter), then the resolution drops (to half); well under it, they come back.

import { eyeCamera } from './camera.js';
import { add, column, fromScale, fromTranslation, invertSimilarity, multiply, norm, scale, sub, transformPoint,
  transformVector, unit } from './linalg.js';
import { readRGBA } from './gl.js';

/** @import { Camera, PackedCamera } from './camera.js' */
/** @import { Mat4, Vec3 } from './linalg.js' */
/** @import { Viewer } from './viewer.js' */
/** @typedef {XRViewerPose['views'][number]} EyeView  one eye of WebXR's viewer pose (its type XRView) */
/**
 * @typedef {object} Hand  a controller's state between frames
 * @property {boolean[]} pressed  its buttons in the last frame
 * @property {number | null} light  the index of the light its trigger drags
 * @property {{start: number[], model: number[]} | null} grab  the hand and the model when the grip was pressed
 * @property {number[]} [matrix]  its pose (the target ray space's) in the 'local' space
 * @property {boolean} [stick]  its thumbstick is pushed aside (a preset step taken)
 */
/**
 * @typedef {object} Eye  an eye of the last XR frame
 * @property {string} eye  'left', 'right' or 'none'
 * @property {number[]} viewport  [x, y, w, h] in the layer's framebuffer
 * @property {Camera} camera
 * @property {{tonemap: string, exposure: number} | null} shown
 */
/** @typedef {Eye & {rgba: Uint8Array}} Shot  an eye's picture (RGBA8, rows from the top) */

const BUTTON = { trigger: 0, squeeze: 1, a: 4, b: 5 };
// volume axes (RAS) -> room axes (x right, y up, z toward the viewer)
const TABLE_TOP = [-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1];   // lying: anterior up, superior away
const LIFE_SIZE = [-1, 0, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 1];    // standing, facing the viewer
const GOVERNOR_LEVELS = [[1, 1], [0.5, 1], [0.25, 1], [0.25, 0.75], [0.25, 0.5]];   // (samples per voxel, scale)

/** @returns {Promise<boolean>} */
export async function xrSupported() {
  return Boolean(navigator.xr && await navigator.xr.isSessionSupported('immersive-vr').catch(() => false));
}

export class XRView {
  /**
   * @param {Viewer} viewer
   * @param {object} callbacks
   * @param {(step: number) => void} callbacks.onPreset  a thumbstick asks for the next (1) or previous (-1) preset
   * @param {(what: string) => void} callbacks.onChange  'xr' (entered), 'xr-end', 'governor' (its level changed)
   */
  constructor(viewer, { onPreset, onChange }) {
    this.viewer = viewer;
    this.onPreset = onPreset;
    this.onChange = onChange;
    /** @type {XRSession | null} */
    this.session = null;
    /** @type {XRReferenceSpace | null} */
    this.ref = null;
    this.governor = true;
    this.level = 0;
    this.base = 1;              // the scene's samples per voxel when the session began (the governor's level 0)
    /** @type {number[]} */
    this.frameTimes = [];
    /** @type {((shots: Shot[]) => void)[]} */
    this.captures = [];
    /** @type {{n: number, resolve: () => void}[]} */
    this.frameWaiters = [];
    /** @type {Map<string, Hand>} by handedness */
    this.hands = new Map();
    this.placement = 'table-top';
    /** @type {number[]} the volume's world mm -> the 'local' space */
    this.model = [];
    this.place(this.placement);
    /** @type {Eye[] | undefined} the eyes of the last frame drawn */
    this.lastEyes = undefined;
    /** @type {{n: number, ms: number[], resolve: (ms: number) => void} | null} timeFrames' measure in progress */
    this.timing = null;
    /** @type {(ray: {position: Vec3, direction: Vec3}) => void} a B / Y press: the controller's ray, volume mm */
    this.onRay = () => {};
    /** @type {((gl: WebGL2RenderingContext, eye: Eye, shift: number[]) => void)[]} drawn over each eye */
    this.overlays = [];
  }

  // model matrix: table-top, the volume 0.4 m across (its diagonal), its centre 0.6 m ahead of the viewer and
  // 0.25 m below; life-size, the volume at its own size, its centre 1.2 m ahead
  /** @param {string} kind 'table-top' or 'life-size' */
  place(kind) {
    const v = this.viewer.info.volume;
    this.placement = kind;
    const s = kind === 'life-size' ? 0.001 : 0.4 / v.diagonal;
    const at = kind === 'life-size' ? [0, 0, -1.2] : [0, -0.25, -0.6];
    const turn = kind === 'life-size' ? LIFE_SIZE : TABLE_TOP;
    this.model = multiply(fromTranslation(at), multiply(turn, multiply(fromScale(s), fromTranslation(scale(v.center, -1)))));
  }

  async enter() {
    const gl = this.viewer.gl;
    if (!navigator.xr) throw new Error('this browser has no WebXR');
    const session = await navigator.xr.requestSession('immersive-vr');
    await gl.makeXRCompatible?.();
    session.updateRenderState({ baseLayer: new XRWebGLLayer(session, gl) });
    this.ref = await session.requestReferenceSpace('local');
    this.session = session;
    this.viewer.xrActive = true;
    this.place(this.placement);
    this.base = this.viewer.scene.sampling.samples_per_voxel;
    session.addEventListener('end', () => {
      this.session = null;
      this.viewer.xrActive = false;
      this.viewer.redraw();
      this.onChange('xr-end');
    });
    session.requestAnimationFrame((t, f) => this.onFrame(t, f));
    this.onChange('xr');
  }

  async exit() { if (this.session) await this.session.end(); }

  // eye of `view` in volume mm: {packed, camera, shift}
  /**
   * @param {EyeView} view @param {XRViewport} vp
   * @returns {{packed: PackedCamera, camera: Camera, shift: number[]}}
   */
  eye(view, vp) {
    const e = multiply(invertSimilarity(this.model), view.transform.matrix);
    const p = view.projectionMatrix;
    const { packed, camera } = eyeCamera(column(e, 3), unit(column(e, 0)), unit(column(e, 1)),
      scale(unit(column(e, 2)), -1), 1 / p[5], vp.width, vp.height);
    return { packed, camera, shift: [-p[8] / 2, -p[9] / 2] };
  }

  /** @param {DOMHighResTimeStamp} _time @param {XRFrame} frame */
  onFrame(_time, frame) {
    const session = frame.session;
    session.requestAnimationFrame((t2, f2) => this.onFrame(t2, f2));
    const ref = this.ref, layer = session.renderState.baseLayer;
    if (!ref || !layer) return;
    const pose = frame.getViewerPose(ref);
    this.controllers(frame, ref);
    const viewer = this.viewer;
    if (!pose || !viewer.frame || !viewer.textures.ready) return;
    const gl = viewer.gl;
    const t0 = performance.now();
    gl.bindFramebuffer(gl.FRAMEBUFFER, layer.framebuffer);
    gl.clearColor(0, 0, 0, 1);
    gl.clear(gl.COLOR_BUFFER_BIT);
    /** @type {Eye[]} */
    const eyes = [];
    /** @type {number | null} */
    let stops = null;   // the exposure: metered on the first eye (when it is metered), both eyes shown with it
    for (const view of pose.views) {
      const vp = layer.getViewport(view);
      if (!vp || vp.width === 0 || vp.height === 0) continue;
      const { packed, camera, shift } = this.eye(view, vp);
      const s = this.governor ? GOVERNOR_LEVELS[this.level][1] : 1;
      stops = viewer.drawView(layer.framebuffer, [vp.x, vp.y, vp.width, vp.height],
        (w, h) => ({ ...packed, u_wh: [w, h] }), camera, s, shift, true, stops);
      const eye = { eye: view.eye, viewport: [vp.x, vp.y, vp.width, vp.height], camera, shown: viewer.shown };
      this.overlays.forEach((draw) => draw(gl, eye, shift));
      eyes.push(eye);
    }
    const waiting = this.captures.splice(0);
    if (waiting.length) {
      gl.bindFramebuffer(gl.FRAMEBUFFER, layer.framebuffer);
      const shots = eyes.map((e) => ({ ...e, rgba: readRGBA(gl, e.viewport) }));
      waiting.forEach((resolve) => resolve(shots));
    }
    this.lastEyes = eyes;
    if (this.timing) this.timeFrame(gl, t0);
    this.record(performance.now() - t0);
    if (this.governor) this.govern();
    this.frameWaiters = this.frameWaiters.filter((w) => --w.n > 0 || (w.resolve(), false));
  }

  // milliseconds to draw both eyes, each frame finished (a pixel read back) before the next: the median of
  // `n` frames (the benchmark's measure; the governor's is the time to submit)
  /** @param {number} n @returns {Promise<number>} */
  timeFrames(n) {
    return new Promise((resolve) => { this.timing = { n, ms: [], resolve }; });
  }

  /** @param {WebGL2RenderingContext} gl @param {number} t0 the frame's start (performance.now()) */
  timeFrame(gl, t0) {
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
    const tm = this.timing;
    if (!tm) return;
    tm.ms.push(performance.now() - t0);
    if (tm.ms.length >= tm.n) {
      this.timing = null;
      tm.resolve(tm.ms.sort((a, b) => a - b)[Math.floor(tm.ms.length / 2)]);
    }
  }

  // resolves after `n` more XR frames were drawn
  /** @param {number} [n] @returns {Promise<void>} */
  afterFrames(n = 1) {
    return new Promise((resolve) => this.frameWaiters.push({ n, resolve }));
  }

  // the next frame's pictures of both eyes (after the pending frame of the server, if any, arrived)
  /** @returns {Promise<Shot[]>} */
  async capture() {
    await this.viewer.idle();
    return new Promise((resolve) => this.captures.push(resolve));
  }

  // ---- controllers ----
  /** @param {XRFrame} frame @param {XRReferenceSpace} ref */
  controllers(frame, ref) {
    for (const src of frame.session.inputSources) {
      if (!src.gamepad) continue;
      const ray = frame.getPose(src.targetRaySpace, ref);
      if (!ray) continue;
      /** @type {Hand} */
      const hand = this.hands.get(src.handedness) ?? { pressed: [], light: null, grab: null };
      this.hands.set(src.handedness, hand);
      const b = src.gamepad.buttons.map((x) => x.pressed || x.value > 0.5);
      const was = hand.pressed;
      hand.matrix = Array.from(ray.transform.matrix);   // the controller (its grip space moves rigidly with it)
      if (b[BUTTON.squeeze] && !was[BUTTON.squeeze]) hand.grab = { start: hand.matrix, model: this.model };
      if (!b[BUTTON.squeeze]) hand.grab = null;
      if (b[BUTTON.trigger] && !was[BUTTON.trigger]) this.placeLight(hand, ray.transform.matrix);
      else if (b[BUTTON.trigger] && hand.light !== null) this.dragLight(hand, ray.transform.matrix);
      if (!b[BUTTON.trigger] && was[BUTTON.trigger] && hand.light !== null) {
        hand.light = null;
        this.viewer.setScene({ ...this.viewer.scene });   // the illumination volumes of the new position
      }
      if (b[BUTTON.a] && !was[BUTTON.a]) this.deleteNearest(ray.transform.matrix);
      if (b[BUTTON.b] && !was[BUTTON.b]) this.onRay(this.toVolume(ray.transform.matrix));
      const x = src.gamepad.axes[2] ?? 0;
      if (Math.abs(x) > 0.7 && !hand.stick) this.onPreset(Math.sign(x));
      hand.stick = Math.abs(x) > 0.3 ? (hand.stick || Math.abs(x) > 0.7) : false;
      hand.pressed = b;
    }
    this.grab();
  }

  // one hand: the volume follows the hand rigidly (model = hand * hand0^-1 * model0); two hands: it also
  // scales by the change of the distance between them, about their midpoint
  grab() {
    // a hand's pose is set in every frame it is tracked, before its grab can be
    const grabbing = [...this.hands.values()].filter(
      /** @type {(h: Hand) => h is Hand & {grab: {start: number[], model: number[]}, matrix: number[]}} */
      (h) => Boolean(h.grab && h.matrix));
    if (grabbing.length === 1) {
      const h = grabbing[0];
      this.model = multiply(h.matrix, multiply(invertSimilarity(h.grab.start), h.grab.model));
    } else if (grabbing.length === 2) {
      const [a, b] = grabbing;
      const pa = column(a.matrix, 3), pb = column(b.matrix, 3);
      const pa0 = column(a.grab.start, 3), pb0 = column(b.grab.start, 3);
      const k = norm(sub(pa, pb)) / Math.max(norm(sub(pa0, pb0)), 1e-6);
      const mid = scale(add(pa, pb), 0.5), mid0 = scale(add(pa0, pb0), 0.5);
      this.model = multiply(fromTranslation(mid), multiply(fromScale(k), multiply(fromTranslation(scale(mid0, -1)),
        a.grab.model)));
    }
  }

  // the controller pose `m` as a light's position and direction in volume mm (the ray's origin, pointing along it)
  /** @param {Mat4} m @returns {{position: Vec3, direction: Vec3}} */
  toVolume(m) {
    const inv = invertSimilarity(this.model);
    return { position: transformPoint(inv, column(m, 3)), direction: unit(transformVector(inv, scale(column(m, 2), -1))) };
  }

  /** @param {Hand} hand @param {Mat4} m */
  placeLight(hand, m) {
    const viewer = this.viewer;
    const { position, direction } = this.toVolume(m);
    const light = { position, direction, intensity: 1, color: [1, 1, 1], exponent: 10, kind: 'spot', attach: 'world',
      radius: 0 };
    const sc = viewer.scene;
    if (sc.lights.length >= viewer.maxLights) return;
    const shading = ['none', 'headlight'].includes(sc.shading.mode) ? { ...sc.shading, mode: 'phong' } : sc.shading;
    hand.light = sc.lights.length;
    viewer.setScene({ ...sc, shading, lights: [...sc.lights, light] });
  }

  /** @param {Hand} hand @param {Mat4} m */
  dragLight(hand, m) {
    const viewer = this.viewer, i = hand.light;
    if (i === null) return;
    const lights = viewer.scene.lights.slice();
    lights[i] = { ...lights[i], ...this.toVolume(m) };
    viewer.scene = { ...viewer.scene, lights };   // drawn at once; its shadows when the trigger is released
  }

  /** @param {Mat4} m */
  deleteNearest(m) {
    const viewer = this.viewer;
    const p = this.toVolume(m).position;
    const lights = viewer.scene.lights;
    if (!lights.length) return;
    let best = 0;
    lights.forEach((lt, i) => { if (norm(sub(lt.position, p)) < norm(sub(lights[best].position, p))) best = i; });
    viewer.setScene({ ...viewer.scene, lights: lights.filter((_, i) => i !== best) });
  }

  // ---- frame-time governor ----
  /** @param {number} drawMs */
  record(drawMs) {
    this.frameTimes.push(drawMs);
    if (this.frameTimes.length > 120) this.frameTimes.shift();
  }

  // one step of the governor over the last 10 frame times (called each frame while it is on)
  govern() {
    const budget = 1000 / (this.session?.frameRate || 72);
    const recent = this.frameTimes.slice(-10);
    if (recent.length < 10) return;
    const mean = recent.reduce((a, b) => a + b, 0) / recent.length;
    let level = this.level;
    if (mean > 1.1 * budget && level < GOVERNOR_LEVELS.length - 1) level++;
    else if (mean < 0.5 * budget && level > 0) level--;
    if (level !== this.level) {
      const spv = GOVERNOR_LEVELS[level][0] * this.base;
      if (GOVERNOR_LEVELS[level][0] !== GOVERNOR_LEVELS[this.level][0]) {
        this.viewer.setScene({ ...this.viewer.scene, sampling: { ...this.viewer.scene.sampling, samples_per_voxel: spv } });
      }
      this.level = level;
      this.frameTimes = [];
      this.onChange('governor');
    }
  }

  stats() {
    const ft = this.frameTimes;
    const mean = ft.length ? ft.reduce((a, b) => a + b, 0) / ft.length : 0;
    return { frames: ft.length, mean_ms: mean, level: this.level, governor: this.governor,
      samples_per_voxel: this.viewer.scene.sampling.samples_per_voxel, scale: GOVERNOR_LEVELS[this.level][1] };
  }
}

