// The marching skeleton (raycast/_march.py) and the pieces of each mode (_composite, _project, _iso),
// chosen by MODE at compile time. Included by raycast.glsl (uses its R, sample_at, shade...).

vec4 S_acc;                 // composite: premultiplied colour and opacity
float S_dep;                // depth (mm, FAR: none)
float S_v, S_t, S_side;     // previous / extreme value, its t, iso side (average: S_v sum, S_t count)
int taken, extra;
bool done, have;

vec4 corrected(vec4 c, float seg, float ds) {   // _composite._corrected
    if (c.a > 0.0 && seg != ds) {
        float a2 = c.a >= 1.0 ? 1.0 : 1.0 - pow(1.0 - c.a, seg / ds);
        return vec4(c.rgb * (a2 / c.a), a2);
    }
    return c;
}

vec4 lit(float t, vec4 c, bool gradop) {   // _composite.lit
    if (u_color) c.rgb = c.a * rgb_idx(R.oi + t * R.di);   // _color.emission
    vec4 g = vec4(0.0);
#if LIGHT == LIGHT_PHONG || LIGHT == LIGHT_SHADOWED
    g = normal_idx(R.oi + t * R.di);
#else
    if (gradop) g = normal_idx(R.oi + t * R.di);
#endif
    if (gradop) c *= texelFetch(u_gradient_lut, ivec2(min(int(g.w + 0.5), 127), 0), 0).r;
    if (c.a > 0.0) {
        vec3 f, s;
        shade(g.xyz, -R.d, R.o + t * R.d, f, s);
        c.rgb = c.rgb * f + c.a * s;
    }
    return c;
}

void accumulate(vec4 c, float t) {   // _composite._accumulate, optics.composite
    if (c.a > 0.0) {
        S_acc += (1.0 - S_acc.a) * c;
        if (S_dep == FAR && S_acc.a >= DEPTH_OPACITY) S_dep = t;
    }
    done = S_acc.a >= u_early_termination;
}

vec4 lookup_pre(float vf, float vb) {
    int n = textureSize(u_preintegrated, 0).x - 1;
    ivec2 at = ivec2(min(int(vb * u_pre_scale + 0.5), n), min(int(vf * u_pre_scale + 0.5), n));
    return texelFetch(u_preintegrated, at, 0);
}

vec4 lut_at(float v) {
    vec4 e = texelFetch(u_lut, ivec2(clamp(int(v + 0.5), 0, textureSize(u_lut, 0).x - 1), 0), 0);
    return vec4(e.rgb * e.a, e.a);
}

bool beyond(float v, float side) { return side > 0.0 ? v >= u_iso_value : v < u_iso_value; }

float crossing(float side, float ta, float fa, float tb, float fb) {   // _iso._crossing
    fa = side * (fa - u_iso_value);
    fb = side * (fb - u_iso_value);
    for (int i = 0; i < 4; i++) {
        float tm = ta + (0.0 - fa) / (fb - fa) * (tb - ta);
        float vm = side * (sample_at(tm) - u_iso_value);
        if (vm >= 0.0) { tb = tm; fb = vm; } else { ta = tm; fa = vm; }
    }
    if (fb - fa <= 0.0) return tb;
    return ta + (0.0 - fa) / (fb - fa) * (tb - ta);
}

void init_mode() {
    S_acc = vec4(0.0); S_dep = FAR; S_v = 0.0; S_t = R.t0; S_side = 1.0;
    taken = 0; done = false; have = false;
#if MODE == MODE_MIP
    S_v = -FAR;
#elif MODE == MODE_MINIP
    S_v = FAR;
#elif MODE == MODE_AVERAGE
    S_t = 0.0;
#elif MODE == MODE_ISO
    float v = sample_at(R.t0);
    S_side = (R.t0 <= u_near && v >= u_iso_value) ? -1.0 : 1.0;
    S_dep = beyond(v, S_side) ? R.t0 : FAR;
    S_v = v; taken = 1; done = S_dep < FAR; have = true;
#endif
}

void step_mode(int k, float t, float v) {
#if MODE == MODE_COMPOSITE
    float seg = u_ds;
    if (k == 0 || k == R.n - 1) seg = (k == R.n - 1 ? R.t1 : t + 0.5 * u_ds) - (k == 0 ? R.t0 : t - 0.5 * u_ds);
    vec4 c = corrected(lut_at(v), seg, u_ds);
    if (c.a > 0.0) c = lit(t, c, u_gradient_opacity);
    accumulate(c, t);
#elif MODE == MODE_PREINT
    float vp = S_v, tp = S_t;
    if (k == 0) { vp = v; tp = R.t0; }
    else if (!have) { tp = R.t0 + (float(k - 1) + R.jit) * u_ds; vp = sample_at(tp); extra = 1; }
    float seg = (k == 0 || k == R.n - 1) ? t - tp : u_ds;
    vec4 c = corrected(lookup_pre(vp, v), seg, u_ds);
    if (c.a > 0.0) c = lit(t, c, u_gradient_opacity);
    accumulate(c, t);
    S_v = v; S_t = t;
#elif MODE == MODE_MIP
    if (v > S_v) { S_v = v; S_dep = t; }
#elif MODE == MODE_MINIP
    if (v < S_v) { S_v = v; S_dep = t; }
#elif MODE == MODE_AVERAGE
    S_v += v; S_t += 1.0;
#elif MODE == MODE_ISO
    if (!beyond(v, S_side)) { S_dep = FAR; S_v = v; S_t = t; return; }
    float vp = S_v, tp = S_t;
    if (!have) { tp = max(t - u_ds, R.t0); vp = sample_at(tp); extra = 1; }
    S_dep = beyond(vp, S_side) ? t : crossing(S_side, tp, vp, t, v);
    done = true;
#endif
}

int octant_side(ivec3 b) {   // _octants.tiled: the ray's octant's grid in the (2 gz, 2 gy, 2 gx) texture
    ivec3 g = textureSize(u_bmin, 0);
    return int(texelFetch(u_skip_flags, b + ivec3(R.di.x < 0.0 ? g.x : 0, R.di.y < 0.0 ? g.y : 0,
                                             R.di.z < 0.0 ? g.z : 0), 0).r);
}

int radius_mode(ivec3 b) {
#if MODE == MODE_COMPOSITE || MODE == MODE_PREINT
    return octant_side(b);
#elif MODE == MODE_MIP
    return texelFetch(u_bmax, b, 0).r <= S_v ? 1 : 0;
#elif MODE == MODE_MINIP
    return texelFetch(u_bmin, b, 0).r >= S_v ? 1 : 0;
#elif MODE == MODE_ISO
    return S_side > 0.0 ? octant_side(b) : 0;
#else
    return 0;
#endif
}

#if MODE == MODE_COMPOSITE || MODE == MODE_ISO
const bool EAGER = true;
#else
const bool EAGER = false;
#endif

float box_exit(float x, float d, int b, int rad, float size) {
    if (d > 0.0) return (float(b + rad) * size - x) / d;
    if (d < 0.0) return (float(b - rad + 1) * size - x) / d;
    return FAR;
}

int jump(int k, float t, inout bool prev_skip, out bool jumped) {   // per sample; the CPU walks the blocks (_walk.walk)
    jumped = false;
    vec3 x = R.oi + t * R.di;
    float size = float(u_block);
    ivec3 b = clamp(ivec3(x / size), ivec3(0), textureSize(u_bmin, 0) - 1);
    int rad = radius_mode(b);
    if (rad <= 0) { prev_skip = false; return k; }
    if (!(prev_skip || EAGER)) { prev_skip = true; return k; }
    float dt = min(box_exit(x.x, R.di.x, b.x, rad, size),
                   min(box_exit(x.y, R.di.y, b.y, rad, size), box_exit(x.z, R.di.z, b.z, rad, size)));
    jumped = true;
    return max(int(ceil((t + dt - R.t0) / u_ds - R.jit)), k + 1);
}

void write_value(float v, float dep) {
    o_rgba = lut_at(v);
    o_aux = vec4(dep, v, float(taken), 0.0);
}

void finish_mode() {
#if MODE == MODE_PREINT
    if (S_acc.a < u_early_termination && R.t1 - S_t > 1e-6 * u_ds) {
        float vp = S_v, tp = S_t;
        if (!have) { tp = min(R.t0 + (float(R.n - 1) + R.jit) * u_ds, R.t1); vp = sample_at(tp); taken++; }
        vec4 c = lookup_pre(vp, sample_at(R.t1));
        if (c.a > 0.0) accumulate(corrected(lit(R.t1, c, false), R.t1 - tp, u_ds), R.t1);
        taken++;
    }
#endif
#if MODE == MODE_COMPOSITE || MODE == MODE_PREINT
    o_rgba = u_hdr ? vec4(S_acc.rgb, min(S_acc.a, 1.0)) : min(S_acc, vec4(1.0));
    o_aux = vec4(S_dep, FAR, float(taken), 0.0);
#elif MODE == MODE_MIP || MODE == MODE_MINIP
    o_aux.z = float(taken);
    if (taken > 0) write_value(S_v, S_dep);
#elif MODE == MODE_AVERAGE
    o_aux.z = float(taken);
    if (S_t > 0.0) write_value(S_v / S_t, R.t0);
#elif MODE == MODE_ISO
    o_aux.z = float(taken);
    if (S_dep >= FAR) return;
    vec3 f, s;
    shade(normal_idx(R.oi + S_dep * R.di).xyz, -R.d, R.o + S_dep * R.d, f, s);
    o_rgba = vec4(min(u_iso_rgb * f + s, vec3(1.0)), 1.0);
    o_aux.x = S_dep;
#endif
}

void march() {
    init_mode();
    bool prev_skip = false;
    int k = 0;
    while (k < R.n && !done) {
        float t = min(R.t0 + (float(k) + R.jit) * u_ds, R.t1);
        if (u_skip) {
            bool jumped;
            k = jump(k, t, prev_skip, jumped);
            if (jumped) { have = false; continue; }
        }
        extra = 0;
        step_mode(k, t, sample_at(t));
        taken += 1 + extra;
        have = true;
        k++;
    }
    finish_mode();
}
