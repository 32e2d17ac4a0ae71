// The three slice views (axial, coronal, sagittal) through the crosshair, with a window: pictures drawn by the
// server (web/_slices.py, radiological orientation) with the lines of the other two planes. A click on a
// picture moves the crosshair to the world point under it (the picture's pixel -> world map comes with it).

import { getSlice } from './api.js';

export const PLANES = ['axial', 'coronal', 'sagittal'];

export class SliceViews {
  constructor(root, { info, max3d, onCrosshair }) {
    Object.assign(this, { info, max3d, onCrosshair });
    const v = info.volume;
    const [lo, hi] = v.value_range;
    this.window = v.units === 'HU' ? { level: 40, width: 400 } : { level: (lo + hi) / 2, width: Math.max(hi - lo, 1e-6) };
    this.crosshair = v.center.slice();
    this.views = {};
    this.seq = 0;
    for (const plane of PLANES) {
      const fig = document.createElement('figure');
      const img = document.createElement('img');
      img.alt = `${plane} slice`;
      img.dataset.plane = plane;
      const cap = document.createElement('figcaption');
      cap.textContent = plane;
      fig.append(img, cap);
      root.append(fig);
      img.addEventListener('click', (e) => this.click(plane, e));
      this.views[plane] = { img, map: null };
    }
  }

  click(plane, e) {
    const { img, map } = this.views[plane];
    if (!map) return;
    const box = img.getBoundingClientRect();
    const col = (e.clientX - box.left) * img.naturalWidth / box.width - 0.5;
    const row = (e.clientY - box.top) * img.naturalHeight / box.height - 0.5;
    this.crosshair = [0, 1, 2].map((a) => map[0][a] + col * map[1][a] + row * map[2][a]);
    this.update();
    this.onCrosshair(this.crosshair);
  }

  setWindow(level, width) {
    this.window = { level, width };
    this.update();
  }

  async update() {
    const seq = ++this.seq;
    const [x, y, z] = this.crosshair;
    const shots = await Promise.all(PLANES.map((plane) => getSlice({ plane, x, y, z, level: this.window.level,
      width: this.window.width, max3d: this.max3d })));
    if (seq !== this.seq) { shots.forEach((s) => URL.revokeObjectURL(s.url)); return; }
    PLANES.forEach((plane, i) => {
      const v = this.views[plane];
      if (v.img.src) URL.revokeObjectURL(v.img.src);
      v.img.src = shots[i].url;
      v.map = shots[i].map;
    });
  }
}
