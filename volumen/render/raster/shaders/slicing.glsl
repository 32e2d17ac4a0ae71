// Texture slicing: view-aligned polygons through the volume, blended in order.
// Variants: PRE_CLASSIFIED (u_volume holds premultiplied RGBA per voxel, else the
// normalized value looked up in the transfer function), SHADED (Phong from the
// gradient by central differences), MAX_LIGHTS, MAX_CLIP.

#if defined VERTEX_SHADER

in vec3 in_pos;    // world mm
in float in_gap;   // slab thickness of the plane, mm of view depth
uniform mat4 u_mvp;
uniform mat4 u_world_to_tex;
out vec3 v_world;
out vec3 v_tex;
out float v_gap;

void main() {
    v_world = in_pos;
    v_tex = (u_world_to_tex * vec4(in_pos, 1.0)).xyz;
    v_gap = in_gap;
    gl_Position = u_mvp * vec4(in_pos, 1.0);
}

#elif defined FRAGMENT_SHADER

in vec3 v_world;
in vec3 v_tex;
in float v_gap;
uniform sampler3D u_volume;
uniform sampler2D u_tf;          // (N x 1): straight rgb, alpha per reference step
uniform float u_tf_n;            // N
uniform vec3 u_eye;
uniform vec3 u_forward;
uniform bool u_ortho;
uniform float u_ds0;             // reference step, mm
uniform vec2 u_range;            // drawn ray distances [near, far], mm
uniform int u_nclip;
uniform vec4 u_clip[MAX_CLIP];   // keep dot(n, p) + w >= 0
uniform vec3 u_texel;            // one voxel in texture coordinates
uniform mat3 u_grad_to_world;    // inverse transpose of the affine's 3x3
uniform float u_zref;            // view depth the depth moments are taken from, mm
uniform mat4 u_world_to_tex;
uniform bool u_jitter;           // sample each pixel's rays off the planes by its jitter (against wood grain)
uniform int u_seed;              // the jitter's frame seed
layout(location = 0) out vec4 f_color;   // premultiplied
layout(location = 1) out vec4 f_tau;     // optical depth tau, tau z, tau z^2 (added up)

#if defined SHADED
#include "lighting.glsl"
#endif
#include "jitter.glsl"

void main() {
    vec3 dir = u_ortho ? u_forward : normalize(v_world - u_eye);
    // the sample: on the plane, or, jittered, moved along the pixel's ray by its share of the slab (-1/2..1/2),
    // the same for all the pixel's planes: their wood grain on a smooth surface becomes the ray caster's noise
    vec3 p = v_world;
    if (u_jitter)
        p += (jitter01(int(gl_FragCoord.x), int(gl_FragCoord.y), u_seed) - 0.5) * v_gap / dot(dir, u_forward) * dir;
    vec3 tex = u_jitter ? (u_world_to_tex * vec4(p, 1.0)).xyz : v_tex;
    float dist = u_ortho ? dot(p - u_eye, u_forward) : length(p - u_eye);
    if (dist < u_range.x || dist > u_range.y) discard;
    for (int i = 0; i < u_nclip; ++i)
        if (dot(u_clip[i].xyz, p) + u_clip[i].w < 0.0) discard;
#if defined PRE_CLASSIFIED
    vec4 c = texture(u_volume, tex);         // premultiplied, opacity per reference step
    float a = c.a;
    vec3 rgb = a > 0.0 ? c.rgb / a : vec3(0.0);
#else
    float u = texture(u_volume, tex).r;
    vec4 c = texture(u_tf, vec2((u * (u_tf_n - 1.0) + 0.5) / u_tf_n, 0.5));
    float a = c.a;
    vec3 rgb = c.rgb;
#endif
    // opacity correction for the path through this slab: gap / cos(theta) against ds0
    float ratio = v_gap / (dot(dir, u_forward) * u_ds0);
    float ac = a >= 1.0 ? 1.0 : 1.0 - pow(1.0 - a, ratio);
    if (ac <= 0.0) discard;
    vec3 col = rgb * ac;
#if defined SHADED
    vec3 t = u_texel;
    vec3 g = 0.5 * vec3(
        texture(u_volume, tex + vec3(t.x, 0, 0)).PROBE - texture(u_volume, tex - vec3(t.x, 0, 0)).PROBE,
        texture(u_volume, tex + vec3(0, t.y, 0)).PROBE - texture(u_volume, tex - vec3(0, t.y, 0)).PROBE,
        texture(u_volume, tex + vec3(0, 0, t.z)).PROBE - texture(u_volume, tex - vec3(0, 0, t.z)).PROBE);
    vec3 f, s;
    shade(u_grad_to_world * g, -dir, v_world, f, s);
    col = col * f + ac * s;
#endif
    f_color = vec4(col, ac);
    float tau = ac >= 1.0 ? 30.0 : -log(1.0 - ac);
    float z = dot(v_world - u_eye, u_forward) - u_zref;
    f_tau = vec4(tau, tau * z, tau * z * z, 0.0);
}

#endif
