#version 330 core
// One lattice Boltzmann step t -> t+1, collide and stream fused (pull form), the same rules in
// the same order as the numpy reference (solver/numpy_backend.py). Populations are stored shifted, g_i = f*_i - w_i RHO0, two nodes
// per texel in five RGBA32F textures (shaders/paired_layout.glsl, solver/gl_layout.py); each
// fragment updates the two nodes a = (2k, y) and b = (2k + 1, y) of its texel k.
// References: Bouzidi, Firdaouss & Lallemand (2001); Lallemand & Luo (2003); Ginzburg (2008);
// Guo, Zheng & Shi (2002).
//
// Compile-time variants (defines injected by solver/gl_programs.py). llvmpipe executes both
// sides of a divergent branch, so each region of the grid is drawn by the variant it needs
// (solver/gl_regions.py):
//   BODY  1: rule 1a (Bouzidi links with the moving-wall term) and solid nodes (body window);
//   EDGES 1: rules 1b-1e (walls, inlet, pressure outlet, periodic wrap) (edge strips); streams
//     like the fast path where the REPEAT samplers wrap right (a tunnel: what crosses the inlet
//     or outlet is replaced by rules c, d; or an even nx), else node by node with an explicit
//     wrap (x-periodic with an odd nx);
//   both 0: the fast path, plain streaming (rule 1f) for the interior: both nodes streamed by
//     stream_pair, one fetch for each of the nine texels around the fragment's (9 for two
//     nodes; 18 node by node), through textureOffset() at normalized coordinates and REPEAT
//     samplers (a fully periodic grid of even width wraps for free).
//   BODY with LINK_SUMS 1 / 2 (the body's only force model is the Galilean-invariant / the
//     classic momentum exchange): while streaming the body's links, the variant also sums the
//     model's link terms (as shaders/link_sums.glsl: S1 + S2, or S1) and adds them to the running
//     total of the block's steps in the spare channels zw of texture G4 (sums_keep 0 on a
//     block's first step restarts it); the backend reads them once per block.
//   TRT, GUO_FORCE, SPONGE: collision operator, Guo body force, outlet sponge (per-column rates);
//   RR 1: recursive-regularised BGK with the Smagorinsky option instead (shaders/collide_rr.glsl).
//   X_PERIODIC 0/1; Y_MODE 0 no_slip, 1 free_slip, 2 periodic; NX_ODD: nx is odd.
//   QUIET_INLET: rule c's wall velocity passes outgoing sound (solver/quiet_inlet.py); its
//     reference density lives in G4.z of texel column 0.
// @LATTICE
// @INCLUDE paired_layout.glsl

uniform ivec2 N;               // (nx, ny) in nodes
uniform vec2 inv_n;            // 1 / (texture width, height) in texels
uniform float omega_plus;      // 1 / tau
uniform float omega_minus;     // TRT odd rate from the magic number
uniform vec2 body_force;       // Guo force density F
#if SPONGE
uniform sampler2D OMEGA;       // (omega+, omega-, keep) of column ix in texel (ix, 0): the outlet sponge
                               // and its absorbing layer (numpy: relaxation_rates, absorb_keep)
#endif
#if BODY
uniform usampler2D MASK;       // per node: bit 0 solid; bit i (1..8) q[OPP[i], x] > 0; bit 8+i:
                               // that link takes the two-node interpolation (q < 1/2, x + c_i fluid)
uniform sampler2D QA;          // q[1..4, x]
uniform sampler2D QB;          // q[5..8, x]
// @INCLUDE body_links.glsl
#endif
#if EDGES || SPONGE
uniform sampler2D INFLOW;      // texel (iy, 0): r profile(iy), gba rule c's links 1, 5, 8 (inflow.py)
uniform float inflow_ramp;     // ramp(t): u_in(iy, t) = ramp(t) profile(iy)
#if QUIET_INLET
uniform vec2 quiet_inlet;      // (rate k, c_s / RHO0) of the quiet inlet (solver/quiet_inlet.py)
float quiet_ref = 0.0;         // the inlet node's new drho_ref, stored in G4.z of texel column 0
#endif
#endif

#if BODY && LINK_SUMS
uniform float sums_keep;       // 0: this step starts the block's running total of link sums; 1: adds to it
vec4 link_sums = vec4(0.0);    // this texel's (S1.x, S1.y, S2.x, S2.y) of the step (link_sums.glsl)
#endif

layout(location = 0) out vec4 out0;
layout(location = 1) out vec4 out1;
layout(location = 2) out vec4 out2;
layout(location = 3) out vec4 out3;
layout(location = 4) out vec4 out4;

ivec2 wrap(ivec2 p) {  // node p, periodic wrap
    return ivec2((p.x + N.x) % N.x, (p.y + N.y) % N.y);
}

// both nodes of this fragment's texel, plain streaming g_i(x - c_i) (rule 1f), each of the nine
// texels around it fetched once (solver/gl_layout.py): G0, G1, G2 at this texel column of rows
// y, y - 1, y + 1; G3, G4 at the columns k - 1 (what node b there sends east to node a here) and
// k + 1 (what node a there sends west to node b here)
void stream_pair(out float a[9], out float b[9]) {
    vec2 p = gl_FragCoord.xy * inv_n;
    vec4 h = texture(G0, p);                          // row y: g0, g1 a -> b, g3 b -> a
    a[0] = h.x; b[1] = h.y; b[0] = h.z; a[3] = h.w;
    vec4 n = textureOffset(G1, p, ivec2(0, -1));      // row y - 1: g2, g5 a -> b, g6 b -> a
    a[2] = n.x; b[5] = n.y; b[2] = n.z; a[6] = n.w;
    vec4 s = textureOffset(G2, p, ivec2(0, 1));       // row y + 1: g4, g8 a -> b, g7 b -> a
    a[4] = s.x; b[8] = s.y; b[4] = s.z; a[7] = s.w;
    a[1] = textureOffset(G3, p, ivec2(-1, 0)).x;      // g1 (+1, 0) of node b of texel k - 1
    b[3] = textureOffset(G3, p, ivec2(1, 0)).y;       // g3 (-1, 0) of node a of texel k + 1
    a[5] = textureOffset(G3, p, ivec2(-1, -1)).z;     // g5 (+1, +1)
    b[6] = textureOffset(G3, p, ivec2(1, -1)).w;      // g6 (-1, +1)
    a[8] = textureOffset(G4, p, ivec2(-1, 1)).x;      // g8 (+1, -1)
    b[7] = textureOffset(G4, p, ivec2(1, 1)).y;       // g7 (-1, -1)
}

#if EDGES && X_PERIODIC && NX_ODD
// node x, plain streaming with the periodic wrap (rules 1e, 1f); what the wrap brings in across
// a non-periodic edge is replaced by rules b-d
void stream_node(ivec2 x, out float g[9]) {
    for (int i = 0; i < Q; ++i) g[i] = pop(i, wrap(x - C[i]));
}
#endif

// f^eq_i - w_i RHO0 for density RHO0 + drho and velocity u (Qian, d'Humieres & Lallemand 1992), shifted.
float feq_shifted(int i, float drho, float rho, vec2 u) {
    float cu = 3.0 * dot(vec2(C[i]), u);
    float usq = 1.5 * dot(u, u);
    return W[i] * (drho + rho * (cu + 0.5 * cu * cu - usq));
}

#if RR
// @INCLUDE collide_rr.glsl
#endif

void store_pair(float a[9], float b[9]) {
    out0 = vec4(a[0], a[1], b[0], b[3]);
    out1 = vec4(a[2], a[5], b[2], b[6]);
    out2 = vec4(a[4], a[8], b[4], b[7]);
    out3 = vec4(b[1], a[3], b[5], a[6]);
    out4 = vec4(b[8], a[7], 0.0, 0.0);
}

// Collision (algorithm.md steps 2-4) of the incoming shifted populations f at node x, in place,
// pair by pair (i, OPP[i]), with the operations in the order of the numpy reference
// (solver/numpy_backend.py, _collide) so that float32 rounding agrees:
//   feq+ - w RHO0 = w (drho + rho (cu^2/2 - usq)), feq- = w rho cu, cu = 3 c.u, usq = 3/2 u.u.
void collide(inout float f[9], ivec2 x) {
    float drho = f[0];
    for (int i = 1; i < Q; ++i) drho += f[i];
#if INCOMPRESSIBLE
    float rho = RHO0;  // He & Luo (1997): the velocity terms and u = j / rho take RHO0
#else
    float rho = drho + RHO0;
#endif
    float jx = 0.0;
    float jy = 0.0;
    for (int i = 1; i < Q; ++i) {
        jx += float(C[i].x) * f[i];
        jy += float(C[i].y) * f[i];
    }
#if GUO_FORCE
    jx += 0.5 * body_force.x;
    jy += 0.5 * body_force.y;
#endif
    float ux = jx / rho;
    float uy = jy / rho;
#if SPONGE
    vec3 rates = texelFetch(OMEGA, ivec2(x.x, 0), 0).rgb;
    float op = rates.r;
    float om = rates.g;
    // absorbing layer: equilibria of (RHO0 + keep drho, keep u + (1 - keep) u_in(iy, t))
    float deq = drho * rates.b;
    ux *= rates.b;
    ux += (inflow_ramp * texelFetch(INFLOW, ivec2(x.y, 0), 0).r) * (1.0 - rates.b);
    uy *= rates.b;
#else
    float op = omega_plus;
    float om = omega_minus;
    float deq = drho;
#endif
#if RR
    collide_rr(f, drho, deq, rho, ux, uy, op);
    return;
#endif
    float usq = ux * ux;
    usq += uy * uy;
    usq *= 1.5;
    f[0] += ((deq - rho * usq) * W[0] - f[0]) * op;
#if GUO_FORCE
    float uF = ux * body_force.x + uy * body_force.y;
    f[0] += (1.0 - 0.5 * op) * (W[0] * -3.0) * uF;
#endif
    for (int i = 1; i < Q; ++i) {
        int ib = OPP[i];
        if (ib < i) continue;  // each pair once
        float cx = float(C[i].x);
        float cy = float(C[i].y);
        float cu = 3.0 * (cx * ux + cy * uy);
        float sym = ((cu * cu * 0.5 - usq) * rho) + deq;
        float anti = cu * rho;
        float fi = f[i];
        float fb = f[ib];
#if TRT
        float dp = ((fi + fb) * 0.5 - sym * W[i]) * op;
        float dm = ((fi - fb) * 0.5 - anti * W[i]) * om;
        fi = fi - dp - dm;
        fb = fb - dp + dm;
#else
        fi += ((sym + anti) * W[i] - fi) * op;
        fb += ((sym - anti) * W[i] - fb) * op;
#endif
#if GUO_FORCE
        float cF = cx * body_force.x + cy * body_force.y;
        float cul = cx * ux + cy * uy;
        float gp = (1.0 - 0.5 * op) * (W[i] * (9.0 * cul * cF - 3.0 * uF));
        float gm = (1.0 - 0.5 * om) * (3.0 * W[i] * cF);
        fi += gp;
        fi += gm;
        fb += gp;
        fb -= gm;
#endif
        f[i] = fi;
        f[ib] = fb;
    }
}

#if EDGES
vec2 stored_velocity(float g[9]) {  // sum c f* / sum f* of shifted populations
    float rho = RHO0;
    vec2 j = vec2(0.0);
    for (int i = 0; i < Q; ++i) {
        rho += g[i];
        j += vec2(C[i]) * g[i];
    }
    return j / rho;
}

int reflect_y(int i) {  // j with C[j] = (C[i].x, -C[i].y)
    int r = 0;
    for (int j = 0; j < Q; ++j)
        if (C[j] == ivec2(C[i].x, -C[i].y)) r = j;
    return r;
}
#endif

#if BODY || EDGES
// Rules a-f and the collision at node x (variants BODY, EDGES): gin holds g_i(x - c_i) as
// streamed and becomes the post-collision populations; own = g*(x); west = g*(x - 1, y), for
// the pressure outlet.
void node_update(ivec2 x, inout float gin[9], float own[9], float west[9]) {
#if BODY
    uint m = texelFetch(MASK, x, 0).r;
    if ((m & 1u) != 0u) {  // solid node: equilibrium at the body velocity, density RHO0
        vec2 ub = wall_velocity(vec2(x));
        for (int i = 0; i < Q; ++i) gin[i] = feq_shifted(i, 0.0, RHO0, ub);
        return;
    }
    vec4 qa = texelFetch(QA, x, 0);
    vec4 qb = texelFetch(QB, x, 0);
    float qs[9] = float[9](0.0, qa.x, qa.y, qa.z, qa.w, qb.x, qb.y, qb.z, qb.w);
    float plain[9] = gin;  // plain[ib] = g_ib(x + c_i): the second node of the interpolation
#endif
#if EDGES
    // rule c's wall velocity per inlet link, at the link's midpoint (inlet_wall_profile)
    vec3 uin = X_PERIODIC == 0 ? inflow_ramp * texelFetch(INFLOW, ivec2(x.y, 0), 0).gba : vec3(0.0);
#if QUIET_INLET
    if (x.x == 0) {  // the quiet inlet: u_w += -c_s (drho - drho_ref) / RHO0 (solver/quiet_inlet.py)
        float drho_in = 0.0;
        for (int i = 0; i < Q; ++i) drho_in += own[i];
        float ref = texelFetch(G4, ivec2(0, x.y), 0).z;
        quiet_ref = ref + quiet_inlet.x * (drho_in - ref);
        uin += vec3(-quiet_inlet.y * (drho_in - quiet_ref));
    }
#endif
    // outlet velocity u_b = u(x) + (u(x) - u(x - 1)) / 2 of the stored populations
    // (solver/inflow.py, outlet_incoming; Krueger et al. 2017, eq. 5.53)
    vec2 u_out = vec2(0.0);
    float usq_out = 0.0;
    if (X_PERIODIC == 0) {
        u_out = 1.5 * stored_velocity(own) - 0.5 * stored_velocity(west);
        usq_out = dot(u_out, u_out);
    }
#endif
    for (int i = 1; i < Q; ++i) {
        int ib = OPP[i];
        ivec2 ci = C[i];
#if BODY
        if ((m & (1u << uint(i))) != 0u) {  // rule a: Bouzidi with the moving-wall term
            float q = qs[ib];
            vec2 uw = wall_velocity(vec2(x) + q * vec2(C[ib]));
            gin[i] = bouzidi_incoming(i, q, (m & (1u << uint(8 + i))) != 0u, own[ib], own[i], plain[ib], uw);
#if LINK_SUMS  // the momentum exchange's terms of this link (link_sums.glsl, add_node)
            link_sums.xy -= vec2(ci) * (own[ib] + gin[i]);
            link_sums.zw -= uw * (own[ib] - gin[i]);
#endif
            continue;
        }
#endif
#if EDGES
        // conditions test the constant C[i] first, so the unrolled loop drops the rules a
        // direction cannot meet (llvmpipe runs both sides of a branch that is not constant)
        ivec2 s = x - ci;
        bool wall = Y_MODE != 2 && ((ci.y > 0 && s.y < 0) || (ci.y < 0 && s.y >= N.y));
        ivec2 s2 = ivec2(x.x - ci.x, x.y);
        // a free-slip tunnel corner keeps the inlet/outlet rule
        bool corner = Y_MODE == 1 && X_PERIODIC == 0 && ((ci.x > 0 && s2.x < 0) || (ci.x < 0 && s2.x >= N.x));
        if (wall && !corner) {  // rule b: channel wall
            if (Y_MODE == 0) gin[i] = own[ib];                      // half-way bounce-back
            else gin[i] = pop(reflect_y(i), wrap(s2));              // specular reflection
        } else if (X_PERIODIC == 0 && ci.x > 0 && s.x < 0) {  // rule c: inlet
            float uw = ci.y == 0 ? uin.x : (ci.y > 0 ? uin.y : uin.z);  // links 1, 5, 8
            gin[i] = own[ib] + 6.0 * W[i] * RHO0 * uw;
        } else if (X_PERIODIC == 0 && ci.x < 0 && s.x >= N.x) {  // rule d: pressure outlet
            float cu = dot(vec2(ci), u_out);
            gin[i] = -own[ib] + 2.0 * W[i] * RHO0 * (4.5 * cu * cu - 1.5 * usq_out);
        }  // else rules e, f: gin[i] as streamed (wrapped)
#endif
    }
    collide(gin, x);
}
#endif

void main() {
    ivec2 k = ivec2(gl_FragCoord.xy);  // texel
    ivec2 xa = ivec2(2 * k.x, k.y);
    ivec2 xb = xa + ivec2(1, 0);
    float a[9];
    float b[9];
#if EDGES && X_PERIODIC && NX_ODD
    stream_node(xa, a);
    stream_node(xb, b);
#else
    stream_pair(a, b);
#endif
#if BODY || EDGES
    float own_a[9];
    float own_b[9];
    load_pair(k, own_a, own_b);
    float west_a[9];
#if EDGES && !X_PERIODIC && NX_ODD
    load_node(wrap(xa - ivec2(1, 0)), west_a);  // the outlet node nx - 1 is an a node
#else
    west_a = own_a;  // not used: without EDGES, x-periodic, or the outlet node is a b node
#endif
    node_update(xa, a, own_a, west_a);
    node_update(xb, b, own_b, own_a);
#if EDGES
    if (xb.x >= N.x)  // the column past the last node of an odd nx: kept at rest
        for (int i = 0; i < Q; ++i) b[i] = 0.0;
#endif
#else
    collide(a, xa);
    collide(b, xb);
#endif
    store_pair(a, b);
#if BODY && LINK_SUMS
    // G4's zw (unused by the layout) carry the running total: Galilean-invariant S1 + S2, classic S1
    vec2 step_sums = LINK_SUMS == 1 ? link_sums.xy + link_sums.zw : link_sums.xy;
    out4.zw = sums_keep * texelFetch(G4, k, 0).zw + step_sums;
#endif
#if EDGES && QUIET_INLET
    if (k.x == 0) out4.z = quiet_ref;
#endif
}
