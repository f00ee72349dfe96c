"""The gl backend's own duties: field texture for the app, robustness to a host's GL state,
divergence detection, no context creation."""
from __future__ import annotations

import moderngl
import numpy as np
import pytest
from conftest import make_solver

from feelflow.shapes import Cylinder
from feelflow.solver.backend import BackendError, SolverDiverged, create_solver
from feelflow.solver.config import FlowConfig
from feelflow.solver.lattice import equilibrium

pytestmark = pytest.mark.gl


def _disturbed(nx, ny, seed=2):
    rng = np.random.default_rng(seed)
    return equilibrium(1 + 1e-3 * rng.standard_normal((ny, nx)), 0.03 * rng.standard_normal((ny, nx)),
                       0.03 * rng.standard_normal((ny, nx)))


def test_needs_a_context():
    with pytest.raises(BackendError, match="moderngl.Context"):
        create_solver("gl", FlowConfig(nx=16, ny=16))


@pytest.mark.parametrize("equilibrium", ["compressible", "incompressible"])  # u = j / rho or j / RHO0
def test_field_texture_holds_moments_and_vorticity(equilibrium, request):
    cfg = FlowConfig(nx=40, ny=24, x_boundary="periodic", y_boundary="periodic", body_force=(1e-5, 0.0),
                     equilibrium=equilibrium)
    s = make_solver("gl", cfg, request)
    s.set_distributions(_disturbed(40, 24))
    s.step(5)
    tex = s.field_texture()
    assert tex.size == (40, 24) and tex.components == 4 and tex.dtype == "f4"
    field = np.frombuffer(tex.read(), dtype="f4").reshape(24, 40, 4)
    rho, ux, uy = s.macroscopic()
    assert np.allclose(field[..., 0], rho, rtol=0, atol=1e-6)
    assert np.allclose(field[..., 1], ux, rtol=0, atol=1e-6)
    assert np.allclose(field[..., 2], uy, rtol=0, atol=1e-6)
    # vorticity: central differences inside, one-sided at the domain edges (np.gradient)
    vort = np.gradient(uy, axis=1, edge_order=1) - np.gradient(ux, axis=0, edge_order=1)
    assert np.allclose(field[..., 3], vort, rtol=0, atol=1e-5)
    # without the vorticity (the window's other display modes): the same moments, a zero fourth
    plain = np.frombuffer(s.field_texture(vorticity=False).read(), dtype="f4").reshape(24, 40, 4)
    assert np.array_equal(plain[..., :3], field[..., :3]) and not plain[..., 3].any()


def test_steps_ignore_the_host_gl_state(gl_context, request):
    """Qt enters paintGL with blending on and its own textures bound (notes, pitfalls 2-3):
    the solver's result must not depend on that."""
    cfg = FlowConfig(nx=48, ny=32, inflow_ramp_steps=10)
    a, b = make_solver("gl", cfg, request), make_solver("gl", cfg, request)
    for s in (a, b):
        s.set_body(Cylinder(8.0, x=16.0, y=16.0), velocity=(0.01, 0.0))
    a.step(10)
    ctx = gl_context
    junk = ctx.texture((4, 4), 4, dtype="f4", data=np.full(64, 7.0, "f4").tobytes())
    other = ctx.framebuffer(color_attachments=[ctx.texture((4, 4), 4)])
    for _ in range(10):
        ctx.enable(moderngl.BLEND | moderngl.CULL_FACE)
        ctx.blend_func = moderngl.ONE, moderngl.ONE
        for unit in range(8):
            junk.use(location=unit)
        other.use()
        ctx.viewport = (0, 0, 2, 2)
        b.step(1)
        b.field_texture()
    assert np.array_equal(a.distributions(), b.distributions())
    ctx.enable_only(moderngl.NOTHING)


def _diverged_step(s, index, value, steps) -> int:
    """Put `value` into population (i, y, x) = index, run `steps`: the step SolverDiverged names."""
    f = s.distributions()
    f[index] = value
    s.set_distributions(f)
    with pytest.raises(SolverDiverged) as err:
        s.step(steps)
    return err.value.step


def test_divergence_raises_with_the_step(gl_context):
    cfg = FlowConfig(nx=40, ny=32, x_boundary="periodic", y_boundary="periodic")
    s = create_solver("gl", cfg, ctx=gl_context)
    s.step(5)
    assert _diverged_step(s, (3, 10, 37), np.inf, 10) == 6


def test_body_upload_touches_only_the_window(request):
    """Moving the body rewrites the mask (and q) only around the old and new windows; removing
    the body clears them there."""
    from feelflow.solver.body import expand_box, union_box
    from feelflow.solver.gl_body import node_mask

    cfg = FlowConfig(nx=64, ny=32)
    s = make_solver("gl", cfg, request)
    s.set_body(Cylinder(6.0, x=20.0, y=16.0))
    old_window = s.body.raster.window
    sentinel = np.uint32(1 << 30)  # a bit the shader never reads
    s._mask_tex.write(np.full((32, 64), sentinel, dtype="u4").tobytes())
    s.set_body(Cylinder(6.0, x=23.5, y=15.0))
    mask = np.frombuffer(s._mask_tex.read(), dtype="u4").reshape(32, 64)
    x0, y0, x1, y1 = expand_box(union_box(old_window, s.body.raster.window), 2, 64, 32)
    inside = np.zeros((32, 64), bool)
    inside[y0:y1, x0:x1] = True
    assert np.all(mask[~inside] == sentinel)  # untouched outside the changed box
    assert np.array_equal(mask[y0:y1, x0:x1], node_mask(*s.body.raster.crop((x0, y0, x1, y1)), (x0, y0, x1, y1),
                                                          s.body.links, s.body.window))
    assert np.array_equal((mask[y0:y1, x0:x1] & 1).astype(bool), s.body.raster.solid[y0:y1, x0:x1])
    s.set_body(None)
    mask = np.frombuffer(s._mask_tex.read(), dtype="u4").reshape(32, 64)
    assert not mask[y0:y1, x0:x1].any()


#: a force model that is not a link sum: with it enabled, every model runs its own code on each
#: step's body window (copied to the band area or the check atlas), the reference for the sums
WINDOW_MODEL = "pressure"


def _single_steps(s, n, names):
    """n calls of step(1), each a block of one step read back at once: the mean force."""
    total = np.zeros((len(names), 2))
    for _ in range(n):
        s.step(1)
        total += [s.forces()[m] for m in names]
    return total / n


@pytest.mark.parametrize("x_boundary", ["tunnel", "periodic"])  # band area; check atlas (no band area)
def test_blocks_of_steps_give_the_forces_and_state_of_single_steps(gl_context, x_boundary):
    """step(n) reads back once per block of steps (force windows batched on the GPU, one check
    per block): 40 steps in blocks give the same state and the same mean force, impulses of the
    moves included, as single steps. A tunnel's step pass copies each window into a slot of its
    destination's band area (10 slots a side here, blocks of 20); an x-periodic channel has no
    band area, and a second pass per step copies the window into the check atlas (blocks of 32
    + 8). The models run on the windows here; the link sums on the GPU are the next tests."""
    cfg = FlowConfig(nx=64, ny=32, inflow_speed=0.04, inflow_ramp_steps=10, x_boundary=x_boundary,
                     body_force=(2e-6, 0.0) if x_boundary == "periodic" else (0.0, 0.0))
    names = ["momentum_exchange", WINDOW_MODEL]
    runs = []
    for blocks in (True, False):
        s = create_solver("gl", cfg, ctx=gl_context)
        s.enable_force_models(names)
        s.set_body(Cylinder(6.0, x=20.0, y=16.0))
        s.step(5)
        s.set_body(Cylinder(6.0, x=20.0, y=16.5), velocity=(0.0, 0.1))
        if blocks:
            s.step(40)
            forces = np.array([s.forces()[m] for m in names])
        else:
            forces = _single_steps(s, 40, names)
        assert (s._band.layout is not None) == (x_boundary == "tunnel")
        runs.append((forces, s.distributions()))
    (f_block, g_block), (f_single, g_single) = runs
    assert np.array_equal(g_block, g_single)
    assert np.allclose(f_block, f_single, rtol=1e-12, atol=0)
    assert abs(f_block[0, 0]) > 0  # the cylinder feels the flow


def test_link_sums_on_the_gpu_give_the_momentum_exchanges_of_the_window(gl_context):
    """With both exchanges as the only models, the link-sum pass sums the links
    (shaders/link_sums.glsl) into the band area instead of copying the window for the models'
    code (the reference: the same models with a window model enabled too). Both forms, on a body moved, turned and spun between
    blocks (Bouzidi links of both kinds, moving wall, cover/uncover impulses), agree with the
    models on the window to float32 round-off of the sums (1e-5 of the largest force; measured
    2.8e-7), their torques about the body's centre likewise (1e-5 of the largest torque), and
    the state is the same bit for bit."""
    from feelflow.shapes import FlatPlate

    cfg = FlowConfig(nx=96, ny=48, inflow_speed=0.05, inflow_ramp_steps=10)
    names = ["momentum_exchange", "momentum_exchange_classic"]
    runs = []
    for forces in ("gpu", "window"):
        s = create_solver("gl", cfg, ctx=gl_context)
        s.enable_force_models(names + ([WINDOW_MODEL] if forces == "window" else []))
        out = []
        for k in range(12):
            shape = (Cylinder(10.0, x=30.3 + 0.13 * k, y=24.2 - 0.07 * k) if k < 6 else
                     FlatPlate(length=12.0, thickness=2.5, x=31.1, y=23.9, angle=0.35 + 0.05 * k))
            s.set_body(shape, velocity=(0.02, -0.01), omega=0.01 * (k >= 6))
            s.step(7)
            out.append([(*s.forces()[n], s.torques()[n]) for n in names])
        assert s._block_sums == (forces == "gpu")
        runs.append((np.array(out), s.distributions()))
    (f_gpu, g_gpu), (f_win, g_win) = runs
    assert np.array_equal(g_gpu, g_win)
    t_gpu, t_win = f_gpu[..., 2], f_win[..., 2]
    f_gpu, f_win = f_gpu[..., :2], f_win[..., :2]
    scale = np.abs(f_win).max()
    assert scale > 0.01
    print(f"\n  link sums against the window: {np.abs(f_gpu - f_win).max() / scale:.1e} of the largest force", end="")
    assert np.abs(f_gpu - f_win).max() <= 1e-5 * scale
    assert not np.allclose(f_win[:, 0], f_win[:, 1])  # the two forms differ on a moving body
    t_scale = np.abs(t_win).max()
    assert t_scale > 0.01
    print(f", torque {np.abs(t_gpu - t_win).max() / t_scale:.1e} of the largest", end="")
    assert np.abs(t_gpu - t_win).max() <= 1e-5 * t_scale


@pytest.mark.parametrize("model", ["momentum_exchange", "momentum_exchange_classic"])
def test_the_step_pass_sums_the_links_of_a_single_momentum_exchange(gl_context, model):
    """With one momentum exchange as the only model and no torque wanted (`sum_torque` False), the
    step's own pass sums its links while it streams them (lbm_step.glsl LINK_SUMS) and keeps the
    running total of a block's steps in texture G4's spare channels; no link-sum pass, no band
    area. On a body moved, turned and spun between calls of 7 and 40 steps (blocks of 32 + 8),
    the forces agree with the model's code on the copied window to float32 round-off (1e-5 of
    the largest force; measured 2.0e-7), the state is the same bit for bit, and enabling both
    exchanges switches to the link-sum pass."""
    from feelflow.shapes import FlatPlate

    cfg = FlowConfig(nx=96, ny=48, inflow_speed=0.05, inflow_ramp_steps=10)
    runs = []
    for forces in ("gpu", "window"):
        s = create_solver("gl", cfg, ctx=gl_context)
        s.sum_torque = False  # the force alone: the step's own pass
        s.enable_force_models([model] + ([WINDOW_MODEL] if forces == "window" else []))
        out = []
        for k in range(8):
            shape = (Cylinder(10.0, x=30.3 + 0.13 * k, y=24.2 - 0.07 * k) if k < 4 else
                     FlatPlate(length=12.0, thickness=2.5, x=31.1, y=23.9, angle=0.35 + 0.05 * k))
            s.set_body(shape, velocity=(0.02, -0.01), omega=0.01 * (k >= 4))
            s.step(40 if k % 3 == 2 else 7)
            out.append(s.forces()[model])
        assert s._link_sums == ({"momentum_exchange": 1, "momentum_exchange_classic": 2}[model]
                                if forces == "gpu" else 0)
        assert not s._block_sums and s._band_sums is None  # no link-sum pass was built
        runs.append((np.array(out), s.distributions(), s))
    (f_gpu, g_gpu, s_gpu), (f_win, g_win, _) = runs
    assert np.array_equal(g_gpu, g_win)
    scale = np.abs(f_win).max()
    assert scale > 0.01
    print(f"\n  link sums against the window: {np.abs(f_gpu - f_win).max() / scale:.1e} of the largest force", end="")
    assert np.abs(f_gpu - f_win).max() <= 1e-5 * scale
    s_gpu.enable_force_models(["momentum_exchange", "momentum_exchange_classic"])
    s_gpu.step(3)
    assert s_gpu._link_sums == 0 and s_gpu._block_sums


@pytest.mark.parametrize("forces", ["pass", "sum pass", "window"])
def test_a_non_finite_body_window_raises_with_its_step_on_every_force_path(gl_context, forces):
    """A NaN next to the body is reported from the step whose window holds it, the same step
    and message whether the step's pass summed the links (one momentum exchange: found by
    replaying the block), the link-sum pass did (both exchanges) or the window was copied."""
    names = {"pass": ["momentum_exchange"], "sum pass": ["momentum_exchange", "momentum_exchange_classic"],
             "window": ["momentum_exchange", WINDOW_MODEL]}[forces]
    cfg = FlowConfig(nx=64, ny=32, inflow_speed=0.04)
    s = create_solver("gl", cfg, ctx=gl_context)
    s.sum_torque = forces != "pass"
    s.enable_force_models(names)
    s.set_body(Cylinder(8.0, x=20.0, y=16.0))
    s.step(5)
    f = s.distributions()
    f[:, 16, 25] = np.nan  # the fluid node right of the cylinder (x = 24 is its edge)
    s.set_distributions(f)
    with pytest.raises(SolverDiverged) as err:
        s.step(10)
    assert err.value.step == 5 and "around the body" in str(err.value)
    assert s._block_sums == (forces == "sum pass")
    assert s._link_sums == (1 if forces == "pass" else 0)


def test_window_wider_than_the_band_area_falls_back_to_the_atlas(gl_context):
    """A body window wider than the band area (BAND_WIDTH) takes the atlas path: blocks give
    the numbers of single steps."""
    from feelflow.shapes import FlatPlate
    from feelflow.solver.gl_backend import BAND_WIDTH

    cfg = FlowConfig(nx=BAND_WIDTH + 64, ny=32, inflow_speed=0.04, inflow_ramp_steps=10)
    plate = FlatPlate(length=BAND_WIDTH + 10.0, thickness=2.0, x=cfg.nx / 2, y=16.0, angle=np.pi / 2)
    names = ["momentum_exchange", WINDOW_MODEL]
    runs = []
    for blocks in (True, False):
        s = create_solver("gl", cfg, ctx=gl_context)
        s.enable_force_models(names)
        s.set_body(plate)
        assert s.body.window[2] - s.body.window[0] > BAND_WIDTH
        if blocks:
            s.step(12)
            forces = np.array([s.forces()[m] for m in names])
        else:
            forces = _single_steps(s, 12, names)
        assert s._band.layout is None  # no slot fits: the check atlas took the windows
        runs.append((forces, s.distributions()))
    (f_block, g_block), (f_single, g_single) = runs
    assert np.array_equal(g_block, g_single)
    assert np.allclose(f_block, f_single, rtol=1e-12, atol=0)
