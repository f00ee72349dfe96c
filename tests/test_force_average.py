"""The one step-weighted force mean (solver/force_average.py): a span run as several calls
reports the force one call over the whole span reports (up to rounding)."""
from __future__ import annotations

import pytest

from feelflow.shapes import Cylinder
from feelflow.solver.backend import create_solver
from feelflow.solver.config import FlowConfig
from feelflow.solver.force_average import StepWeightedMean


def run(calls):
    cfg = FlowConfig(nx=40, ny=20, nu=0.05, inflow_speed=0.04, inflow_ramp_steps=0, initial_velocity=(0.04, 0.0))
    solver = create_solver("numpy", cfg)
    solver.enable_force_models(["momentum_exchange"])
    solver.set_body(Cylinder(5.0, 12.0, 10.0))
    mean = StepWeightedMean()
    for k in calls:
        solver.step(k)
        mean.add(solver.forces(), k)
    return mean


def test_parts_give_the_whole_calls_mean():
    whole, parts = run([12]), run([5, 4, 3])
    assert parts.steps == whole.steps == 12
    (fx, fy), (gx, gy) = whole.mean()["momentum_exchange"], parts.mean()["momentum_exchange"]
    assert gx == pytest.approx(fx, rel=1e-12) and gy == pytest.approx(fy, rel=1e-9, abs=1e-15)


def test_weights_are_the_steps():
    m = StepWeightedMean()
    m.add({"a": (1.0, 0.0)}, 3)
    m.add({"a": (5.0, 2.0), "b": (4.0, 4.0)}, 1)
    assert m.mean() == {"a": (2.0, 0.5), "b": (1.0, 1.0)}
    assert StepWeightedMean().mean() == {}
