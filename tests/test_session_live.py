"""Recording that starts on a running flow (the GUI's Record button), and the GUI's own
simulation driving a SessionSolver: replay reproduces the forces."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from feelflow.app.sessions import SessionSolver, load_session, replay
from session_scenes import MODELS, small_config, start_body
from feelflow.solver.backend import create_solver


@pytest.mark.parametrize("dtype, quiet", [("float32", False), ("float64", False), ("float32", True)])
def test_recording_started_mid_flow_replays(tmp_path, dtype, quiet):
    """quiet: the quiet inlet's reference (solver/quiet_inlet.py) is part of the flow's state;
    the session keeps it with the populations, and a rebuild carries it."""
    cfg = small_config(dtype=dtype)
    if quiet:
        cfg = dataclasses.replace(cfg, inlet_nonreflecting=0.01, inflow_ramp_steps=0,
                                  initial_velocity=(cfg.inflow_speed, 0.0))
    ss = SessionSolver(create_solver("numpy", cfg), body=start_body())
    ss.enable_force_models(MODELS)
    x = 20.0
    for k in range(10):  # not recorded: the flow develops
        x += 0.04
        ss.set_body(start_body().moved(x=x), (0.04, 0.0))
        ss.step(3)
    rec = ss.start_recording(renderer="test")
    for k in range(12):
        x += 0.04
        ss.set_body(start_body().moved(x=x, y=16.3 - 0.01 * k), (0.04, -0.01))
        ss.step(2)
        if k == 5:  # the GUI's way to change viscosity: a new backend carrying the flow
            ss.rebuild(dataclasses.replace(cfg, nu=0.07), keep_flow=True)
            ss.enable_force_models(MODELS)
            ss.set_body(start_body().moved(x=x), (0.04, -0.01))
    path = tmp_path / "mid.ffsession"
    rec.save(path)
    s = load_session(path)
    assert s.start["time"] == 30 and s.state.shape == (9, 32, 64)
    assert (s.inlet_reference is not None and np.abs(s.inlet_reference).max() > 0) == quiet
    assert [p["name"] for p in s.parameters].count("rebuild") == 1
    result = replay(s)
    assert result.max_force > 1e-3
    if dtype == "float32":  # the state round-trips exactly through float64
        assert result.max_deviation == 0.0
    else:  # f* = g + w_i rho0 rounds in the last bit of g
        assert result.relative_deviation <= 1e-12


def test_gui_simulation_through_a_session_solver(tmp_path):
    """feelflow.app.model.simulation drives its solver by set_body/step/forces/set_inflow_speed; wrapped in a
    SessionSolver, a mouse drag recorded mid-run replays to the same forces."""
    from feelflow.app.model.body_input import BodyInput
    from feelflow.app.model.simulation import Params, Simulation

    sim = Simulation(Params(grid=(192, 96), size=16.0))
    sim.solver = SessionSolver(sim.solver, body=sim.shape)
    sim.solver.enable_force_models([sim.params.force_model])
    sim.solver.set_body(sim.shape, sim.vel, 0.0)
    for _ in range(5):
        sim.advance(4)
    rec = sim.solver.start_recording()
    x0, y0 = sim.pos
    for k in range(8):
        sim.drive(BodyInput.pull(x0 + 2.0 * k, y0 + 0.5 * k, "mouse"))  # the mouse drags the body
        sim.advance(4)
        if k == 4:
            sim.set_flow(wind=0.04)
    rec.save(tmp_path / "gui.ffsession")
    s = load_session(tmp_path / "gui.ffsession")
    assert len(s.inputs["step"]) >= 5 and "inflow_speed" in [p["name"] for p in s.parameters]
    assert np.ptp(s.inputs["pose"][:, 0]) > 0.5  # the body really moved
    result = replay(s)
    assert result.max_force > 0 and result.max_deviation == 0.0
