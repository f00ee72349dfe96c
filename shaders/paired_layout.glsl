#version 330 core
// Included (// @INCLUDE paired_layout.glsl, after // @LATTICE) by the programs that read the
// stored populations node by node. The layout, defined once in solver/gl_layout.py: two nodes
// per texel, a = (2k, y) and b = (2k + 1, y) in texel (k, y) of five RGBA32F textures,
//   G0 (g1a g1b g3a g3b)  G1 (g5a g5b g6a g6b)  G2 (g7a g7b g8a g8b)  G3 (g2a g2b g4a g4b)
//   G4 (g0a g0b  -   - )  (zw: zero, except in the body window with lbm_step.glsl's LINK_SUMS)
// so that the directions sharing a row offset share texels when a fragment streams both nodes
// (lbm_step.glsl, stream_pair: 12 fetches for 2 nodes instead of 18).

uniform sampler2D G0;
uniform sampler2D G1;
uniform sampler2D G2;
uniform sampler2D G3;
uniform sampler2D G4;

// SLOT[i] = (texture, channel of node a) of direction i; node b is the next channel
const ivec2 SLOT[9] = ivec2[9](ivec2(4, 0), ivec2(0, 0), ivec2(3, 0), ivec2(0, 2), ivec2(3, 2),
                               ivec2(1, 0), ivec2(1, 2), ivec2(2, 0), ivec2(2, 2));

vec4 layout_texel(int t, ivec2 k) {  // texel k of texture t (t is constant after unrolling)
    if (t == 0) return texelFetch(G0, k, 0);
    if (t == 1) return texelFetch(G1, k, 0);
    if (t == 2) return texelFetch(G2, k, 0);
    if (t == 3) return texelFetch(G3, k, 0);
    return texelFetch(G4, k, 0);
}

float pop(int j, ivec2 p) {  // stored g_j at node p (inside the grid)
    return layout_texel(SLOT[j].x, ivec2(p.x >> 1, p.y))[SLOT[j].y + (p.x & 1)];
}

// the stored populations of both nodes of texel k (five fetches)
void load_pair(ivec2 k, out float a[9], out float b[9]) {
    vec4 t[5] = vec4[5](texelFetch(G0, k, 0), texelFetch(G1, k, 0), texelFetch(G2, k, 0),
                        texelFetch(G3, k, 0), texelFetch(G4, k, 0));
    for (int i = 0; i < Q; ++i) {
        a[i] = t[SLOT[i].x][SLOT[i].y];
        b[i] = t[SLOT[i].x][SLOT[i].y + 1];
    }
}

// the stored populations of node p (five fetches)
void load_node(ivec2 p, out float g[9]) {
    float a[9];
    float b[9];
    load_pair(ivec2(p.x >> 1, p.y), a, b);
    bool odd = (p.x & 1) == 1;
    for (int i = 0; i < Q; ++i) g[i] = odd ? b[i] : a[i];
}
