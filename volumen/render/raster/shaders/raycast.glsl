// Ray casting in a fragment shader: the CPU kernels' marching skeleton
// (volumen/render/raycast/_march.py) with the same pieces, one pixel per fragment.
// Every table and volume is built by the Python/Numba code (raycast.pack_frame) and only
// read here; each formula below names the CPU function it mirrors.
// Variants (#define): MODE (MODE_COMPOSITE, MODE_PREINT, MODE_MIP, MODE_MINIP, MODE_AVERAGE,
// MODE_ISO), LIGHT (LIGHT_UNLIT, LIGHT_PHONG, LIGHT_SHADOWED, LIGHT_SCATTER), MAX_LIGHTS, MAX_PLANES.
// Compiled as GLSL 3.30 (OpenGL: raster/_raycast.py) and GLSL ES 3.00 (WebGL2: the page of volumen.web),
// see raster/_shaders.py; under GL_ES there is one colour attachment (a canvas or an XR layer).

#define MODE_COMPOSITE 0
#define MODE_PREINT 1
#define MODE_MIP 2
#define MODE_MINIP 3
#define MODE_AVERAGE 4
#define MODE_ISO 5
#define LIGHT_UNLIT 0
#define LIGHT_PHONG 1
#define LIGHT_SHADOWED 2
#define LIGHT_SCATTER 3

#if defined VERTEX_SHADER

in vec2 in_pos;
void main() { gl_Position = vec4(in_pos, 0.0, 1.0); }

#elif defined FRAGMENT_SHADER

layout(location = 0) out vec4 o_rgba;  // premultiplied colour, opacity
#if defined GL_ES
vec4 o_aux;                            // (not written out)
#else
layout(location = 1) out vec4 o_aux;   // depth (mm, FAR: none), value (table units, FAR: none), samples
#endif

const float FAR = 1e30;
const float PI = 3.14159265358979;
const float DEPTH_OPACITY = 0.5;   // _composite.DEPTH_OPACITY
const float TAU_STOP = 14.0;       // _shadow.TAU_STOP
const float NEAR_STEPS = 3.0;      // _params.NEAR_STEPS

// volume and tables (fields of raycast.Arrays)
uniform sampler3D u_vol;      // samples, trilinear, clamped; in table units: (texel + u_vol_map.x) * u_vol_map.y
uniform vec2 u_vol_map;       // (0, 1) where the texture holds table units (OpenGL's R32F; WebGL's 16-bit differs)
uniform sampler3D u_rgb;      // colour volume: voxel RGB in [0, 1] (raycast._color), used when u_color
uniform sampler2D u_lut;      // (NLUT x 1) straight rgb, alpha per step
uniform sampler2D u_preintegrated;  // (NPRE x NPRE) pre-integrated, x = back value, y = front value
uniform sampler2D u_gradient_lut;   // (128 x 1) gradient-opacity factor
uniform sampler2D u_extinction;     // (NLUT x 1) optical depth per reference step
uniform usampler3D u_skip_flags;   // skip side per block and ray octant, the 8 grids 2x2x2 (_octants.tiled)
uniform sampler3D u_bmin;
uniform sampler3D u_bmax;
uniform sampler2D u_light_data;     // illumination-volume buffer, row-major rows of u_light_data_w values
uniform int u_light_data_w;

// camera (_geometry.pack_camera)
uniform vec3 u_eye, u_right, u_up, u_fwd;
uniform bool u_ortho;
uniform float u_half, u_near, u_far;
uniform vec2 u_wh;
uniform vec2 u_origin;        // framebuffer pixel of the picture's bottom-left corner (an XR eye's viewport)
// region (_geometry.pack_geometry, pack_planes)
uniform mat4 u_to_index;      // world -> voxel index (x, y, z)
uniform vec3 u_box_lo, u_box_hi, u_wlo, u_whi;
uniform int u_nplanes;
uniform vec3 u_pp[MAX_PLANES];
uniform vec3 u_pn[MAX_PLANES];
// lights (_shade.pack_lights) and their illumination volumes (_lightvol meta rows)
uniform int u_nlights;
uniform vec3 u_lpos[MAX_LIGHTS];
uniform vec3 u_ldir[MAX_LIGHTS];
uniform vec3 u_lcol[MAX_LIGHTS];
uniform float u_lexp[MAX_LIGHTS];
uniform vec4 u_lvm[MAX_LIGHTS * 4];   // each light's 16 meta values (LV_*), four per vec4
uniform int u_lvoff[MAX_LIGHTS];
// settings (raycast.Settings)
uniform float u_ds, u_ds0, u_early_termination, u_ambient, u_diffuse, u_specular, u_shininess, u_iso_value;
uniform float u_pre_scale, u_shadow_offset, u_shadow_step, u_extinction_scale;
uniform float u_albedo, u_phase_g;
uniform vec3 u_iso_rgb;
uniform bool u_nearest, u_jitter, u_skip, u_gradient_opacity, u_sobel, u_color;
uniform int u_recon;          // Settings.recon: 0 trilinear (or nearest), 1 the tricubic B-spline (_bspline)
// normals (Arrays.gradient_matrix): index -> world gradient matrix, 1 / largest |gradient| in table units per mm
uniform mat3 u_nmat;
uniform float u_inv_gmax;
uniform int u_seed, u_block;
// the environment's ambient term (raycast._environment): u_env_mode 0 the uniform u_ambient, 1 its SH to order 2
uniform int u_env_mode;
uniform vec3 u_envsh[9];
uniform bool u_hdr;           // composite colour unclipped (for a tone curve)

ivec3 g_size;

// sum_lm w_l L_lm Y_lm(d), at least 0 (_environment._sh_sum)
vec3 sh_sum(vec3 d, float w1, float w2) {
    vec3 c = 0.282095 * u_envsh[0]
        + w1 * 0.488603 * (d.y * u_envsh[1] + d.z * u_envsh[2] + d.x * u_envsh[3])
        + w2 * (1.092548 * (d.x * d.y * u_envsh[4] + d.y * d.z * u_envsh[5] + d.x * d.z * u_envsh[7])
                + 0.315392 * (3.0 * d.z * d.z - 1.0) * u_envsh[6] + 0.546274 * (d.x * d.x - d.y * d.y) * u_envsh[8]);
    return max(c, vec3(0.0));
}

// ---- reconstruction (_sample) ----
float table_units(float texel) { return (texel + u_vol_map.x) * u_vol_map.y; }

// ---- the tricubic B-spline's fast form (_bspline): 8 trilinear texture lookups a value, 24 a gradient ----
void bs_value_taps(float x, out vec2 h, out vec2 g) {   // _bspline._value_taps: positions h, weights g
    float i = floor(x), a = x - i;
    float w1 = (4.0 + a * a * (3.0 * a - 6.0)) / 6.0;
    float g0 = (1.0 - a) * (1.0 - a) * (1.0 - a) / 6.0 + w1;
    h = vec2(i - 1.0 + w1 / g0, i + 1.0 + a * a * a / (6.0 * (1.0 - g0)));
    g = vec2(g0, 1.0 - g0);
}

void bs_slope_taps(float x, out vec2 h, out vec2 g) {   // _bspline._slope_taps
    float i = floor(x), a = x - i, q = 0.5 + a - a * a;
    h = vec2(i - 1.0 + a * (4.0 - 3.0 * a) / (2.0 * q), i + 1.0 + a * a / (2.0 * q));
    g = vec2(-q, q);
}

float bs_blend(vec2 hx, vec2 gx, vec2 hy, vec2 gy, vec2 hz, vec2 gz) {   // _bspline._blend, in texels
    float s = 0.0;
    for (int c = 0; c < 8; c++) {
        int bx = c & 1, by = (c >> 1) & 1, bz = (c >> 2) & 1;
        vec3 q = vec3(hx[bx], hy[by], hz[bz]);   // clamp-to-edge = _sample._cell's clamp
        s += gx[bx] * gy[by] * gz[bz] * texture(u_vol, (q + 0.5) / vec3(g_size)).r;
    }
    return s;
}

float bspline_idx(vec3 p) {
    vec2 hx, gx, hy, gy, hz, gz;
    bs_value_taps(p.x, hx, gx); bs_value_taps(p.y, hy, gy); bs_value_taps(p.z, hz, gz);
    return table_units(bs_blend(hx, gx, hy, gy, hz, gz));
}

vec4 bspline_normal(vec3 p) {   // _bspline._bspline_normal: unit world gradient, magnitude code
    vec2 hx, gx, hy, gy, hz, gz, ex, fx, ey, fy, ez, fz;
    bs_value_taps(p.x, hx, gx); bs_value_taps(p.y, hy, gy); bs_value_taps(p.z, hz, gz);
    bs_slope_taps(p.x, ex, fx); bs_slope_taps(p.y, ey, fy); bs_slope_taps(p.z, ez, fz);
    vec3 gi = u_vol_map.y * vec3(bs_blend(ex, fx, hy, gy, hz, gz), bs_blend(hx, gx, ey, fy, hz, gz),
                                 bs_blend(hx, gx, hy, gy, ez, fz));   // table units per voxel
    vec3 g = u_nmat * gi;
    float n = length(g);
    return vec4(n > 0.0 ? g / n : vec3(0.0), 127.0 * sqrt(min(n * u_inv_gmax, 1.0)));
}

float sample_idx(vec3 p) {
    if (u_recon == 1) return bspline_idx(p);
    if (u_nearest) return table_units(texelFetch(u_vol, clamp(ivec3(p + 0.5), ivec3(0), g_size - 1), 0).r);
    return table_units(texture(u_vol, (p + 0.5) / vec3(g_size)).r);
}

float voxel(int i, int j, int k) { return table_units(texelFetch(u_vol, ivec3(i, j, k), 0).r); }

vec3 grad_at(ivec3 v) {   // _sample.grad_at: central differences or 3x3x3 Sobel, neighbours clamped
    ivec3 hi = g_size - 1;
    ivec3 p = min(v + 1, hi), m = max(v - 1, ivec3(0));
    if (!u_sobel)
        return 0.5 * vec3(voxel(p.x, v.y, v.z) - voxel(m.x, v.y, v.z), voxel(v.x, p.y, v.z) - voxel(v.x, m.y, v.z),
                          voxel(v.x, v.y, p.z) - voxel(v.x, v.y, m.z));
    vec3 g = vec3(0.0);
    for (int b = -1; b <= 1; b++) {
        for (int a = -1; a <= 1; a++) {
            float w = (a == 0 ? 2.0 : 1.0) * (b == 0 ? 2.0 : 1.0) / 32.0;
            int jj = clamp(v.y + a, 0, hi.y), kk = clamp(v.z + b, 0, hi.z);
            int ii = clamp(v.x + a, 0, hi.x), jj2 = clamp(v.y + b, 0, hi.y);
            g.x += w * (voxel(p.x, jj, kk) - voxel(m.x, jj, kk));
            g.y += w * (voxel(ii, p.y, kk) - voxel(ii, m.y, kk));
            g.z += w * (voxel(ii, jj2, p.z) - voxel(ii, jj2, m.z));
        }
    }
    return g;
}

vec4 voxel_normal(ivec3 v) {   // _sample._voxel_normal: unit world gradient, magnitude code
    vec3 g = u_nmat * grad_at(v);
    float n = length(g);
    float code = floor(127.0 * sqrt(min(n * u_inv_gmax, 1.0)) + 0.5);
    return vec4(n > 0.0 ? g / n : vec3(0.0), code);
}

vec4 normal_idx(vec3 p) {   // _sample.sample_normal: the voxels' normals, interpolated
    if (u_recon == 1) return bspline_normal(p);
    if (u_nearest) return voxel_normal(clamp(ivec3(p + 0.5), ivec3(0), g_size - 1));
    ivec3 i0 = clamp(ivec3(floor(p)), ivec3(0), g_size - 1);
    ivec3 i1 = min(i0 + 1, g_size - 1);
    vec3 f = clamp(p - vec3(i0), 0.0, 1.0);
    vec4 n = vec4(0.0);
    for (int c = 0; c < 8; c++) {
        bvec3 up = bvec3((c & 1) != 0, (c & 2) != 0, (c & 4) != 0);
        vec3 w = mix(1.0 - f, f, vec3(up));
        n += w.x * w.y * w.z * voxel_normal(ivec3(up.x ? i1.x : i0.x, up.y ? i1.y : i0.y, up.z ? i1.z : i0.z));
    }
    return n;
}

vec3 rgb_idx(vec3 p) {   // _color.sample_rgb
    ivec3 n = textureSize(u_rgb, 0);
    if (u_nearest) return texelFetch(u_rgb, clamp(ivec3(p + 0.5), ivec3(0), n - 1), 0).rgb;
    return texture(u_rgb, (p + 0.5) / vec3(n)).rgb;
}

#include "jitter.glsl"

// ---- geometry (_geometry) ----
vec2 slab(float o, float d, float lo, float hi, vec2 t) {
    if (d == 0.0) return (o < lo || o > hi) ? vec2(1.0, 0.0) : t;
    float a = (lo - o) / d, b = (hi - o) / d;
    return vec2(max(t.x, min(a, b)), min(t.y, max(a, b)));
}

vec2 region_interval(vec3 o, vec3 d, vec2 t) {
    vec3 oi = (u_to_index * vec4(o, 1.0)).xyz;
    vec3 di = (u_to_index * vec4(d, 0.0)).xyz;
    for (int i = 0; i < 3; i++) t = slab(oi[i], di[i], u_box_lo[i], u_box_hi[i], t);
    for (int i = 0; i < 3; i++) t = slab(o[i], d[i], u_wlo[i], u_whi[i], t);
    for (int p = 0; p < u_nplanes; p++) {
        float s = dot(o - u_pp[p], u_pn[p]);
        float dn = dot(d, u_pn[p]);
        if (dn == 0.0) { if (s < 0.0) return vec2(1.0, 0.0); }
        else if (dn > 0.0) t.x = max(t.x, -s / dn);
        else t.y = min(t.y, -s / dn);
    }
    return t;
}

// ---- one view ray (_ray.Ray) ----
struct Ray { vec3 o, d, oi, di; float t0, t1, jit; int n; };
Ray R;

float sample_at(float t) { return sample_idx(R.oi + t * R.di); }

bool begin_ray(int px, int py) {
    float sx = (float(px) + 0.5 - 0.5 * u_wh.x) / (0.5 * u_wh.y) * u_half;
    float sy = (0.5 * u_wh.y - float(py) - 0.5) / (0.5 * u_wh.y) * u_half;
    if (u_ortho) { R.o = u_eye + sx * u_right + sy * u_up; R.d = u_fwd; }
    else { R.o = u_eye; R.d = normalize(u_fwd + sx * u_right + sy * u_up); }
    vec2 t = region_interval(R.o, R.d, vec2(u_near, u_far));
    R.oi = (u_to_index * vec4(R.o, 1.0)).xyz;
    R.di = (u_to_index * vec4(R.d, 0.0)).xyz;
    R.t0 = t.x; R.t1 = t.y;
    R.jit = u_jitter ? jitter01(px, py, u_seed) : 0.0;
    R.n = 1;
    if (t.y >= t.x) R.n = max(int(floor((t.y - t.x) / u_ds - R.jit + 1e-4)) + 1, 1);
    return t.y >= t.x;
}

// ---- shadows (_shadow, _lightvol) ----
float sig_at(vec3 p) {
    int n = textureSize(u_extinction, 0).x;
    return texelFetch(u_extinction, ivec2(clamp(int(sample_idx(p) + 0.5), 0, n - 1), 0), 0).r;
}

float shadow_transmittance(vec3 o, vec3 l, float smax) {
    vec2 ab = region_interval(o, l, vec2(0.0, smax));
    if (!(ab.y > ab.x)) return 1.0;
    vec3 oi = (u_to_index * vec4(o, 1.0)).xyz;
    vec3 di = (u_to_index * vec4(l, 0.0)).xyz;
    float stop = TAU_STOP * u_ds0 / u_extinction_scale;
    float sp = sig_at(oi + ab.x * di), acc = 0.0, t = ab.x;
    int m = int((ab.y - ab.x) / u_shadow_step);
    for (int j = 1; j <= m; j++) {
        t = ab.x + float(j) * u_shadow_step;
        float s = sig_at(oi + t * di);
        acc += 0.5 * (sp + s) * u_shadow_step;
        sp = s;
        if (acc > stop) return 0.0;
    }
    if (ab.y - t > 1e-6 * u_shadow_step) acc += 0.5 * (sp + sig_at(oi + ab.y * di)) * (ab.y - t);
    return exp(-u_extinction_scale * acc / u_ds0);
}

float lvd(int i) { return texelFetch(u_light_data, ivec2(i % u_light_data_w, i / u_light_data_w), 0).r; }
float lvm(int li, int f) { return u_lvm[li * 4 + f / 4][f % 4]; }

float slice_value(int base, int nv, int nu, float q, float ub, float uc, float cb, float cc, float pb, float pc) {
    float u = uc + (cc - pc) * q;
    float v = ub + (cb - pb) * q;
    if (!(u >= 0.0 && v >= 0.0 && u <= float(nu - 1) && v <= float(nv - 1))) return 1.0;
    int u0 = min(int(u), nu - 2), v0 = min(int(v), nv - 2);
    float fu = u - float(u0), fv = v - float(v0);
    int i = base + v0 * nu + u0;
    float r0 = mix(lvd(i), lvd(i + 1), fu);
    float r1 = mix(lvd(i + nu), lvd(i + nu + 1), fu);
    return mix(r0, r1, fv);
}

float pick(int ax, vec3 p) { return ax == 0 ? p.z : (ax == 1 ? p.y : p.x); }

float lattice_transmittance(int li, vec3 p) {   // _lightvol.lattice_site + lattice_read; meta fields LV_*
    float ca = pick(int(lvm(li, 5)), p), cb = pick(int(lvm(li, 6)), p), cc = pick(int(lvm(li, 7)), p);
    int nk = int(lvm(li, 2)), nv = int(lvm(li, 3)), nu = int(lvm(li, 4));
    float pa = lvm(li, 8), kfar = lvm(li, 11), k0 = lvm(li, 12);
    float kf = ca - k0;
    bool low = pa < k0;
    if (kf < 0.0) { if (low) return 1.0; kf = 0.0; }
    if (kf > float(nk - 1)) { if (!low) return 1.0; kf = float(nk - 1); }
    int i0 = min(int(kf), max(nk - 2, 0)), i1 = min(i0 + 1, nk - 1);
    float w = kf - float(i0);
    float pb = lvm(li, 9), pc = lvm(li, 10), ih = 1.0 / lvm(li, 15);
    float ub = (pb - lvm(li, 13)) * ih, uc = (pc - lvm(li, 14)) * ih, ph = (kfar - pa) * ih;
    int off = u_lvoff[li];
    float t0 = slice_value(off + i0 * nv * nu, nv, nu, ph / (k0 + float(i0) - pa), ub, uc, cb, cc, pb, pc);
    if (w <= 0.0 || i1 == i0) return t0;
    float t1 = slice_value(off + i1 * nv * nu, nv, nu, ph / (k0 + float(i1) - pa), ub, uc, cb, cc, pb, pc);
    return t0 + w * (t1 - t0);
}

float light_visibility(int li, vec3 w, vec3 l, float dist) {   // _shade.light_visibility
    float off = u_shadow_offset;
    if (dist <= off) return 1.0;
    vec3 y = w + off * l;
    int kind = int(lvm(li, 0));
    if (kind == 2) return shadow_transmittance(y, l, dist - off);
    if (kind == 1) {
        float near = min(NEAR_STEPS * u_ds0, dist - off);
        float tr = shadow_transmittance(y, l, near);
        if (near < dist - off && tr > 0.0) tr *= lattice_transmittance(li, (u_to_index * vec4(y + near * l, 1.0)).xyz);
        return tr;
    }
    return 1.0;
}

// ---- lighting (_shade, optics) ----
vec4 light_vector(int li, vec3 w) {   // (unit L toward the light, distance); spot factor separately
    vec3 l = u_lpos[li] - w;
    float d = length(l);
    return vec4(d > 0.0 ? l / d : l, d);
}

float spot_factor(int li, vec3 l) {
    if (u_lexp[li] == 0.0) return 1.0;
    float c = dot(-l, u_ldir[li]);
    return c <= 0.0 ? 0.0 : pow(c, u_lexp[li]);
}

// lighting factors: colour' = colour * f + alpha * s (f in .xyz of the first, s of the second)
void shade(vec3 g, vec3 v, vec3 w, out vec3 f, out vec3 s) {
    f = vec3(1.0); s = vec3(0.0);
#if LIGHT == LIGHT_PHONG || LIGHT == LIGHT_SHADOWED
    float gl = length(g);
    bool flat_ = gl < 1e-3;
    vec3 n = flat_ ? vec3(0.0) : g / gl;
    if (dot(n, v) < -FACING) n = -n;   // core.FACING: at right angles it keeps its side
    f = u_env_mode == 0 ? vec3(u_ambient) : (flat_ ? sh_sum(n, 0.0, 0.0) : sh_sum(n, 2.0 / 3.0, 0.25));
    for (int li = 0; li < u_nlights; li++) {
        vec4 lv = light_vector(li, w);
        float spot = spot_factor(li, lv.xyz);
        if (spot <= 0.0) continue;
        float diff = 1.0, spec = 0.0;
        if (!flat_) {   // optics.phong_terms
            float ndl = dot(n, lv.xyz);
            diff = max(ndl, 0.0);
            if (ndl > 0.0) {
                float rdv = dot(2.0 * ndl * n - lv.xyz, v);
                spec = rdv > 0.0 ? pow(rdv, u_shininess) : 0.0;
            }
        }
        if (diff <= 0.0) continue;
        float wt = spot;
#if LIGHT == LIGHT_SHADOWED
        wt *= light_visibility(li, w, lv.xyz, lv.w);
#endif
        f += u_diffuse * diff * wt * u_lcol[li];
        s += u_specular * spec * wt * u_lcol[li];
    }
#elif LIGHT == LIGHT_SCATTER
    f = vec3(u_env_mode == 0 ? u_ambient : 0.0);
    for (int li = 0; li < u_nlights; li++) {
        vec4 lv = light_vector(li, w);
        float spot = spot_factor(li, lv.xyz);
        if (spot <= 0.0) continue;
        float c = -dot(lv.xyz, v), g2 = u_phase_g * u_phase_g;   // _scatter.phase_weight: 4 pi HG
        float wt = spot * (1.0 - g2) / pow(1.0 + g2 - 2.0 * u_phase_g * c, 1.5);
        wt *= light_visibility(li, w, lv.xyz, lv.w);
        f += wt * u_lcol[li];
    }
    if (u_env_mode == 0) f = (u_ambient + u_diffuse * (f - u_ambient)) * u_albedo;
    else f = (sh_sum(-v, u_phase_g, u_phase_g * u_phase_g) + u_diffuse * f) * u_albedo;
#endif
}

#include "raycast_modes.glsl"

void main() {
    g_size = textureSize(u_vol, 0);
    int px = int(gl_FragCoord.x - u_origin.x);
    int py = int(u_wh.y) - 1 - int(gl_FragCoord.y - u_origin.y);
    o_rgba = vec4(0.0);
    o_aux = vec4(FAR, FAR, 0.0, 0.0);
    if (!begin_ray(px, py)) return;
    march();
}

#endif
