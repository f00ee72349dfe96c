#version 330 core
// Cheap divergence check: each output texel sums texture G0 (g0 of both nodes of a texel,
// g1 of node a, g3 of node b: shaders/paired_layout.glsl) over a BLOCK_X x BLOCK_Y tile of
// texels; a NaN or Inf anywhere makes its tile's sum non-finite (NaN spreads to every population of the neighbours within a
// step, so one texture suffices). The sums of step k go
// to a band of an atlas whose lower-left texel is `band`; the tiles are shaped so that a band
// is at least 128 texels wide (two of llvmpipe's 64 x 64 bins: both threads share the work).
// @LATTICE

uniform sampler2D G0;
uniform ivec2 N;       // the lattice's texels (ceil(nx / 2), ny)
uniform ivec2 band;

out vec4 tile_sum;

void main() {
    ivec2 origin = (ivec2(gl_FragCoord.xy) - band) * ivec2(BLOCK_X, BLOCK_Y);
    vec4 s = vec4(0.0);
    for (int dy = 0; dy < BLOCK_Y; ++dy)
        for (int dx = 0; dx < BLOCK_X; ++dx)
            s += texelFetch(G0, min(origin + ivec2(dx, dy), N - 1), 0);
    tile_sum = s;
}
