// The display transform (volumen/core/_tonemap.py, docs/design.md section 5) as a final pass: the ray caster's
// picture, premultiplied linear RGBA in a texture, becomes display values in the bound framebuffer's viewport.
// The browser viewer draws every picture through it (volumen/web/static/display.js); the desktop devices return
// linear pictures and Image.to_uint8 applies the same transform in Python. The constants are not written here:
// the page sets them from core._tonemap.shader_constants() (u_aces, u_srgb).
//   u_tonemap 0 (linear): rgba * gain, clipped: Image.to_uint8 of a `linear` display over black
//   u_tonemap 1 (aces):   a * srgb(aces(gain * rgb / a)), a: Display.encode over black, premultiplied
// gain = 2^exposure (stops: given, or metered on the linear picture by the page). The viewport's picture is
// the whole texture, stretched with linear filtering when smaller (reduced resolution).

#if defined VERTEX_SHADER

in vec2 in_pos;

void main() {
    gl_Position = vec4(in_pos, 0.0, 1.0);
}

#elif defined FRAGMENT_SHADER

uniform sampler2D u_linear;   // premultiplied linear RGBA
uniform vec4 u_viewport;      // x, y, width, height of the picture in the framebuffer, pixels
uniform int u_tonemap;        // 0 linear, 1 aces
uniform float u_gain;         // 2^exposure
uniform float u_aces[5];      // A, B, C, D, E of x (A x + B) / (x (C x + D) + E)
uniform float u_srgb[5];      // linear-segment limit, slope, scale, exponent, offset
out vec4 frag;

vec3 aces(vec3 x) {
    x = max(x, vec3(0.0));
    return clamp(x * (u_aces[0] * x + u_aces[1]) / (x * (u_aces[2] * x + u_aces[3]) + u_aces[4]), 0.0, 1.0);
}

vec3 srgb_encode(vec3 x) {
    vec3 curve = u_srgb[2] * pow(max(x, vec3(u_srgb[0])), vec3(1.0 / u_srgb[3])) - u_srgb[4];
    return mix(u_srgb[1] * x, curve, greaterThan(x, vec3(u_srgb[0])));
}

void main() {
    vec4 c = texture(u_linear, (gl_FragCoord.xy - u_viewport.xy) / u_viewport.zw);
    if (u_tonemap == 0) {
        frag = clamp(vec4(c.rgb * u_gain, c.a), 0.0, 1.0);
        return;
    }
    float a = clamp(c.a, 0.0, 1.0);
    vec3 straight = c.a > 0.0 ? c.rgb / max(c.a, 1e-12) : vec3(0.0);
    frag = vec4(a * srgb_encode(aces(u_gain * straight)), a);
}

#endif
