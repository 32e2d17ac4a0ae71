// The vessel profile under the slice views (`volumen serve --report`): the equivalent diameter against the
// distance along the centerline, the band between the minimum and the maximum diameter, the stenosis and the
// maximum marked (an SVG in CSS pixels). A click on the plot moves the slices' crosshair to the section's
// centerline point and shows that section's numbers (mm to 0.1, mm² to 0.1).

/** @import { SliceViews } from './slices.js' */
/**
 * @typedef {object} Lesion
 * @property {number} arc_mm
 * @property {number} diameter_mm
 * @property {number} reference_mm
 * @property {number} percent
 * @property {boolean} flagged
 */
/**
 * @typedef {object} Profile  web/_profile_route.py's answer
 * @property {Record<string, number[]>} table  arc_mm, x_mm, y_mm, z_mm, area_mm2, diameter_mm, min_diameter_mm,
 *   max_diameter_mm, inscribed_radius_mm: one value per section
 * @property {Lesion} stenosis
 * @property {Lesion} maximum
 * @property {number} length_mm
 */
/** @typedef {{left: number, top: number, width: number, height: number, arc: number[], mm: number[]}} Axes */

const SVG = 'http://www.w3.org/2000/svg';
const MARGIN = { left: 34, right: 8, top: 6, bottom: 16 };

/** @param {string} tag @param {Record<string, string | number>} attrs @returns {SVGElement} */
function svg(tag, attrs) {
  const e = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
  return e;
}

/** @param {number} v */
const mm = (v) => v.toFixed(1);

export class ProfilePlot {
  /**
   * @param {HTMLElement} root  the section it is drawn in (shown once a profile is set)
   * @param {SliceViews} slices
   * @param {() => void} onCrosshair  called after a click moved the crosshair
   */
  constructor(root, slices, onCrosshair) {
    this.root = root;
    this.slices = slices;
    this.onCrosshair = onCrosshair;
    this.svg = /** @type {SVGSVGElement} */ (svg('svg', { class: 'profile-plot' }));
    this.numbers = document.createElement('p');
    this.numbers.className = 'profile-numbers';
    root.append(this.svg, this.numbers);
    /** @type {Profile | null} */
    this.profile = null;
    /** @type {Axes | null} */
    this.axes = null;
    this.selected = -1;
    this.svg.addEventListener('click', (e) => this.click(e));
    new ResizeObserver(() => this.draw()).observe(root);
  }

  /** @param {Profile | null} profile */
  set(profile) {
    this.profile = profile;
    this.root.hidden = !profile;
    this.selected = -1;
    this.numbers.textContent = profile ? `length ${mm(profile.length_mm)} mm: click the plot for a section` : '';
    this.draw();
  }

  // the plot's pixel of (arc mm, diameter mm)
  /** @param {number} arc @param {number} d @returns {[number, number]} */
  toPixel(arc, d) {
    const a = /** @type {Axes} */ (this.axes);
    return [a.left + (arc - a.arc[0]) / (a.arc[1] - a.arc[0]) * a.width,
      a.top + (a.mm[1] - d) / (a.mm[1] - a.mm[0]) * a.height];
  }

  draw() {
    const p = this.profile;
    this.svg.replaceChildren();
    if (!p) return;
    const box = this.svg.getBoundingClientRect();
    this.svg.setAttribute('viewBox', `0 0 ${box.width} ${box.height}`);
    const t = p.table, arc = t.arc_mm;
    const top = Math.max(...t.max_diameter_mm, ...t.diameter_mm);
    this.axes = { left: MARGIN.left, top: MARGIN.top, width: Math.max(1, box.width - MARGIN.left - MARGIN.right),
      height: Math.max(1, box.height - MARGIN.top - MARGIN.bottom), arc: [arc[0], arc[arc.length - 1]],
      mm: [0, top > 0 ? 1.1 * top : 1] };
    const pts = (/** @type {number[]} */ d) => arc.map((s, i) => this.toPixel(s, d[i]).map((v) => v.toFixed(2)).join(','));
    this.svg.append(svg('polygon', { class: 'band', points: [...pts(t.max_diameter_mm),
      ...pts(t.min_diameter_mm).reverse()].join(' ') }));
    this.svg.append(svg('polyline', { class: 'diameter', points: pts(t.diameter_mm).join(' ') }));
    this.drawAxes();
    for (const [name, lesion] of /** @type {[string, Lesion][]} */ ([['stenosis', p.stenosis], ['maximum', p.maximum]])) {
      this.mark(name, lesion);
    }
    if (this.selected >= 0) this.mark('selected', null);
  }

  drawAxes() {
    const a = /** @type {Axes} */ (this.axes);
    this.svg.append(svg('rect', { class: 'frame', x: a.left, y: a.top, width: a.width, height: a.height }));
    const label = (/** @type {number} */ x, /** @type {number} */ y, /** @type {string} */ s, anchor = 'end') => {
      const e = svg('text', { x, y, 'text-anchor': anchor });
      e.textContent = s;
      this.svg.append(e);
    };
    label(a.left - 3, a.top + 9, `${mm(a.mm[1])}`);
    label(a.left - 3, a.top + a.height, '0 mm');
    label(a.left, a.top + a.height + 12, `${mm(a.arc[0])}`, 'start');
    label(a.left + a.width, a.top + a.height + 12, `${mm(a.arc[1])} mm`);
  }

  // a vertical line at a lesion (or at the selected section) with its label
  /** @param {string} name @param {Lesion | null} lesion */
  mark(name, lesion) {
    const a = /** @type {Axes} */ (this.axes), t = /** @type {Profile} */ (this.profile).table;
    const arc = lesion ? lesion.arc_mm : t.arc_mm[this.selected];
    const [x] = this.toPixel(arc, 0);
    this.svg.append(svg('line', { class: `mark ${name}`, 'data-mark': name, x1: x, x2: x, y1: a.top,
      y2: a.top + a.height }));
    if (!lesion) return;
    const e = svg('text', { class: `mark ${name}`, x: x + 2, y: a.top + (name === 'stenosis' ? 20 : 9) });
    e.textContent = `${name} ${Math.round(lesion.percent)} %${lesion.flagged ? ' !' : ''}`;
    this.svg.append(e);
  }

  /** @param {MouseEvent} e */
  click(e) {
    if (!this.profile || !this.axes) return;
    const box = this.svg.getBoundingClientRect(), a = this.axes, arc = this.profile.table.arc_mm;
    const s = a.arc[0] + (e.clientX - box.left - a.left) / a.width * (a.arc[1] - a.arc[0]);
    let best = 0;
    arc.forEach((v, i) => { if (Math.abs(v - s) < Math.abs(arc[best] - s)) best = i; });
    this.select(best);
  }

  // show section `i`: the crosshair at its centerline point, its numbers under the plot
  /** @param {number} i @returns {Promise<void>} once the slices show it */
  select(i) {
    const t = /** @type {Profile} */ (this.profile).table;
    this.selected = i;
    this.numbers.textContent = `at ${mm(t.arc_mm[i])} mm: area ${mm(t.area_mm2[i])} mm², diameter `
      + `${mm(t.diameter_mm[i])} mm (min ${mm(t.min_diameter_mm[i])}, max ${mm(t.max_diameter_mm[i])}), `
      + `inscribed radius ${mm(t.inscribed_radius_mm[i])} mm`;
    this.draw();
    this.slices.crosshair = [t.x_mm[i], t.y_mm[i], t.z_mm[i]];
    const shown = this.slices.update();
    this.onCrosshair();
    return shown;
  }
}
