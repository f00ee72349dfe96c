#version 330 core
// Included (// @INCLUDE body_links.glsl, after // @LATTICE) by the programs that apply rule 1a
// of docs/science/algorithm.md to the body's links: lbm_step.glsl (its BODY variant streams with it)
// and link_sums.glsl (the momentum exchange sums what it gives), so both use one rule.
// References: Bouzidi, Firdaouss & Lallemand (2001), linear scheme; the moving-wall term of
// Lallemand & Luo (2003); solver/bouzidi.py is the numpy reference's form of the same rule.

uniform vec2 body_velocity;    // V
uniform float body_omega;      // Omega, radians per step, counter-clockwise
uniform vec2 body_centre;      // X

vec2 wall_velocity(vec2 xw) {  // rigid-body velocity at xw (algorithm.md, 'Links cut')
    vec2 r = xw - body_centre;
    return body_velocity + body_omega * vec2(-r.y, r.x);
}

// rule 1a: the shifted g_i^in(x) of a cut link (x, OPP[i]) with cut fraction q, from the stored
// g*_ib(x), g*_i(x) and g*_ib(x + c_i) (used only by the two-node rule, q < 1/2 and x + c_i
// fluid), and the wall velocity uw at the crossing x + q c_ib
float bouzidi_incoming(int i, float q, bool two_node, float own_ib, float own_i, float second_ib, vec2 uw) {
    float cu = dot(vec2(C[i]), uw);
    if (q >= 0.5)
        return 1.0 / (2.0 * q) * own_ib + (2.0 * q - 1.0) / (2.0 * q) * own_i + 3.0 / q * W[i] * RHO0 * cu;
    if (two_node)
        return 2.0 * q * own_ib + (1.0 - 2.0 * q) * second_ib + 6.0 * W[i] * RHO0 * cu;
    return own_ib + 6.0 * W[i] * RHO0 * cu;
}
