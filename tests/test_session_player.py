"""The incremental session player (app/sessions/replay.py) behind the window's replay: replayed
a few steps at a time it gives the recorded force series bit for bit (numpy), the same as
`replay()`, with the body at the recorded poses; an impossible event is one SessionError line."""
from __future__ import annotations

import math

import numpy as np
import pytest

from feelflow.app.sessions import SessionError, SessionRecorder, SessionSolver, load_session, replay
from feelflow.app.sessions import SessionPlayer
from session_scenes import drive_moving_cylinder, small_config, start_body
from feelflow.solver.backend import create_solver


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """A headless numpy session with every kind of event (inputs, inflow, models, viscosity,
    pause/resume, shape edit, reset), saved and loaded back."""
    cfg = small_config()
    rec = SessionRecorder(cfg, start_body(), ("momentum_exchange",))
    drive_moving_cylinder(SessionSolver(create_solver("numpy", cfg), rec), steps=40, extras=True)
    path = tmp_path_factory.mktemp("player") / "run.ffsession"
    rec.save(path)
    return load_session(path)


def values_of(rows, models):
    """Replayed rows -> the (m, 2 * len(models)) array of the file's forces.npz 'values'."""
    out = np.full((len(rows), 2 * len(models)), np.nan)
    for r, row in enumerate(rows):
        for j, m in enumerate(models):
            if m in row.forces:
                out[r, 2 * j:2 * j + 2] = row.forces[m]
    return out


@pytest.mark.parametrize("budget", [1, 4, 25])
def test_stepwise_replay_gives_the_recorded_forces_bit_for_bit(recorded, budget):
    s = recorded
    rows_n = s.forces["n"]
    with SessionPlayer(s) as player:
        assert player.total_steps == s.steps and player.step == 0 and not player.done
        calls = 0
        while not player.done:
            before, first = player.step, len(player.rows)
            ran = player.advance(budget)
            calls += 1
            assert ran == player.step - before
            new = player.rows[first:]
            # bounded: within the budget, or one row that is longer than the budget on its own
            assert ran <= budget or (len(new) == 1 and new[0].n > budget)
            if new:  # the body drawn is the body the flow felt during the last replayed row
                k = len(player.rows) - 1
                assert player.step == s.forces["step"][k]
                if player.shape is not None:
                    assert (player.shape.x, player.shape.y) == tuple(s.forces["body"][k][:2])
        assert player.step == s.steps
        values = values_of(player.rows, s.models)
    assert calls >= s.steps // max(budget, int(rows_n.max()))
    assert np.nanmax(np.abs(values)) > 1e-3            # the body feels a real force
    np.testing.assert_array_equal(values, s.forces["values"])        # as recorded, bitwise
    np.testing.assert_array_equal(values, replay(s).values)          # and as replay() gives
    np.testing.assert_array_equal([r.step for r in player.rows], s.forces["step"])


def test_an_impossible_event_stops_the_player_with_one_line(recorded):
    s = recorded
    s = type(s)(**{**s.__dict__, "inputs": {k: v.copy() for k, v in s.inputs.items()}})
    s.inputs["pose"][6, 0] = 1.0     # the cylinder's centre one cell from the inlet
    bad_step = int(s.inputs["step"][6])
    player = SessionPlayer(s)
    try:
        with pytest.raises(SessionError, match=r"event \d+ \(input at step \d+\) cannot be replayed") as info:
            while not player.done:
                player.advance(3)
        assert "\n" not in str(info.value)
        # everything before the bad event was replayed as recorded
        k = len(player.rows)
        assert player.step == bad_step and k > 0
        np.testing.assert_array_equal(values_of(player.rows, s.models), s.forces["values"][:k])
    finally:
        player.close()


def test_a_scene_that_cannot_be_built_is_a_session_error(recorded):
    """A backend that refuses the recorded grid: one line, no traceback."""
    def refuse(config):
        raise ValueError(f"a {config.nx} x {config.ny} grid is too large for this backend\nmore detail")

    with pytest.raises(SessionError, match="cannot be built: a 64 x 32 grid is too large") as info:
        SessionPlayer(recorded, factory=refuse)
    assert "\n" not in str(info.value)


def test_replay_simulation_feeds_the_history_the_replayed_rows(recorded):
    """What the window's plot reads: one history sample per replayed row, its forces and time
    the recorded ones, the relative wind from the recorded body velocity and inflow."""
    from feelflow.app.model.replay_simulation import ReplaySimulation

    s = recorded
    sim = ReplaySimulation(s)
    try:
        assert sim.name == "run.ffsession" and sim.config.nx == 64
        while not sim.done:
            sim.advance(5)
            assert sim.last_steps >= 1 or sim.done
        h = sim.history
        assert h.time == [int(t) for t in s.forces["step"]]
        # rows longer than what was left of a frame's budget ran in parts: equal up to rounding
        np.testing.assert_allclose(values_of(sim.player.rows, s.models), s.forces["values"], rtol=1e-12, atol=1e-15)
        me = np.array(h.forces["momentum_exchange"])
        np.testing.assert_allclose(me, s.forces["values"][:, 0:2], rtol=1e-12, atol=1e-15)
        vx = s.forces["body"][:, 2]
        np.testing.assert_array_equal(np.array(h.body_velocity)[:, 0], np.where(np.isnan(vx), 0.0, vx))
        assert h.wind[-1][0] == pytest.approx(0.02 - vx[-1])   # the inflow was changed to 0.02
        p = sim.params
        assert p.grid == (64, 32) and p.shape == "cylinder" and p.size == 6.0   # the edited shape
        assert p.compare_all and p.nu == 0.08 and math.isclose(p.wind, 0.02)
    finally:
        sim.close()


def test_long_rows_replay_in_parts_at_the_frame_budget(tmp_path):
    """A session recorded as `feelflow run --record` records it (a force row per output
    interval, here 50 steps) replays in the window a frame's budget at a time: each call runs
    exactly the budget, a row appears when its last part has run, its forces equal the recorded
    ones up to rounding and the flow is bit for bit the flow of a whole-row replay."""
    cfg = small_config()
    body = start_body()
    rec = SessionRecorder(cfg, body, ("momentum_exchange",))
    ss = SessionSolver(create_solver("numpy", cfg), rec)
    ss.enable_force_models(("momentum_exchange",))
    for k in range(4):
        ss.set_body(body.moved(x=body.x + 0.4 * k, y=body.y), (0.008, 0.0), 0.0)
        ss.step(50)
    rec.save(tmp_path / "long.ffsession")
    s = load_session(tmp_path / "long.ffsession")
    assert list(s.forces["n"]) == [50] * 4
    with SessionPlayer(s) as whole:
        while not whole.done:
            whole.advance(7)
        whole_f = whole.solver.distributions()
    with SessionPlayer(s) as player:
        runs, rows_seen = [], []
        while not player.done:
            before = player.step
            runs.append(player.advance(7, split_rows=True))
            assert player.step - before == runs[-1]
            rows_seen.append(len(player.rows))
        assert runs == [7] * 28 + [4]                       # 200 steps in frames of 7
        assert rows_seen[6] == 0 and rows_seen[7] == 1      # the first row completes in the 8th frame
        values = values_of(player.rows, s.models)
        np.testing.assert_allclose(values, s.forces["values"], rtol=1e-12)
        assert [r.step for r in player.rows] == [50, 100, 150, 200]
        np.testing.assert_array_equal(player.solver.distributions(), whole_f)
