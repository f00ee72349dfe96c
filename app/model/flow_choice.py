"""What flow the tunnel runs for the panel's parameters (Qt-free): the base configuration (a
scene's, or the window's default tunnel), the collision operator chosen for the parameters
(solver/operator_choice.py) and the stability guard that keeps them inside the measured stable
region (solver/stability_limit.py). `Simulation` holds one `FlowChoice`. Lattice units.
"""
from __future__ import annotations

import math
from dataclasses import replace

from feelflow.solver.config import FlowConfig
from feelflow.solver.operator_choice import MOST_STABLE, Choice, choose
from feelflow.solver.stability_limit import inside, min_stable_viscosity


#: the quiet inlet's rate in the window's tunnel (FlowConfig.inlet_nonreflecting, solver/quiet_inlet.py)
QUIET_INLET_RATE = 1e-3


def default_base_config(grid) -> FlowConfig:
    """What the panel does not edit: TRT, float32, an outlet sponge with its absorbing layer,
    and the wind blowing everywhere from the first step (initial velocity = inflow, no ramp).
    Ramping the inlet up from fluid at rest excites a slow slosh of the whole tunnel, its
    quarter-wave sound mode (mean u swings +-60 % of U with a 1000-step ramp, +-6 % with 2000,
    measured at 256 x 128); starting in uniform flow keeps the mean within +-4 % from the start.
    The absorbing layer (sponge_absorb, docs/science/algorithm.md step 3) lets that sound out: after a
    1000-step ramp at 256 x 128 the mean u swings by 0.3 % of U instead of 46 % (a test,
    tests/test_solver_boundaries.py), so a change of wind settles at once. The quiet inlet
    (inlet_nonreflecting) lets out the sound a moving or stopping body sends upstream
    (docs/science/quiet-tunnel.md)."""
    nx, ny = grid
    return FlowConfig(nx=nx, ny=ny, dtype="float32", inflow_ramp_steps=0, sponge_cells=32, sponge_absorb=0.1,
                      inlet_nonreflecting=QUIET_INLET_RATE)


def stable_params(params, collision: str):
    """`params` kept inside the measured stable region (solver/stability_limit.py): where the
    wind and body size over the viscosity, U sqrt(d) / nu, exceed what the scheme survives, the viscosity
    is raised to the limit (the wind is what the student sees and feels, and what the lessons
    step through; viscosity is the scheme's stability lever). Returns (params, plain sentence
    for the status bar, or None when nothing changed)."""
    if inside(params.wind, params.nu, collision, params.size):
        return params, None
    nu = math.ceil(min_stable_viscosity(params.wind, collision, params.size) * 1e4 - 1e-6) / 1e4   # 4 decimals
    return replace(params, nu=nu), (f"Viscosity raised to {nu:.4f}: at wind {params.wind:.3f} past a "
                                    f"{params.size:g}-cell body a thinner fluid makes this grid unstable "
                                    f"(lower the wind or the size to go thinner).")


class FlowChoice:
    """The flow for a set of panel parameters (app/model/simulation.py `Params`): the base
    configuration it starts from, the collision operator (named by a scene, else chosen per
    flow) and the guard's operator."""

    def __init__(self, base_config: FlowConfig | None = None, grid=(256, 128)):
        #: what the panel does not edit (a scene's configuration, or the default tunnel's)
        self.base_config = base_config or default_base_config(grid)
        #: the default tunnel starts with the wind everywhere (no ramp: `default_base_config`)
        self.wind_starts_everywhere = base_config is None
        #: the collision operator a given base configuration names; None: chosen per flow
        self.operator_named = None if base_config is None else base_config.collision

    def use_scene(self, scene) -> None:
        """Start from a scene's configuration and its named operator (app/model/scene.py)."""
        self.base_config = scene.config
        self.operator_named = scene.operator_named
        self.wind_starts_everywhere = False

    @property
    def guard_operator(self) -> str:
        """The operator whose measured region the stability guard keeps the flow in: the named
        one, else the most stable one the chooser can pick."""
        return self.operator_named or MOST_STABLE

    def stable(self, params):
        """(params inside the stable region, the status bar's sentence or None): `stable_params`."""
        return stable_params(params, self.guard_operator)

    def operator_for(self, params) -> Choice:
        """The collision operator for `params` (solver/operator_choice.py) and why, in one line."""
        base = self.base_config
        return choose(params.wind, params.nu, params.size, base.mach_limit, named=self.operator_named,
                      smagorinsky=base.smagorinsky)

    def config_for(self, params) -> FlowConfig:
        """The base configuration with what the panel edits, and the operator, validated."""
        nx, ny = params.grid
        base = self.base_config
        op = self.operator_for(params)
        extra = {"initial_velocity": (params.wind, 0.0)} if self.wind_starts_everywhere else {}
        return replace(base, nx=nx, ny=ny, nu=params.nu, inflow_speed=params.wind, y_boundary=params.wall,
                       collision=op.collision, smagorinsky=op.smagorinsky,
                       sponge_cells=min(base.sponge_cells, nx // 4), **extra).validate()
