"""A short recorded session for the session tests: a cylinder pushed across a small tunnel."""
from __future__ import annotations

from feelflow.shapes.cylinder import Cylinder
from feelflow.solver.config import FlowConfig

MODELS = ("momentum_exchange",)


def small_config(**kw) -> FlowConfig:
    base = dict(nx=64, ny=32, nu=0.05, inflow_speed=0.04, inflow_ramp_steps=20)
    base.update(kw)
    return FlowConfig(**base)


def drive_moving_cylinder(ss, steps: int = 40, extras: bool = True):
    """Drive a SessionSolver: the body moves diagonally at sub-cell poses, stepping 1-3 steps
    between samples; with extras, inflow, force-model, viscosity, pause/resume, reset and shape
    edits happen on the way."""
    body = ss.geometry_shape
    ss.enable_force_models(MODELS)
    x, y = body.x, body.y
    vx, vy = 0.03, 0.011
    for k in range(steps):
        x, y = x + vx, y + vy
        ss.set_body(body.moved(x=x, y=y, angle=0.01 * k), (vx, vy), 0.002)
        ss.step(1 + k % 3)
        if extras and k == 10:
            ss.set_inflow_speed(0.02)
            ss.enable_force_models(MODELS + ("pressure",))
        if extras and k == 20:
            ss.set_viscosity(0.08)
            ss.pause()
            ss.resume()
        if extras and k == 25:
            body = Cylinder(diameter=6.0, x=x, y=y)
        if extras and k == 30:
            ss.reset()
    return ss


def start_body() -> Cylinder:
    return Cylinder(diameter=8.0, x=20.0, y=16.3)
