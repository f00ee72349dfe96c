#version 330 core
// Cheap divergence check: each output texel sums the stored g_0..g_3 over a BLOCK x BLOCK
// tile of nodes; a NaN or Inf anywhere makes its tile's sum non-finite (NaN spreads to every
// population of the neighbours within a step, so one texture suffices).
// @LATTICE

uniform sampler2D G0;
uniform ivec2 N;

out vec4 tile_sum;

void main() {
    ivec2 origin = ivec2(gl_FragCoord.xy) * BLOCK;
    vec4 s = vec4(0.0);
    for (int dy = 0; dy < BLOCK; ++dy)
        for (int dx = 0; dx < BLOCK; ++dx)
            s += texelFetch(G0, min(origin + ivec2(dx, dy), N - 1), 0);
    tile_sum = s;
}
