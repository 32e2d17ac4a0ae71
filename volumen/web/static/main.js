// The page: load the scan (info, shaders, the volume as a 3-D texture), then the view, its gestures and
// overlay, the slice views, the panel and VR. `window.volumen` is the page's script interface (tests,
// benchmarks): set a view, read the picture back, enter VR and read both eyes.

import { getBinary, getJSON } from './api.js';
import { attachGestures, aimLight, dragZoom, moveLight, orbit, pan, wheelZoom } from './camera.js';
import { DisplayPass } from './display.js';
import { createContext, limits, Textures } from './gl.js';
import { drawOverlay, lightLength, pickLight } from './overlay.js';
import { RaycastProgram } from './program.js';
import { SliceMeasures } from './measure.js';
import { ProfilePlot } from './profile.js';
import { PictureRuler } from './ruler3d.js';
import { XRRuler } from './xrruler.js';
import { SliceViews } from './slices.js';
import { Panel, shifted } from './ui.js';
import { Viewer } from './viewer.js';
import { XRView, xrSupported } from './xr.js';

/** @import { Camera, Size } from './camera.js' */
/** @import { Scene } from './viewer.js' */

// the page's element `id`, of the class `type` (index.html has them all)
/** @template {HTMLElement} T @param {string} id @param {new () => T} type @returns {T} */
function element(id, type) {
  const e = document.getElementById(id);
  if (!(e instanceof type)) throw new Error(`the page has no ${type.name} #${id}`);
  return e;
}

const status = element('status', HTMLParagraphElement);

/** @param {Uint8Array} bytes @returns {string} */
function base64(bytes) {
  let s = '';
  for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(s);
}

/** @param {Viewer} viewer @param {HTMLCanvasElement} overlay */
function fitCanvases(viewer, overlay) {
  const parent = viewer.gl.canvas.parentElement;
  if (!parent) return;
  const box = parent.getBoundingClientRect();
  const w = Math.max(1, Math.round(box.width * devicePixelRatio));
  const h = Math.max(1, Math.round(box.height * devicePixelRatio));
  if (viewer.fixedSize || viewer.xrActive) return;
  for (const c of [viewer.gl.canvas, overlay]) { c.width = w; c.height = h; }
  viewer.redraw();
}

async function boot() {
  const canvas = element('gl', HTMLCanvasElement), overlay = element('overlay', HTMLCanvasElement);
  const gl = createContext(canvas);
  const lim = limits(gl);
  const max3d = lim.max3d;
  const [info, sources, volume] = await Promise.all([getJSON('info.json', { max3d }), getJSON('shaders.json'),
    getBinary('volume.bin', { max3d })]);
  const textures = new Textures(gl);
  const volumeHeader = /** @type {{shape: number[], vol_map: number[], notices: string[]}} */ (volume.header);
  textures.setVolume(volumeHeader, volume.arrays.vol.data);
  const program = new RaycastProgram(gl, sources.raycast);
  const display = new DisplayPass(gl, sources.display, info.display);
  const viewer = new Viewer({ gl, program, display, textures, info, max3d });
  const xr = new XRView(viewer, { onPreset: (step) => panel.cyclePreset(step), onChange: () => panel.refresh('xr') });
  const slices = new SliceViews(element('slices', HTMLElement), { info, max3d,
    onCrosshair: () => viewer.redraw() });
  const measures = new SliceMeasures(slices);
  measures.fromDicts((await getJSON('measurements.json')).measurements);   // `volumen serve --measurements`
  const profile = new ProfilePlot(element('profile', HTMLElement), slices, () => viewer.redraw());
  profile.set((await getJSON('profile.json')).profile);   // `volumen serve --report`
  const ruler3d = new PictureRuler(viewer, measures, /** @type {HTMLElement} */ (canvas.parentElement));
  const xrRuler = new XRRuler(xr, ruler3d);
  const panel = new Panel(element('panel', HTMLElement), { viewer, slices, xr, xrAvailable: await xrSupported() });
  // the volume's header repeats the notices info.json already gave where the volume was packed before it answered
  for (const n of new Set([...info.notices, ...volumeHeader.notices])) panel.notice(n);

  /** @returns {Size} */
  const size = () => [canvas.width, canvas.height];
  attachGestures(canvas, (x, y) => pickLight(viewer.scene.lights, viewer.camera, size(), lightLength(info),
    x * devicePixelRatio, y * devicePixelRatio), (kind, dx, dy, light) => {
    viewer.interacting = kind !== 'wheel';
    const cam = viewer.camera, r = devicePixelRatio;
    if (kind === 'orbit') viewer.setCamera(orbit(cam, dx * r, dy * r));
    else if (kind === 'pan') viewer.setCamera(pan(cam, dx * r, dy * r, size()));
    else if (kind === 'zoom') viewer.setCamera(dragZoom(cam, dy * r));
    else if (kind === 'wheel') viewer.setCamera(wheelZoom(cam, dy));
    else if (light !== null) {   // 'light' and 'aim' start on a light
      const lights = viewer.scene.lights.slice();
      lights[light] = kind === 'light' ? moveLight(lights[light], cam, dx * r, dy * r, size())
        : aimLight(lights[light], cam, dx * r, dy * r);
      panel.selected = light;
      viewer.scene = { ...viewer.scene, lights };   // drawn at once, its shadows when the button is released
      viewer.redraw();
    }
  }, () => {
    viewer.interacting = false;
    viewer.setScene({ ...viewer.scene });
  });
  viewer.onChange((what) => {
    if (what === 'drawn') drawOverlay(overlay, { info, scene: viewer.scene, camera: viewer.camera,
      selected: panel.selected, crosshair: slices.crosshair });
  });
  new ResizeObserver(() => fitCanvases(viewer, overlay)).observe(/** @type {HTMLElement} */ (canvas.parentElement));
  fitCanvases(viewer, overlay);
  viewer.requestFrame();
  const slicesShown = slices.update();
  status.textContent = `${lim.renderer} | ${lim.version}`;

  /**
   * @typedef {object} Capture
   * @property {number} width
   * @property {number} height
   * @property {string} rgba
   * @property {Camera} camera
   * @property {Scene} scene
   * @property {{tonemap: string, exposure: number} | null} shown
   * @property {string | null} error
   * @property {{width: number, height: number, rgba: string, float: boolean}} [linear]
   */
  const volumen = {
    viewer, xr, info, limits: lim, shifted, measures, ruler3d, xrRuler, profile,
    // the slice views' rulers and regions as volumen.measure's JSON (`volumen measure export` reads it)
    measurements() { return { version: 1, measurements: measures.toDicts() }; },
    // put back what `measurements()` gave (the page's state): how many were added
    /** @param {{measurements: Record<string, any>[]}} state */
    loadMeasurements(state) { return measures.fromDicts(state.measurements); },
    // fix the picture's size (pixels) and show `scene` / `camera` (JSON); resolves once it is drawn
    /** @param {{scene?: Scene, camera?: Camera, size?: number[]}} view */
    async show({ scene, camera, size: wh }) {
      if (wh) {
        viewer.fixedSize = true;
        document.body.classList.add('fixed');
        canvas.width = overlay.width = wh[0];
        canvas.height = overlay.height = wh[1];
      }
      if (camera) viewer.camera = camera;
      if (scene) viewer.setScene(scene); else viewer.requestFrame();
      if (viewer.xrActive) {   // the canvas is the XR layer: wait for the frame and one XR picture
        await viewer.idle();
        await xr.afterFrames(1);
      } else {
        await viewer.settled();
      }
      return { error: viewer.error };
    },
    // the canvas: RGBA8 (base64), rows from the top, with the scene and camera it shows and the display
    // transform it was shown with ({tonemap, exposure}); `linear`: also the picture before that transform
    // (float32 RGBA, base64, rows from the top)
    /** @param {{linear?: boolean}} [options] @returns {Capture} */
    capture({ linear = false } = {}) {
      /** @type {Capture} */
      const out = { width: canvas.width, height: canvas.height, rgba: base64(viewer.read()), camera: viewer.camera,
        scene: viewer.scene, shown: viewer.shown, error: viewer.error };
      if (linear) {
        const lin = viewer.readLinear();
        out.linear = { width: lin.width, height: lin.height, rgba: base64(new Uint8Array(lin.rgba.buffer)),
          float: viewer.linear.float };
      }
      return out;
    },
    async enterVR({ governor = true, placement = 'table-top' } = {}) {
      xr.governor = governor;
      xr.placement = placement;
      await xr.enter();
      return true;
    },
    // both eyes of the next XR frame: [{eye, viewport, camera, rgba (base64)}]
    async captureVR() {
      const shots = await xr.capture();
      return shots.map((s) => ({ ...s, rgba: base64(s.rgba) }));
    },
    stateVR() { return { model: xr.model, scene: viewer.scene, stats: xr.stats(), eyes: xr.lastEyes }; },
    /** @param {number} n */
    framesVR(n) { return xr.afterFrames(n); },
    /** @param {number} n */
    timeFrames(n) { return viewer.timeFrames(n); },
    // resolves once the first picture and the slice views are shown
    async shown() { await Promise.all([viewer.settled(), slicesShown]); },
    /** @param {number} n */
    timeFramesVR(n) { return xr.timeFrames(n); },
    // a new scene during an XR session: resolves once its frame arrived
    /** @param {Scene} scene */
    async sceneVR(scene) { viewer.setScene(scene); await viewer.idle(); await xr.afterFrames(1); },
  };
  Object.assign(window, { volumen });
  document.body.dataset.ready = 'yes';
}

Object.assign(window, { volumenReady: boot().catch((e) => {
  status.textContent = `error: ${(e instanceof Error && e.message) || e}`;
  document.body.dataset.ready = 'error';
  throw e;
}) });
