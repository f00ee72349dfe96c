"""The two-nodes-per-fragment layout probe (solver/gl_layout_probe.py) computes what the gl
backend computes: same populations after steps of a fully periodic flow, so the speed that
`feelflow bench --variants` reports for it compares layouts, not schemes."""
import numpy as np
import pytest

from solver.config import FlowConfig
from solver.gl_backend import GLSolver
from solver.gl_layout_probe import PairedLayoutProbe
from solver.lattice import equilibrium

pytestmark = pytest.mark.gl


def _shear_wave(nx, ny):
    """A decaying shear wave plus a density bump: every direction carries something different."""
    y, x = np.mgrid[0:ny, 0:nx]
    ux = 0.05 * np.sin(2 * np.pi * y / ny) + 0.01
    uy = 0.02 * np.cos(2 * np.pi * x / nx)
    rho = 1.0 + 1e-3 * np.exp(-((x - nx / 3) ** 2 + (y - ny / 2) ** 2) / 20.0)
    return equilibrium(rho, ux, uy)


@pytest.mark.parametrize("collision", ["trt", "bgk"])
def test_paired_layout_equals_the_backend(gl_context, collision):
    cfg = FlowConfig(nx=64, ny=32, nu=0.02, collision=collision, dtype="float32",
                     x_boundary="periodic", y_boundary="periodic")
    f0 = _shear_wave(cfg.nx, cfg.ny)
    ref = GLSolver(cfg, ctx=gl_context)
    probe = PairedLayoutProbe(cfg, gl_context)
    try:
        ref.set_distributions(f0)
        probe.set_distributions(f0)
        assert np.abs(probe.distributions() - f0).max() < 1e-6  # the layout round-trips
        ref.step(25)
        probe.step(25)
        probe.finish()
        a, b = ref.distributions(), probe.distributions()
        moved = np.abs(a - f0).max()
        assert moved > 1e-4  # the flow did change
        assert np.abs(a - b).max() < 1e-5 * moved
    finally:
        ref.close()
        probe.close()


def test_probe_refuses_what_it_does_not_model(gl_context):
    from solver.backend import BackendError

    with pytest.raises(BackendError, match="periodic"):
        PairedLayoutProbe(FlowConfig(nx=64, ny=32, x_boundary="tunnel"), gl_context)
