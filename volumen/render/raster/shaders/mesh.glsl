// Triangle meshes in world mm, lit by the scene's lights.
// Variants: GOURAUD (lighting per vertex, colours interpolated; else Phong per
// pixel from the interpolated normal), MAX_LIGHTS, MAX_CLIP.
// Attachment 1 gets the distance along the view ray (Image.depth): from the eye,
// or for orthographic cameras from the image plane through the camera position.

#include "lighting.glsl"

uniform mat4 u_mvp;
uniform vec3 u_eye;
uniform vec3 u_forward;
uniform bool u_ortho;
uniform vec3 u_color;   // linear RGB

vec3 toward_viewer(vec3 p) {
    return u_ortho ? -u_forward : normalize(u_eye - p);
}

vec3 lit(vec3 n, vec3 p) {
    vec3 f, s;
    shade(n, toward_viewer(p), p, f, s);
    return u_color * f + s;
}

#if defined VERTEX_SHADER

in vec3 in_pos;
in vec3 in_normal;
out vec3 v_world;
out vec3 v_normal;
out vec3 v_color;

void main() {
    v_world = in_pos;
    v_normal = in_normal;
#if defined GOURAUD
    v_color = lit(in_normal, in_pos);
#else
    v_color = vec3(0.0);
#endif
    gl_Position = u_mvp * vec4(in_pos, 1.0);
}

#elif defined FRAGMENT_SHADER

in vec3 v_world;
in vec3 v_normal;
in vec3 v_color;
uniform vec2 u_range;            // drawn ray distances [near, far], mm
uniform int u_nclip;
uniform vec4 u_clip[MAX_CLIP];   // keep dot(n, p) + w >= 0
layout(location = 0) out vec4 f_color;
layout(location = 1) out vec4 f_depth;

void main() {
    float d = u_ortho ? dot(v_world - u_eye, u_forward) : length(v_world - u_eye);
    if (d < u_range.x || d > u_range.y) discard;
    for (int i = 0; i < u_nclip; ++i)
        if (dot(u_clip[i].xyz, v_world) + u_clip[i].w < 0.0) discard;
#if defined GOURAUD
    vec3 c = v_color;
#else
    vec3 c = lit(v_normal, v_world);
#endif
    f_color = vec4(min(c, vec3(1.0)), 1.0);
    f_depth = vec4(d, 0.0, 0.0, 1.0);
}

#endif
