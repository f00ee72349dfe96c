"""The window's body motion (app/model/body_motion.py): while the body moves, its pose advances
every step, so the force the frame loop receives has no catching-up step after each placement."""
from __future__ import annotations

import math

import numpy as np
import pytest

from feelflow.app.model.body_input import BodyInput
from feelflow.app.model.body_motion import REST_SPEED, advance_with_motion, is_moving
from feelflow.app.model.simulation import Params, Simulation


class Placements:
    """Wraps a solver: records the time and x of every set_body."""

    def __init__(self, solver):
        self.solver, self.calls = solver, []

    def __getattr__(self, name):
        return getattr(self.solver, name)

    def set_body(self, shape, velocity=(0.0, 0.0), omega=0.0, **kw):
        self.calls.append((self.solver.time, shape.x, velocity[0]))
        self.solver.set_body(shape, velocity, omega, **kw)


def test_is_moving_says_rest_only_at_rest_and_at_the_target():
    assert not is_moving((0.0, 0.0), 0.0)
    assert not is_moving((REST_SPEED / 2, 0.0), 0.0, (10.0, 5.0), (10.0, 5.0))
    assert is_moving((0.0, 0.0), 0.0, (10.0, 5.0), (12.0, 5.0))     # a new target: starts now
    assert is_moving((0.01, 0.0), 0.0)
    assert is_moving((0.0, 0.0), 0.002)
    assert is_moving((0.0, 0.0), 0.0, angle=0.0, angle_target=0.5)


def test_a_pulled_body_is_placed_every_step_at_its_advancing_pose():
    """A frame of 8 steps while the spring pulls: 8 placements, one before each step, each pose
    one step's travel further (the window used to place it once per half cell)."""
    sim = Simulation(Params(grid=(96, 48), size=8.0))
    x0 = sim.pos[0]
    sim.drive(BodyInput.pull(x0 + 20.0, sim.pos[1], source="mouse"))
    sim.advance(30)
    spy = Placements(sim.solver)
    sim.solver = spy
    sim.advance(8)
    times = [t for t, _, _ in spy.calls]
    assert len(times) == 8 and times == list(range(times[0], times[0] + 8))
    xs = np.array([x for _, x, _ in spy.calls])
    vx = np.array([v for _, _, v in spy.calls])
    assert np.all(vx > 0)
    np.testing.assert_allclose(np.diff(xs), vx[1:], rtol=1e-12)   # each pose one step's travel on


def test_a_body_at_rest_runs_the_frame_in_one_call():
    sim = Simulation(Params(grid=(96, 48), size=8.0))
    sim.advance(2)
    spy = Placements(sim.solver)
    sim.solver = spy
    sim.advance(10)
    assert spy.calls == []


def test_advance_with_motion_weights_forces_by_steps():
    class Fake:
        def __init__(self):
            self.k = []

        def step(self, k):
            self.k.append(k)

        def forces(self):
            return {"m": (float(self.k[-1]), 1.0)}

    state = {"moving": 3}

    def moving():
        state["moving"] -= 1
        return state["moving"] >= 0

    fake = Fake()
    moves = []
    acc = advance_with_motion(fake, 10, moves.append, moving)
    assert fake.k == [1, 1, 1, 7] and moves == [1, 1, 1, 7]
    assert acc["m"] == pytest.approx((3 + 49, 10.0)) and math.isfinite(acc["m"][0])
