#version 330 core
// Recursive-regularised BGK with an optional Smagorinsky eddy viscosity, the collision of
// variant RR (included by lbm_step.glsl); the same operator and terms as the numpy reference
// solver/regularised.py (Latt & Chopard 2006; Malaspinas 2015; Coreixas et al. 2017;
// Smagorinsky after Hou et al. 1995; Guo, Zheng & Shi 2002 forcing):
//   feq: the third-order Hermite equilibrium, with 27/2 rho (H_xxy ux^2 uy + H_xyy ux uy^2);
//   n = f - feq projected on the Hermite polynomials up to order 2 plus the recursive order-3
//   terms a_xxy = 2 ux a_xy + uy a_xx, a_xyy = 2 uy a_xy + ux a_yy;
//   f* = feq + (1 - omega) n_reg + (1 - omega / 2) S.

uniform float smagorinsky;     // 18 sqrt(2) C^2 (solver/regularised.py, smagorinsky_factor); 0: none

void collide_rr(inout float f[9], float drho, float deq, float rho, float ux, float uy, float op) {
    float usq = 1.5 * (ux * ux + uy * uy);
    float feq[9];
    float a0 = 0.0;
    float a1x = 0.0;
    float a1y = 0.0;
    float pxx = 0.0;
    float pyy = 0.0;
    float pxy = 0.0;
    float eq_xxy = rho * ux * uy * ux;
    float eq_xyy = rho * ux * uy * uy;
    for (int i = 0; i < Q; ++i) {
        float cx = float(C[i].x);
        float cy = float(C[i].y);
        float cu = 3.0 * (cx * ux + cy * uy);
        float eq3 = 13.5 * ((cx * cx - 1.0 / 3.0) * cy * eq_xxy + (cy * cy - 1.0 / 3.0) * cx * eq_xyy);
        feq[i] = W[i] * (deq + rho * (cu + 0.5 * cu * cu - usq) + eq3);
        float n = f[i] - feq[i];
        a0 += n;
        a1x += cx * n;
        a1y += cy * n;
        pxx += cx * cx * n;
        pyy += cy * cy * n;
        pxy += cx * cy * n;
    }
    float axx = pxx - a0 / 3.0;
    float ayy = pyy - a0 / 3.0;
    float axxy = 2.0 * ux * pxy + uy * axx;
    float axyy = 2.0 * uy * pxy + ux * ayy;
    float omega = op;
    if (smagorinsky > 0.0) {
        float tau0 = 1.0 / op;
        float stress = sqrt(pxx * pxx + pyy * pyy + 2.0 * pxy * pxy);
        omega = 1.0 / (0.5 * (tau0 + sqrt(tau0 * tau0 + smagorinsky * stress / (drho + RHO0))));
    }
    float keep_neq = 1.0 - omega;
#if GUO_FORCE
    float uF = ux * body_force.x + uy * body_force.y;
    float src = 1.0 - 0.5 * omega;
#endif
    for (int i = 0; i < Q; ++i) {
        float cx = float(C[i].x);
        float cy = float(C[i].y);
        float hxx = cx * cx - 1.0 / 3.0;
        float hyy = cy * cy - 1.0 / 3.0;
        float hxy = cx * cy;
        float hxxy = cx * cx * cy - cy / 3.0;
        float hxyy = cx * cy * cy - cx / 3.0;
        float reg = a0 + 3.0 * (cx * a1x + cy * a1y)
                  + 4.5 * (hxx * axx + hyy * ayy + 2.0 * hxy * pxy) + 13.5 * (hxxy * axxy + hxyy * axyy);
        float out_i = feq[i] + keep_neq * (W[i] * reg);
#if GUO_FORCE
        float cF = cx * body_force.x + cy * body_force.y;
        out_i += src * (W[i] * (9.0 * (cx * ux + cy * uy) * cF - 3.0 * uF + 3.0 * cF));
#endif
        f[i] = out_i;
    }
}
