// Lighting of one sample or surface point: the Phong model of volumen.render.optics
// (docs/design.md section 3), included by the programs that shade. Needs MAX_LIGHTS defined.
// Two-sided: the normal is turned toward the viewer; a zero gradient counts every
// light as head-on (diffuse 1, no specular). Spot factor max(dot(L, D), 0)^exponent,
// L the unit vector from the light to the point; exponent 0 is a point light.

uniform int u_nlights;
uniform vec3 u_light_pos[MAX_LIGHTS];   // world mm
uniform vec3 u_light_dir[MAX_LIGHTS];   // unit spot axis
uniform vec3 u_light_col[MAX_LIGHTS];   // linear RGB x intensity
uniform float u_light_exp[MAX_LIGHTS];  // spot exponent
uniform vec4 u_phong;                   // ambient, diffuse, specular, shininess

float power_of(float x, float e) {
    return e == 0.0 ? 1.0 : (x <= 0.0 ? 0.0 : pow(x, e));
}

// g: gradient or normal (any length), V: unit vector toward the viewer, P: world point (mm).
// The shaded straight colour is c * f + s; premultiplied C * f + alpha * s.
void shade(vec3 g, vec3 V, vec3 P, out vec3 f, out vec3 s) {
    float len = length(g);
    bool flat_ = len < 1e-20;
    vec3 N = flat_ ? vec3(0.0) : g / len;
    if (dot(N, V) < 0.0) N = -N;
    f = vec3(u_phong.x);
    s = vec3(0.0);
    for (int l = 0; l < u_nlights; ++l) {
        vec3 L = u_light_pos[l] - P;
        float d = length(L);
        L = d > 0.0 ? L / d : L;
        float spot = power_of(max(dot(-L, u_light_dir[l]), 0.0), u_light_exp[l]);
        if (spot <= 0.0) continue;
        float diff = 1.0;
        float spec = 0.0;
        if (!flat_) {
            float ndl = dot(N, L);
            diff = max(ndl, 0.0);
            if (ndl > 0.0) {
                float rdv = dot(2.0 * ndl * N - L, V);
                spec = rdv > 0.0 ? power_of(rdv, u_phong.w) : 0.0;
            }
        }
        vec3 w = spot * u_light_col[l];
        f += u_phong.y * diff * w;
        s += u_phong.z * spec * w;
    }
}
