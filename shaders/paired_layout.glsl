#version 330 core
// Included (// @INCLUDE paired_layout.glsl, after // @LATTICE) by the programs that read the
// stored populations node by node. The layout, defined once in solver/gl_layout.py: two nodes
// per texel, a = (2k, y) and b = (2k + 1, y) in texel (k, y) of five RGBA32F textures,
//   G0 (g0a g1a g0b g3b)  G1 (g2a g5a g2b g6b)  G2 (g4a g8a g4b g7b)
//   G3 (g1b g3a g5b g6a)  G4 (g8b g7a  -   - )  (G4 zw: zero, except in the body window with
//   lbm_step.glsl's LINK_SUMS)
// so that a fragment streaming both nodes of its texel fetches each of the nine texels around
// it once (lbm_step.glsl, stream_pair: 9 fetches for 2 nodes, 18 node by node).

uniform sampler2D G0;
uniform sampler2D G1;
uniform sampler2D G2;
uniform sampler2D G3;
uniform sampler2D G4;

// SLOT[i] = (texture, channel) of direction i for node a, then for node b
const ivec4 SLOT[9] = ivec4[9](ivec4(0, 0, 0, 2), ivec4(0, 1, 3, 0), ivec4(1, 0, 1, 2), ivec4(3, 1, 0, 3),
                               ivec4(2, 0, 2, 2), ivec4(1, 1, 3, 2), ivec4(3, 3, 1, 3), ivec4(4, 1, 2, 3),
                               ivec4(2, 1, 4, 0));

vec4 layout_texel(int t, ivec2 k) {  // texel k of texture t (t is constant after unrolling)
    if (t == 0) return texelFetch(G0, k, 0);
    if (t == 1) return texelFetch(G1, k, 0);
    if (t == 2) return texelFetch(G2, k, 0);
    if (t == 3) return texelFetch(G3, k, 0);
    return texelFetch(G4, k, 0);
}

float pop(int j, ivec2 p) {  // stored g_j at node p (inside the grid)
    ivec2 k = ivec2(p.x >> 1, p.y);
    vec4 ta = layout_texel(SLOT[j].x, k);
    vec4 tb = SLOT[j].z == SLOT[j].x ? ta : layout_texel(SLOT[j].z, k);  // one fetch where a, b share it
    return (p.x & 1) == 1 ? tb[SLOT[j].w] : ta[SLOT[j].y];
}

// the stored populations of both nodes of texel k (five fetches)
void load_pair(ivec2 k, out float a[9], out float b[9]) {
    vec4 t[5] = vec4[5](texelFetch(G0, k, 0), texelFetch(G1, k, 0), texelFetch(G2, k, 0),
                        texelFetch(G3, k, 0), texelFetch(G4, k, 0));
    for (int i = 0; i < Q; ++i) {
        a[i] = t[SLOT[i].x][SLOT[i].y];
        b[i] = t[SLOT[i].z][SLOT[i].w];
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
