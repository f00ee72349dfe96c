#version 330 core
// Colours the flow field for the window: one quantity through a colormap look-up texture.
// field texel (ix, iy) = (rho, ux, uy, vorticity) in lattice units (docs/science/algorithm.md).
// @LATTICE

uniform sampler2D field;
uniform sampler2D lut;      // 256 x 1 RGBA colormap (built by pyqtgraph's ColorMap)
uniform int mode;           // 0 speed, 1 vorticity, 2 pressure, 3 tracers (speed, faded)
uniform float scale;        // lattice value -> shown value (e.g. 1/U for speed / wind speed)
uniform vec2 range;         // shown values at the bottom and the top of the colour bar
uniform float rho_ref;      // free-stream density: pressure is shown relative to it
uniform int bgra;           // 1: blue, green, red, alpha (a QImage of Format_RGB32 on little-endian)

in vec2 uv;
out vec4 colour;

void main() {
    vec4 f = texture(field, uv);
    if (any(isnan(f)) || any(isinf(f))) {   // never draw garbage: flat grey
        colour = vec4(0.5, 0.5, 0.5, 1.0);
        return;
    }
    float v;
    if (mode == 1) {
        v = f.w;
    } else if (mode == 2) {
        v = CS2 * (f.x - rho_ref);          // p - p_inf = c_s^2 (rho - rho_inf)
    } else {
        v = length(f.yz);
    }
    float s = clamp((v * scale - range.x) / (range.y - range.x), 0.0, 1.0);
    colour = vec4(texture(lut, vec2(s, 0.5)).rgb, 1.0);
    if (mode == 3) {
        colour.rgb = mix(vec3(0.96), colour.rgb, 0.3);
    }
    if (bgra == 1) {
        colour = colour.bgra;
    }
}
