// A program of the desktop shader files compiled as GLSL ES 3.00 (the ray caster, the display pass), drawn as
// one full-screen triangle. The server sends each stage as
// (head, body) (raster/_shaders.py stage_parts: the #version line and the stage's macro; the precision
// preamble and the file with its includes); a variant is head + its #define lines + body, compiled once.
// Uniforms are set generically from a {name: value} object by the type the linker reports, so the page sets
// the values the server packed (raster/_rc_uniforms.py) without a table of its own.

/** @typedef {number | boolean | number[] | Float32Array | null} UniformValue  a scalar, or a vector, matrix or array */
/** @typedef {Record<string, UniformValue>} Uniforms  values by uniform name */
/** @typedef {Record<string, [string, string]>} StageSources  (head, body) of the vertex and fragment stages */
/**
 * @typedef {object} Variant  a linked program and its active uniforms (arrays by their name without [0])
 * @property {WebGLProgram} prog
 * @property {Record<string, {loc: WebGLUniformLocation | null, type: number}>} uniforms
 */

export class RaycastProgram {
  /** @param {WebGL2RenderingContext} gl @param {StageSources} sources @param {string} [file] */
  constructor(gl, sources, file = 'raycast.glsl') {
    this.gl = gl;
    this.sources = sources;
    this.file = file;
    /** @type {Map<string, Variant>} */
    this.cache = new Map();
    const buf = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, buf);
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array([-1, -1, 3, -1, -1, 3]), gl.STATIC_DRAW);
    this.vao = gl.createVertexArray();
    gl.bindVertexArray(this.vao);
    gl.enableVertexAttribArray(0);
    gl.vertexAttribPointer(0, 2, gl.FLOAT, false, 0, 0);
    gl.bindVertexArray(null);
  }

  // the linked program of `defines` ({MODE: 0, LIGHT: 1, ...}), compiled on first use
  /** @param {Record<string, number>} defines @returns {Variant} */
  variant(defines) {
    const key = Object.entries(defines).sort().map(([k, v]) => `${k}=${v}`).join(',');
    let p = this.cache.get(key);
    if (!p) {
      p = this.link(defines);
      this.cache.set(key, p);
    }
    return p;
  }

  /** @param {string} stage 'vertex' or 'fragment' @param {Record<string, number>} defines @returns {WebGLShader} */
  compile(stage, defines) {
    const gl = this.gl;
    const [head, body] = this.sources[stage];
    const lines = Object.entries(defines).sort().map(([k, v]) => `#define ${k} ${v}`);
    const sh = gl.createShader(stage === 'vertex' ? gl.VERTEX_SHADER : gl.FRAGMENT_SHADER);
    if (!sh) throw new Error(`${this.file} (${stage}): no shader (the WebGL context is lost)`);
    gl.shaderSource(sh, [head, ...lines, body].join('\n'));
    gl.compileShader(sh);
    if (!gl.getShaderParameter(sh, gl.COMPILE_STATUS)) {
      throw new Error(`${this.file} (${stage}) does not compile as GLSL ES 3.00: ${gl.getShaderInfoLog(sh)}`);
    }
    return sh;
  }

  /** @param {Record<string, number>} defines @returns {Variant} */
  link(defines) {
    const gl = this.gl;
    const prog = gl.createProgram();
    gl.attachShader(prog, this.compile('vertex', defines));
    gl.attachShader(prog, this.compile('fragment', defines));
    gl.bindAttribLocation(prog, 0, 'in_pos');
    gl.linkProgram(prog);
    if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(`${this.file}: ${gl.getProgramInfoLog(prog)}`);
    /** @type {Variant['uniforms']} */
    const uniforms = {};
    const n = gl.getProgramParameter(prog, gl.ACTIVE_UNIFORMS);
    for (let i = 0; i < n; i++) {
      const info = gl.getActiveUniform(prog, i);
      if (!info) continue;
      uniforms[info.name.replace(/\[0\]$/, '')] = { loc: gl.getUniformLocation(prog, info.name), type: info.type };
    }
    return { prog, uniforms };
  }

  // set every uniform of `p` named in `values` (the compiler drops unused ones: those are skipped)
  /** @param {Variant} p @param {Uniforms} values */
  set(p, values) {
    const gl = this.gl;
    gl.useProgram(p.prog);
    for (const [name, { loc, type }] of Object.entries(p.uniforms)) {
      if (!(name in values)) continue;
      const v = values[name];
      const flat = typeof v === 'object' ? v : null;
      switch (type) {
        case gl.FLOAT:
          if (flat) gl.uniform1fv(loc, flat); else gl.uniform1f(loc, Number(v));
          break;
        case gl.FLOAT_VEC2: gl.uniform2fv(loc, vector(name, flat)); break;
        case gl.FLOAT_VEC3: gl.uniform3fv(loc, vector(name, flat)); break;
        case gl.FLOAT_VEC4: gl.uniform4fv(loc, vector(name, flat)); break;
        case gl.FLOAT_MAT3: gl.uniformMatrix3fv(loc, false, vector(name, flat)); break;
        case gl.FLOAT_MAT4: gl.uniformMatrix4fv(loc, false, vector(name, flat)); break;
        case gl.INT: case gl.BOOL:
          if (flat) gl.uniform1iv(loc, Int32Array.from(flat, Number)); else gl.uniform1i(loc, Number(v));
          break;
        default: gl.uniform1i(loc, Number(v));   // samplers: the texture unit
      }
    }
  }

  // one full-screen triangle into the bound framebuffer's viewport
  draw() {
    const gl = this.gl;
    gl.disable(gl.BLEND);
    gl.disable(gl.DEPTH_TEST);
    gl.bindVertexArray(this.vao);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
  }
}

// the values of a vector or matrix uniform; a scalar or null there is the server's or the page's mistake
/** @param {string} name @param {number[] | Float32Array | null} flat @returns {number[] | Float32Array} */
function vector(name, flat) {
  if (!flat) throw new Error(`uniform ${name}: a vector or matrix needs an array`);
  return flat;
}
