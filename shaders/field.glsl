#version 330 core
// The field the viewport draws: (rho, ux, uy, vorticity) per node from the stored populations
// (moments of f*, as Solver.macroscopic, Guo's F/2 removed; vorticity duy/dx - dux/dy by central differences,
// one-sided at the domain edges; only with VORTICITY 1: it reads five nodes, not one). Runs
// only when the app asks for it.
// @LATTICE
// @INCLUDE paired_layout.glsl

uniform ivec2 N;
uniform vec2 body_force;  // Guo: the step's velocity is (sum c f* - F/2) / rho

out vec4 field;

vec3 moments(ivec2 p) {  // (rho, ux, uy) at node p
    float g[9];
    load_node(p, g);
    float rho = RHO0;
    vec2 j = vec2(0.0);
    for (int i = 0; i < Q; ++i) {
        rho += g[i];
        j += vec2(C[i]) * g[i];
    }
#if INCOMPRESSIBLE
    return vec3(rho, (j - 0.5 * body_force) / RHO0);  // He & Luo's velocity (algorithm.md, step 3)
#else
    return vec3(rho, (j - 0.5 * body_force) / rho);
#endif
}

void main() {
    ivec2 x = ivec2(gl_FragCoord.xy);
    vec3 m = moments(x);
#if VORTICITY
    ivec2 xe = ivec2(min(x.x + 1, N.x - 1), x.y);
    ivec2 xw = ivec2(max(x.x - 1, 0), x.y);
    ivec2 xn = ivec2(x.x, min(x.y + 1, N.y - 1));
    ivec2 xs = ivec2(x.x, max(x.y - 1, 0));
    float duy_dx = (moments(xe).z - moments(xw).z) / float(xe.x - xw.x);
    float dux_dy = (moments(xn).y - moments(xs).y) / float(xn.y - xs.y);
    field = vec4(m, duy_dx - dux_dy);
#else
    field = vec4(m, 0.0);   // VORTICITY 0: one node's moments, not five
#endif
}
