// The panel beside the 3-D view: preset (and its shift along the values), mode, shading, display transform
// (curve and exposure), lights (add at the camera, select, delete; dragged on the picture), crop box, slice
// window, VR, notices and frame times.
// Every control edits the scene (Scene.to_dict() JSON) through viewer.setScene.

import { lightAtCamera } from './camera.js';

/** @import { SliceViews } from './slices.js' */
/** @import { Scene, TransferFunction, Viewer } from './viewer.js' */
/** @import { XRView } from './xr.js' */

const MODES = ['composite', 'mip', 'minip', 'average', 'isosurface'];
const SHADINGS = ['none', 'headlight', 'phong', 'shadows', 'scattering'];   // path tracing: cpu and cuda only
const TONEMAPS = ['auto', 'linear', 'aces'];   // core._tonemap.Display

// a new element `tag` with the properties `props` and the children `children`
/**
 * @template {keyof HTMLElementTagNameMap} K
 * @param {K} tag @param {Partial<HTMLElementTagNameMap[K]>} [props] @param {...(Node | string)} children
 * @returns {HTMLElementTagNameMap[K]}
 */
function el(tag, props = {}, ...children) {
  const e = Object.assign(document.createElement(tag), props);
  e.append(...children);
  return e;
}

/** @param {string} text @param {HTMLElement} control */
function labelled(text, control) {
  return el('label', {}, el('span', { textContent: text }), control);
}

/** @param {string[]} options @param {string} value @param {(value: string) => void} onChange */
function select(options, value, onChange) {
  const s = el('select');
  for (const o of options) s.append(el('option', { value: o, textContent: o, selected: o === value }));
  s.addEventListener('change', () => onChange(s.value));
  return s;
}

/**
 * @param {number} min @param {number} max @param {number} step @param {number} value
 * @param {(value: number) => void} onInput
 */
function slider(min, max, step, value, onInput) {
  const s = el('input', { type: 'range', min: String(min), max: String(max), step: String(step),
    value: String(value) });
  s.addEventListener('input', () => onInput(Number(s.value)));
  return s;
}

// TransferFunction.shifted: the inner control points moved by `offset`, clamped between the end points
/** @param {TransferFunction} tf @param {number} offset @returns {TransferFunction} */
export function shifted(tf, offset) {
  /** @param {number[][]} pts */
  const move = (pts) => (pts.length <= 2 ? pts : [pts[0], ...pts.slice(1, -1).map(([v, ...rest]) =>
    [Math.min(Math.max(v + offset, pts[0][0]), pts[pts.length - 1][0]), ...rest]), pts[pts.length - 1]]);
  return { ...tf, color: move(tf.color), opacity: move(tf.opacity) };
}

export class Panel {
  /**
   * @param {HTMLElement} root
   * @param {object} parts
   * @param {Viewer} parts.viewer
   * @param {SliceViews} parts.slices
   * @param {XRView} parts.xr
   * @param {boolean} parts.xrAvailable  whether the browser offers immersive-vr sessions
   */
  constructor(root, { viewer, slices, xr, xrAvailable }) {
    this.root = root;
    this.viewer = viewer;
    this.slices = slices;
    this.xr = xr;
    /** @type {number | null} the index of the selected light */
    this.selected = null;
    this.presetName = viewer.scene.transfer.name || viewer.info.presets[0];
    const info = viewer.info;
    this.shift = info.shift || 0;
    const [lo, hi] = info.volume.value_range;
    const span = Math.max(hi - lo, Math.abs(this.shift) * 2);
    this.notices = el('ul', { className: 'notices' });
    this.timing = el('p', { className: 'timing' });
    this.lightList = el('select', { size: 4, className: 'lights' });
    this.lightList.addEventListener('change', () => this.select(this.lightList.selectedIndex));
    this.iso = slider(lo, hi, span / 500, viewer.scene.isosurface.value, (v) => this.edit({ isosurface:
      { ...viewer.scene.isosurface, value: v } }));
    this.isoRow = labelled('iso value', this.iso);
    const sc = viewer.scene;
    root.append(
      el('h2', { textContent: 'volumen' }),
      this.notices,
      labelled('preset', select(info.presets, this.presetName, (n) => { this.presetName = n; this.applyPreset(); })),
      labelled('shift', slider(-span / 2, span / 2, span / 500, this.shift, (v) => {
        this.shift = v;
        this.applyPreset();
      })),
      labelled('mode', select(MODES, sc.mode, (m) => this.setMode(m))),
      this.isoRow,
      labelled('shading', select(SHADINGS, sc.shading.mode, (m) => this.edit({ shading: { ...viewer.scene.shading,
        mode: m } }))),
      el('h3', { textContent: 'display' }), ...this.displayControls(),
      el('h3', { textContent: 'lights' }), this.lightList,
      el('div', { className: 'row' },
        el('button', { textContent: 'add at camera', onclick: () => this.addLight() }),
        el('button', { textContent: 'delete', onclick: () => this.deleteLight() })),
      el('p', { className: 'hint', textContent: 'drag a cone to move a light, ctrl + drag to aim it' }),
      el('h3', { textContent: 'crop box' }), this.cropControls(),
      el('h3', { textContent: 'slice window' }),
      labelled('level', slider(lo - span / 2, hi, span / 500, slices.window.level,
        (v) => slices.setWindow(v, slices.window.width))),
      labelled('width', slider(span / 500, 2 * span, span / 500, slices.window.width,
        (v) => slices.setWindow(slices.window.level, v))),
      el('h3', { textContent: 'VR' }), this.vrControls(xrAvailable),
      this.timing,
    );
    viewer.onChange((what) => this.refresh(what));
    this.refresh('scene');
  }

  /** @param {Partial<Scene>} changes */
  edit(changes) { this.viewer.setScene({ ...this.viewer.scene, ...changes }); }

  applyPreset() {
    const tf = this.viewer.info.transfers[this.presetName];
    this.edit({ transfer: shifted(tf, this.shift) });
  }

  // the preset `step` places after the current one in the list (the projections' gray ramp skipped), applied
  /** @param {number} step */
  cyclePreset(step) {
    const names = this.viewer.info.presets.filter((n) => n !== 'mip-gray');
    this.presetName = names[(names.indexOf(this.presetName) + step + names.length) % names.length];
    this.applyPreset();
  }

  /** @param {string} mode */
  setMode(mode) {
    const projection = ['mip', 'minip', 'average'].includes(mode);
    const transfer = projection ? this.viewer.info.transfers['mip-gray']
      : shifted(this.viewer.info.transfers[this.presetName], this.shift);
    this.edit({ mode, transfer });
  }

  /** @param {number} i the light's index, or -1: none */
  select(i) {
    this.selected = i >= 0 ? i : null;
    this.viewer.redraw();
  }

  addLight() {
    const v = this.viewer;
    if (v.scene.lights.length >= v.maxLights) return;
    const shading = ['none', 'headlight'].includes(v.scene.shading.mode) ? { ...v.scene.shading, mode: 'phong' }
      : v.scene.shading;
    this.selected = v.scene.lights.length;
    this.edit({ shading, lights: [...v.scene.lights, lightAtCamera(v.camera)] });
  }

  deleteLight() {
    if (this.selected === null) return;
    const lights = this.viewer.scene.lights.filter((_, i) => i !== this.selected);
    this.selected = null;
    this.edit({ lights });
  }

  cropControls() {
    const [nz, ny, nx] = this.viewer.info.volume.shape;
    const n = [nx - 1, nx - 1, ny - 1, ny - 1, nz - 1, nz - 1];
    const box = [0, nx - 1, 0, ny - 1, 0, nz - 1];
    const on = el('input', { type: 'checkbox' });
    const apply = () => this.edit({ clipping: { ...this.viewer.scene.clipping, crop: on.checked ? box.slice() : null,
      crop_space: 'voxel' } });
    on.addEventListener('change', apply);
    const rows = ['x min', 'x max', 'y min', 'y max', 'z min', 'z max'].map((name, i) => labelled(name,
      slider(0, n[i], 1, box[i], (v) => {
        box[i] = v;
        if (i % 2 === 0) box[i + 1] = Math.max(box[i + 1], v); else box[i - 1] = Math.min(box[i - 1], v);
        on.checked = true;
        apply();
      })));
    return el('div', { className: 'crop' }, labelled('crop', on), ...rows);
  }

  // Display.tonemap, and Display.exposure: the slider sets it (stops), `metered` gives it back to the meter
  displayControls() {
    const d = () => this.viewer.scene.display;
    const metered = el('input', { type: 'checkbox', checked: d().exposure === null });
    const ev = slider(-4, 8, 0.1, d().exposure ?? 0, (v) => {
      metered.checked = false;
      this.edit({ display: { ...d(), exposure: v } });
    });
    metered.addEventListener('change', () => this.edit({ display: { ...d(), exposure: metered.checked ? null
      : Number(ev.value) } }));
    return [labelled('tone curve', select(TONEMAPS, d().tonemap, (t) => this.edit({ display: { ...d(), tonemap: t } }))),
      labelled('exposure', ev), labelled('metered', metered)];
  }

  /** @param {boolean} available */
  vrControls(available) {
    const enter = el('button', { textContent: 'Enter VR', disabled: !available, onclick: () => this.xr.enter()
      .catch((e) => this.notice(`VR: ${(e instanceof Error && e.message) || e}`)) });
    const placement = select(['table-top', 'life-size'], 'table-top', (p) => this.xr.place(p));
    const gov = el('input', { type: 'checkbox', checked: true });
    gov.addEventListener('change', () => { this.xr.governor = gov.checked; });
    return el('div', {}, enter, labelled('placement', placement), labelled('frame-time governor', gov),
      available ? '' : el('p', { className: 'hint', textContent: 'no immersive-vr here (a headset\'s browser, '
        + 'or desktop Chrome with an OpenXR runtime, over https or localhost)' }));
  }

  /** @param {string} text */
  notice(text) { this.notices.append(el('li', { textContent: text })); }

  /** @param {string} what what changed: a Viewer's Change, or 'xr', 'xr-end', 'governor' */
  refresh(what) {
    const v = this.viewer;
    if (what === 'scene') {
      const names = v.scene.lights.map((lt, i) => `${i + 1}: ${lt.kind} at ${lt.position.map((x) => x.toFixed(0))
        .join(', ')} mm`);
      this.lightList.replaceChildren(...names.map((t, i) => el('option', { textContent: t, selected: i === this.selected })));
      this.isoRow.hidden = v.scene.mode !== 'isosurface';
    }
    if (what === 'error' && v.error) this.notice(v.error);
    const xr = this.xr.session ? this.xr.stats() : null;
    this.timing.textContent = xr ? `VR ${xr.mean_ms.toFixed(1)} ms a frame (both eyes), step level ${xr.level}`
      : `${v.lastDraw.ms.toFixed(1)} ms a picture (${v.lastDraw.size.join(' x ')})`;
    if (v.shown) this.timing.textContent += `; shown ${v.shown.tonemap}, ${v.shown.exposure.toFixed(2)} EV`;
  }
}
