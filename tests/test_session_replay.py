"""Sessions replay deterministically: re-simulating a recorded numpy session reproduces its
force series bit for bit, and a changed recording does not (the check can fail)."""
from __future__ import annotations

import csv
import math

import numpy as np
import pytest

from feelflow.app.sessions import (SessionRecorder, SessionSolver, export_csv, force_columns, load_session,
                         record_headless, replay)
from session_scenes import MODELS, drive_moving_cylinder, small_config, start_body
from feelflow.solver.backend import create_solver
from solver_backends import BACKENDS
from conftest import make_solver


def record(tmp_path, extras=True, steps=40):
    cfg = small_config()
    rec = SessionRecorder(cfg, start_body(), MODELS, scene_toml="# test scene\n")
    ss = SessionSolver(create_solver("numpy", cfg), rec)
    drive_moving_cylinder(ss, steps=steps, extras=extras)
    path = tmp_path / "run.ffsession"
    rec.save(path)
    return path, rec


def test_numpy_replay_reproduces_recorded_forces_bit_for_bit(tmp_path):
    path, rec = record(tmp_path)
    s = load_session(path)
    assert s.steps == rec.step > 40
    assert s.models == ("momentum_exchange", "pressure")
    names = [p["name"] for p in s.parameters]
    for name in ("inflow_speed", "nu", "pause", "resume", "reset", "body", "force_models"):
        assert name in names
    result = replay(s)
    assert result.max_force > 1e-3  # the body feels a real force
    assert result.max_deviation == 0.0
    np.testing.assert_array_equal(result.values, s.forces["values"])
    np.testing.assert_array_equal(result.session.forces["body"], s.forces["body"])


def test_replay_detects_a_changed_input(tmp_path):
    path, _ = record(tmp_path, extras=False, steps=20)
    s = load_session(path)
    s.inputs["velocity"][5, 0] += 0.01  # the body was pushed a little faster at one sample
    result = replay(s)
    assert result.relative_deviation > 1e-6
    # forces before that sample are unaffected: the replay follows the recorded order
    first = int(s.inputs["step"][5])
    before = s.forces["step"] <= first
    np.testing.assert_array_equal(result.values[before], s.forces["values"][before])


def test_viscosity_change_to_the_same_value_leaves_the_flow_alone():
    """set_viscosity rebuilds the backend; with the same nu the forces must continue as if
    nothing happened (no impulse booked, populations carried to rounding)."""
    cfg = small_config()
    series = []
    for change in (False, True):
        ss = SessionSolver(create_solver("numpy", cfg), body=start_body())
        ss.enable_force_models(MODELS)
        out = []
        for k in range(12):
            ss.set_body(start_body().moved(x=20.0 + 0.03 * k), (0.03, 0.0))
            if change and k == 6:
                ss.set_viscosity(cfg.nu)
            ss.step(2)
            out.append(ss.forces()["momentum_exchange"])
        series.append(np.array(out))
    scale = np.abs(series[0]).max()
    np.testing.assert_allclose(series[1], series[0], rtol=0, atol=1e-10 * scale)


def test_reset_restarts_the_flow_with_the_body_in_place():
    cfg = small_config()
    ss = SessionSolver(create_solver("numpy", cfg), body=start_body())
    ss.enable_force_models(MODELS)
    ss.set_body(start_body(), (0.02, 0.0))
    ss.step(15)
    ss.reset()
    fresh = create_solver("numpy", cfg)
    fresh.enable_force_models(MODELS)
    fresh.set_body(start_body(), velocity=(0.02, 0.0))
    assert ss.time == 0
    np.testing.assert_array_equal(ss.distributions(), fresh.distributions())
    ss.step(3)
    fresh.step(3)
    assert ss.forces() == fresh.forces()


def test_recorded_playback_and_csv_export(tmp_path):
    path, rec = record(tmp_path, extras=False, steps=10)
    s = load_session(path)
    frames = list(s.frames())
    assert [f[0] for f in frames] == list(s.forces["step"])
    assert frames[-1][2]["momentum_exchange"] == tuple(s.forces["values"][-1, :2])
    out = tmp_path / "forces.csv"
    export_csv(s, out)
    with open(out, newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["step", "x", "y", "vx", "vy", "fx_momentum_exchange", "fy_momentum_exchange",
                       "torque_momentum_exchange"]
    assert rows[0] == force_columns(s.models)
    assert len(rows) == 1 + len(frames)
    # the decimals round-trip exactly
    assert [float(v) for v in rows[-1][5:7]] == list(s.forces["values"][-1])
    assert float(rows[-1][7]) == s.forces["torques"][-1, 0]
    assert int(rows[-1][0]) == s.steps and math.isclose(float(rows[-1][1]), frames[-1][1][0])


SCENE_TOML = """
[grid]
nx = 64
ny = 32
[flow]
nu = 0.05
inflow_speed = 0.03
inflow_ramp_steps = 10
[body]
kind = "plate"
length = 8
thickness = 2
x = 24
y = 16.2
angle = 10
[[motion]]
steps = 10
move = "stop"
[[motion]]
steps = 20
move = "against"
[output]
forces = ["momentum_exchange", "pressure"]
interval = 5
"""


def test_record_headless_records_a_scripted_run(tmp_path):
    """What `feelflow run SCENE --record FILE` does: the scene's motion runner drives the
    wrapped solver; the file replays to the same forces."""
    import tomllib

    from feelflow.app.model.scene import scene_from_dict
    from feelflow.solver.motion import MotionRunner

    scene = scene_from_dict(tomllib.loads(SCENE_TOML), "plate.toml")
    solver = create_solver("numpy", scene.config)
    ss, rec = record_headless(solver, scene, scene_toml=SCENE_TOML)
    ss.enable_force_models(scene.force_models)
    runner = MotionRunner(ss, scene.body, scene.motion)
    while runner.t < scene.steps:
        runner.advance(scene.output_interval)
    rec.save(tmp_path / "h.ffsession")
    s = load_session(tmp_path / "h.ffsession")
    assert s.manifest["scene"]["source"] == "plate.toml" and s.manifest["scene"]["toml"] == SCENE_TOML
    assert s.steps == scene.steps and len(s.inputs["step"]) >= 20  # placed before every moving step
    assert s.inputs["velocity"][-1, 0] == -0.03
    result = replay(s)
    assert result.max_force > 1e-3 and result.max_deviation == 0.0


@pytest.mark.parametrize("bad", [{"step": 3}, {"n": 0}])
def test_recorder_refuses_inconsistent_steps(bad):
    rec = SessionRecorder(small_config(), start_body(), MODELS)
    with pytest.raises(ValueError):
        if "n" in bad:
            rec.record_forces(bad["n"], {})
        else:
            rec.record_input(20, 16, step=bad["step"])


@pytest.mark.parametrize("backend", BACKENDS)
def test_replay_on_the_recording_backend_is_exact(backend, request, tmp_path):
    """Both backends replay their own recordings bit for bit (float32 storage, the GUI's)."""
    cfg = small_config(dtype="float32")
    factory = lambda c: make_solver(backend, c, request)  # noqa: E731
    rec = SessionRecorder(cfg, start_body(), MODELS, backend=backend)
    drive_moving_cylinder(SessionSolver(factory(cfg), rec, factory=factory), steps=30)
    rec.save(tmp_path / "b.ffsession")
    s = load_session(tmp_path / "b.ffsession")
    result = replay(s, factory=factory)
    assert result.max_force > 1e-3 and result.max_deviation == 0.0
    if backend == "gl":  # the other backend follows the same algorithm to float32 rounding
        other = replay(s, "numpy")
        assert 0 < other.relative_deviation < 1e-4
