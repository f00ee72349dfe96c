#version 330 core
// The momentum exchange's link sums of one step on the GPU (docs/science/algorithm.md 'Forces'; Wen,
// Zhang, Tu, Wang & Fang 2014; Ladd 1994), drawn right after the step into the same framebuffer,
// in a slot of the band area (solver/gl_band.py): one RGBA32F texel per state texel with a cut
// link, so that a block reads back those few texels instead of the window's five attachments. The state texels with links are listed in
// LINK_TEXELS, packed row by row; one rectangle covers the list (llvmpipe pays per primitive:
// a point per texel cost the step about 10 %, the rectangle next to nothing).
//
// Each fragment takes the two nodes x of one listed state texel and sums, over
// their cut links (x, ib) (bits of MASK, as lbm_step.glsl rule a), from the stored
// post-collision populations g* = f* - w RHO0 of the step's source state:
//   S1 = sum -c_i (g*_ib(x) + g_i^in(x)),   S2 = sum -u_w (g*_ib(x) - g_i^in(x)),
// with g_i^in(x) from the rule lbm_step.glsl streams with (body_links.glsl, rule 1a).
// The backend sums the texels in float64 and adds the links' constant K = -2 RHO0 sum w_i c_i
// and the cover/uncover impulse J: Galilean-invariant F = S1 + S2 + K + J, classic F = S1 + K,
// the numbers solver/forces/momentum_exchange.py computes from the window (f = g + w RHO0).
// The same terms' moments about the body's centre, r = x + q c_ib - X (the link's wall
// crossing), go to the second target: M1 = sum r x S1-term, M2 = sum r x S2-term; the backend
// adds K's moment: Galilean-invariant torque M1 + M2 + M_K, classic M1 + M_K.
// @LATTICE
// @INCLUDE paired_layout.glsl
// @INCLUDE body_links.glsl

uniform usampler2D MASK;       // lbm_step.glsl: bit 0 solid; bit i link cut; bit 8+i two-node rule
uniform sampler2D QA;          // q[1..4, x]
uniform sampler2D QB;          // q[5..8, x]
uniform ivec2 N;               // (nx, ny) in nodes
uniform ivec4 window;          // the force window (x0, y0, x1, y1) in nodes
uniform sampler2D LINK_TEXELS;  // (k, y, 1, 0): the state texels with links; (0, 0, 0, 0) past the list
uniform ivec2 slot_origin;     // the slot's lower-left texel in the target

layout(location = 0) out vec4 sums;     // (S1.x, S1.y, S2.x, S2.y) of this texel's two nodes
layout(location = 1) out vec4 moments;  // (M1, M2, 0, 0) of the same links about body_centre

ivec2 wrap(ivec2 p) {
    return ivec2((p.x + N.x) % N.x, (p.y + N.y) % N.y);
}

float cross2(vec2 a, vec2 b) {
    return a.x * b.y - a.y * b.x;
}

void add_node(ivec2 x, inout vec2 s1, inout vec2 s2, inout vec2 mom) {
    if (x.x < window.x || x.x >= window.z) return;
    uint m = texelFetch(MASK, x, 0).r;
    if ((m & 1u) != 0u || (m & 0x1FEu) == 0u) return;  // solid, or no cut link
    float own[9];
    load_node(x, own);
    vec4 qa = texelFetch(QA, x, 0);
    vec4 qb = texelFetch(QB, x, 0);
    float qs[9] = float[9](0.0, qa.x, qa.y, qa.z, qa.w, qb.x, qb.y, qb.z, qb.w);
    for (int i = 1; i < Q; ++i) {
        if ((m & (1u << uint(i))) == 0u) continue;
        int ib = OPP[i];
        ivec2 ci = C[i];
        float q = qs[ib];
        vec2 xw = vec2(x) + q * vec2(C[ib]);  // the wall crossing
        vec2 uw = wall_velocity(xw);
        bool two_node = (m & (1u << uint(8 + i))) != 0u;
        float second = two_node ? pop(ib, wrap(x + ci)) : 0.0;
        float gin = bouzidi_incoming(i, q, two_node, own[ib], own[i], second, uw);
        float gout = own[ib];
        vec2 t1 = -vec2(ci) * (gout + gin);
        vec2 t2 = -uw * (gout - gin);
        s1 += t1;
        s2 += t2;
        vec2 r = xw - body_centre;
        mom += vec2(cross2(r, t1), cross2(r, t2));
    }
}

void main() {
    vec4 entry = texelFetch(LINK_TEXELS, ivec2(gl_FragCoord.xy) - slot_origin, 0);
    ivec2 k = ivec2(entry.xy);
    vec2 s1 = vec2(0.0);
    vec2 s2 = vec2(0.0);
    vec2 m = vec2(0.0);
    if (entry.z > 0.5 && k.y >= window.y && k.y < window.w) {
        add_node(ivec2(2 * k.x, k.y), s1, s2, m);
        add_node(ivec2(2 * k.x + 1, k.y), s1, s2, m);
    }
    sums = vec4(s1, s2);
    moments = vec4(m, 0.0, 0.0);
}
