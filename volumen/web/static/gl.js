// The WebGL2 context and the frame's textures: the page's side of raster/_rc_textures.py.
//   vol    3-D R16F, trilinear, clamped (the served volume: volumen/web/_served.py; table units through
//          u_vol_map); texel centres are voxel centres
//   rgb    3-D RGB8 placeholder (colour volumes are not served)
//   skip_flags  3-D R8UI (the eight octants' skip sides side by side), bmin / bmax 3-D R32F: the empty-space
//          skipping grids, read per texel
//   lut    (NLUT x 1) RGBA32F, extinction (NLUT x 1) R32F, gradient_lut (128 x 1) R32F, preintegrated
//          (NPRE x NPRE) RGBA32F
//   light_data  the illumination volumes' buffer as rows of `lightDataWidth` R32F values
// Only the frame's tables change between frames; the volume is uploaded once.

export const FIELDS = ['vol', 'lut', 'preintegrated', 'gradient_lut', 'extinction', 'skip_flags', 'bmin', 'bmax',
  'light_data', 'rgb'];

/** @import { Arrays, WireArray } from './api.js' */
/** @import { Uniforms } from './program.js' */
/** @typedef {WebGL2RenderingContext & {canvas: HTMLCanvasElement}} GL  a context on a page's canvas */

// a WebGL2 context on `canvas` able to draw into an XR layer; throws with the reason when there is none
/** @param {HTMLCanvasElement} canvas @returns {GL} */
export function createContext(canvas) {
  const gl = canvas.getContext('webgl2', { alpha: true, premultipliedAlpha: true, antialias: false, depth: false,
    stencil: false, preserveDrawingBuffer: true, xrCompatible: true });
  if (!gl) throw new Error('this browser has no WebGL2');
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  return /** @type {GL} */ (gl);
}

/**
 * @param {WebGL2RenderingContext} gl
 * @returns {{max3d: number, max2d: number, renderer: string, version: string}}
 */
export function limits(gl) {
  return { max3d: gl.getParameter(gl.MAX_3D_TEXTURE_SIZE), max2d: gl.getParameter(gl.MAX_TEXTURE_SIZE),
    renderer: gl.getParameter(gl.RENDERER), version: gl.getParameter(gl.VERSION) };
}

/** @param {WebGL2RenderingContext} gl @param {GLenum} target @param {GLenum} filter @returns {WebGLTexture} */
function make(gl, target, filter) {
  const t = gl.createTexture();
  if (!t) throw new Error('no texture (the WebGL context is lost)');
  gl.bindTexture(target, t);
  gl.texParameteri(target, gl.TEXTURE_MIN_FILTER, filter);
  gl.texParameteri(target, gl.TEXTURE_MAG_FILTER, filter);
  for (const w of [gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T, gl.TEXTURE_WRAP_R]) gl.texParameteri(target, w, gl.CLAMP_TO_EDGE);
  return t;
}

/**
 * @param {WebGL2RenderingContext} gl @param {number[]} shape (nz, ny, nx) @param {GLenum} internal
 * @param {GLenum} format @param {GLenum} type @param {ArrayBufferView} data @param {GLenum} filter
 */
function texture3d(gl, [nz, ny, nx], internal, format, type, data, filter) {
  const t = make(gl, gl.TEXTURE_3D, filter);
  gl.texImage3D(gl.TEXTURE_3D, 0, internal, nx, ny, nz, 0, format, type, data);
  return t;
}

/**
 * @param {WebGL2RenderingContext} gl @param {number} w @param {number} h @param {GLenum} internal
 * @param {GLenum} format @param {GLenum} type @param {ArrayBufferView} data
 */
function texture2d(gl, w, h, internal, format, type, data) {
  const t = make(gl, gl.TEXTURE_2D, gl.NEAREST);
  gl.texImage2D(gl.TEXTURE_2D, 0, internal, w, h, 0, format, type, data);
  return t;
}

export class Textures {
  /** @param {WebGL2RenderingContext} gl */
  constructor(gl) {
    this.gl = gl;
    /** @type {Record<string, WebGLTexture | undefined>} by FIELDS' names */
    this.tex = {};
    /** @type {number[] | undefined} the volume's texture coordinates of table units (u_vol_map) */
    this.volMap = undefined;
    /** @type {number[] | undefined} */
    this.shape = undefined;
    this.lightDataWidth = Math.min(gl.getParameter(gl.MAX_TEXTURE_SIZE), 8192);
    this.tex.rgb = texture3d(gl, [1, 1, 1], gl.RGB8, gl.RGB, gl.UNSIGNED_BYTE, new Uint8Array(3), gl.LINEAR);
  }

  // the volume: {shape, vol_map} and its float16 texels (Uint16Array)
  /** @param {{shape: number[], vol_map: number[]}} header @param {ArrayBufferView} texels */
  setVolume(header, texels) {
    const gl = this.gl;
    if (this.tex.vol) gl.deleteTexture(this.tex.vol);
    this.tex.vol = texture3d(gl, header.shape, gl.R16F, gl.RED, gl.HALF_FLOAT, texels, gl.LINEAR);
    this.volMap = header.vol_map;
    this.shape = header.shape;
  }

  // the frame's tables and grids (the arrays of a /frame.bin answer); a frame this browser cannot hold throws
  // before any texture changes, so the last frame's stay bound, matching the header the viewer keeps
  /** @param {Arrays} a */
  setFrame(a) {
    const gl = this.gl;
    const w = this.lightDataWidth, n = a.light_data.data.length, rows = Math.ceil(n / w);
    if (rows > w) throw new Error(`illumination volumes of ${n} values are past this browser's ${w} x ${w} texture`);
    const old = FIELDS.filter((name) => name !== 'vol' && name !== 'rgb').map((name) => this.tex[name]);
    /** @param {WireArray} x @param {GLenum} internal @param {GLenum} format */
    const row = (x, internal, format) => texture2d(gl, x.shape[0], 1, internal, format, gl.FLOAT, x.data);
    this.tex.lut = row(a.lut, gl.RGBA32F, gl.RGBA);
    this.tex.extinction = row(a.extinction, gl.R32F, gl.RED);
    this.tex.gradient_lut = row(a.gradient_lut, gl.R32F, gl.RED);
    const pre = a.preintegrated;
    this.tex.preintegrated = texture2d(gl, pre.shape[1], pre.shape[0], gl.RGBA32F, gl.RGBA, gl.FLOAT, pre.data);
    const skip = a.skip_flags;
    this.tex.skip_flags = texture3d(gl, skip.shape, gl.R8UI, gl.RED_INTEGER, gl.UNSIGNED_BYTE, skip.data, gl.NEAREST);
    this.tex.bmin = texture3d(gl, a.bmin.shape, gl.R32F, gl.RED, gl.FLOAT, a.bmin.data, gl.NEAREST);
    this.tex.bmax = texture3d(gl, a.bmax.shape, gl.R32F, gl.RED, gl.FLOAT, a.bmax.data, gl.NEAREST);
    const light = new Float32Array(rows * w).fill(1);
    light.set(a.light_data.data);
    this.tex.light_data = texture2d(gl, w, rows, gl.R32F, gl.RED, gl.FLOAT, light);
    for (const t of old) if (t) gl.deleteTexture(t);
  }

  get ready() { return Boolean(this.tex.vol && this.tex.lut); }

  // bind every texture to its unit; the sampler uniforms and the layout uniforms to set
  /** @returns {Uniforms} */
  bind() {
    const gl = this.gl;
    /** @type {Uniforms} */
    const u = {};
    FIELDS.forEach((name, unit) => {
      gl.activeTexture(gl.TEXTURE0 + unit);
      const flat = ['lut', 'preintegrated', 'gradient_lut', 'extinction', 'light_data'].includes(name);
      const target = flat ? gl.TEXTURE_2D : gl.TEXTURE_3D;
      gl.bindTexture(target, this.tex[name] ?? null);
      u[`u_${name}`] = unit;
    });
    u.u_light_data_w = this.lightDataWidth;
    u.u_vol_map = this.volMap ?? null;
    return u;
  }
}

// The ray caster's picture before the display transform: premultiplied linear RGBA in an offscreen texture,
// RGBA16F where the browser renders to float (EXT_color_buffer_float: every desktop WebGL2 and the headsets'
// browsers), else RGBA8 (`float` false: linear values in 8 bits band in the dark after the curve). Its size is
// the picture's (reduced while dragging and by the VR governor); display.js shows it, stretched, in a
// viewport and meters its exposure on a read-back.
export class LinearTarget {
  /** @param {WebGL2RenderingContext} gl */
  constructor(gl) {
    this.gl = gl;
    this.size = [0, 0];
    /** @type {WebGLTexture | null} */
    this.tex = null;
    this.float = Boolean(gl.getExtension('EXT_color_buffer_float'));
    this.format = this.float ? [gl.RGBA16F, gl.HALF_FLOAT] : [gl.RGBA8, gl.UNSIGNED_BYTE];
    this.fbo = gl.createFramebuffer();
    /** @type {{fbo: WebGLFramebuffer, tex: WebGLTexture | null, size: number[]}} the subsample's target */
    this.small = { fbo: gl.createFramebuffer(), tex: null, size: [0, 0] };
  }

  /** @param {number} w @param {number} h @returns {WebGLTexture} */
  allocate(w, h) {
    const gl = this.gl;
    const t = make(gl, gl.TEXTURE_2D, gl.LINEAR);
    gl.texImage2D(gl.TEXTURE_2D, 0, this.format[0], w, h, 0, gl.RGBA, this.format[1], null);
    return t;
  }

  /** @param {WebGLFramebuffer} fbo @param {WebGLTexture} tex */
  attach(fbo, tex) {
    const gl = this.gl;
    gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0);
  }

  // bind it as the framebuffer at `w` x `h` pixels (the viewport too), cleared to transparent
  /** @param {number} w @param {number} h */
  use(w, h) {
    const gl = this.gl;
    if (this.size[0] !== w || this.size[1] !== h) {
      if (this.tex) gl.deleteTexture(this.tex);
      this.tex = this.allocate(w, h);
      this.attach(this.fbo, this.tex);
      this.size = [w, h];
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.fbo);
    gl.viewport(0, 0, w, h);
    gl.clearColor(0, 0, 0, 0);
    gl.clear(gl.COLOR_BUFFER_BIT);
  }

  // its pixels as a Float32Array of RGBA (rows from the bottom): all of them when there are at most
  // `maxPixels`, else a nearest-neighbour subsample of at most that many (a blit: every k-th pixel)
  /** @param {number} [maxPixels] @returns {{rgba: Float32Array, size: number[]}} */
  read(maxPixels = Infinity) {
    const gl = this.gl;
    let [w, h] = this.size;
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, this.fbo);
    if (w * h > maxPixels) {
      const f = Math.sqrt(maxPixels / (w * h));
      const [sw, sh] = [Math.max(1, Math.floor(w * f)), Math.max(1, Math.floor(h * f))];
      const s = this.small;
      if (s.size[0] !== sw || s.size[1] !== sh) {
        if (s.tex) gl.deleteTexture(s.tex);
        s.tex = this.allocate(sw, sh);
        this.attach(s.fbo, s.tex);
        s.size = [sw, sh];
      }
      gl.bindFramebuffer(gl.READ_FRAMEBUFFER, this.fbo);
      gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, s.fbo);
      gl.blitFramebuffer(0, 0, w, h, 0, 0, sw, sh, gl.COLOR_BUFFER_BIT, gl.NEAREST);
      gl.bindFramebuffer(gl.READ_FRAMEBUFFER, s.fbo);
      [w, h] = [sw, sh];
    }
    let px;
    if (this.float) {
      px = new Float32Array(w * h * 4);
      gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT, px);
    } else {
      const b = new Uint8Array(w * h * 4);
      gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, b);
      px = Float32Array.from(b, (v) => v / 255);
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    return { rgba: px, size: [w, h] };
  }
}

// RGBA8 of the region [x, y, w, h] of the bound framebuffer, rows from the TOP (as volumen.core.Image)
/** @param {WebGL2RenderingContext} gl @param {number[]} region @returns {Uint8Array} */
export function readRGBA(gl, [x, y, w, h]) {
  const px = new Uint8Array(w * h * 4);
  gl.readPixels(x, y, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
  const out = new Uint8Array(w * h * 4);
  for (let r = 0; r < h; r++) out.set(px.subarray((h - 1 - r) * w * 4, (h - r) * w * 4), r * w * 4);
  return out;
}
