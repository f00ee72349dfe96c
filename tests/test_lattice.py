"""The D2Q9 lattice: isotropy moments and the equilibrium's moments (Krueger et al. 2017, 3.4)."""
import numpy as np

from feelflow.solver.lattice import C, CS2, OPP, Q, W, equilibrium


def test_weights_and_opposites():
    assert Q == 9
    assert np.isclose(W.sum(), 1.0)
    assert np.all(C[OPP] == -C)
    assert np.all(W[OPP] == W)


def test_isotropy_moments():
    c = C.astype(float)
    assert np.allclose((W[:, None] * c).sum(0), 0)
    second = np.einsum("i,ia,ib->ab", W, c, c)
    assert np.allclose(second, CS2 * np.eye(2))
    third = np.einsum("i,ia,ib,ic->abc", W, c, c, c)
    assert np.allclose(third, 0)
    fourth = np.einsum("i,ia,ib,ic,id->abcd", W, c, c, c, c)
    d = np.eye(2)
    iso = CS2**2 * (np.einsum("ab,cd->abcd", d, d) + np.einsum("ac,bd->abcd", d, d) + np.einsum("ad,bc->abcd", d, d))
    assert np.allclose(fourth, iso)


def test_equilibrium_moments():
    rng = np.random.default_rng(1)
    rho = 1 + 0.1 * rng.standard_normal(50)
    ux, uy = 0.05 * rng.standard_normal((2, 50))
    feq = equilibrium(rho, ux, uy)
    assert np.allclose(feq.sum(0), rho)
    assert np.allclose(np.tensordot(C[:, 0], feq, 1), rho * ux)
    assert np.allclose(np.tensordot(C[:, 1], feq, 1), rho * uy)
    pxx = np.tensordot(C[:, 0] ** 2, feq, 1)
    assert np.allclose(pxx, rho * CS2 + rho * ux * ux)


def test_incompressible_equilibrium_moments():
    """He & Luo (1997): sum f = rho, sum c f = RHO0 u, sum c c f = rho c_s^2 I + RHO0 u u, so the
    density fluctuation enters only the pressure."""
    from feelflow.solver.lattice import RHO0

    rho, ux, uy = 1.013, 0.04, -0.03
    f = equilibrium(np.array(rho), np.array(ux), np.array(uy), incompressible=True)
    c = C.astype(float)
    u = np.array([ux, uy])
    assert np.isclose(f.sum(), rho)
    assert np.allclose(c.T @ f, RHO0 * u)
    assert np.allclose(np.einsum("ia,ib,i->ab", c, c, f), rho * CS2 * np.eye(2) + RHO0 * np.outer(u, u))
