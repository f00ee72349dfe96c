"""The declared interface between the window and the tunnel it shows: `TunnelModel`, what the
window, the viewport, the side panel and the force plot read and call on the model. Both the
live `Simulation` (app/model/simulation.py) and a replaying session's `ReplaySimulation`
(app/model/replay_simulation.py) implement it, so the window swaps one for the other without
knowing which it holds; tests/test_tunnel_model.py checks both against it, member by member.

Changing the live tunnel (body, flow, grid, lessons, recording) is not part of it: those calls
go to the live `Simulation` only, which a replay never replaces. Lattice units throughout
(docs/science/algorithm.md).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Protocol, runtime_checkable

import numpy as np

from feelflow.app.model.body_input import BodyInput
from feelflow.app.model.readouts import ReferenceLength
from feelflow.app.model.wind_sweep import WindSweep
from feelflow.app.sessions import SessionSolver
from feelflow.shapes.base import Shape
from feelflow.solver.config import FlowConfig
from feelflow.solver.motion import MotionRunner

if TYPE_CHECKING:   # simulation.py defines them and implements this interface
    import moderngl

    from feelflow.app.model.force_history import History
    from feelflow.app.model.live_polar import LivePolar
    from feelflow.solver.forces.surface_pressure import SurfacePressure
    from feelflow.app.model.simulation import Params
    from feelflow.app.sessions.format import Session


@runtime_checkable
class TunnelModel(Protocol):
    """What the window drives: one frame at a time (`advance`), body input through one way in
    (`drive`), and what is drawn and read out."""

    config: FlowConfig   # grid size, Mach cap, sponge
    params: "Params"     # what the side panel shows
    history: "History"   # one force sample per frame, for the plot
    solver: SessionSolver   # the flow (a solver.backend.FlowSolver): its field, range check, recording
    shape: Shape | None  # the body where the flow feels it, or None
    pos: tuple[float, float]    # the body's reference point (cells)
    angle: float         # the body's angle (radians)
    vel: tuple[float, float]    # the body's velocity (cells per step)
    target: tuple[float, float] | None   # where an input pulls the body, or None
    hold_still: bool     # the body ignores pulls and turns (the polygon editor, some lessons)
    polygon: list | None   # the custom polygon's vertices (body frame), or None
    capped: bool         # the Mach cap limited the body's speed in the last frame
    sweep: WindSweep | None   # a lesson's wind sweep, or None
    runner: MotionRunner | None   # a motion script driving the pose, or None
    polar: "LivePolar | None"   # an angle-of-attack sweep running in the tunnel (the plot's polar views), or None

    def advance(self, n: int) -> dict:
        """Run about n steps; {force model: (Fx, Fy)} averaged over them."""
        ...

    def drive(self, request: BodyInput) -> bool:
        """Body input from the mouse, a device or a script; False when the model refuses it."""
        ...

    def hit(self, x: float, y: float, tolerance: float = 2.0) -> bool:
        """Is the lattice point (x, y) on the body, within `tolerance` cells?"""
        ...

    def target_degrees(self) -> float:
        """The angle the body is asked to turn to (degrees, any number of turns)."""
        ...

    def relative_wind(self) -> tuple[float, float]:
        """The wind the body meets: the inflow less the body's velocity."""
        ...

    def reference_length(self) -> ReferenceLength:
        """The length the force coefficients are made dimensionless with (app/model/readouts.py)."""
        ...

    def reynolds(self) -> float:
        ...

    def mach(self) -> float:
        ...

    def operator_line(self) -> str:
        """Which collision operator runs and why, in one line (solver/operator_choice.py)."""
        ...

    def field_texture(self, vorticity: bool = True) -> "moderngl.Texture | None":
        """The field as a texture on the flow's GL context, or None (draw `field_rgba`)."""
        ...

    def field_rgba(self) -> np.ndarray:
        """(ny, nx, 4) float32: rho, ux, uy, vorticity (the numpy path's field)."""
        ...

    def script_phase(self) -> tuple[int, int, str] | None:
        """(phase index, count, words) of a running motion script, or None."""
        ...

    def sweep_stage(self) -> int | None:
        """Which speed of a wind sweep holds now, or None."""
        ...

    def surface_pressure(self) -> "SurfacePressure | None":
        """C_p along the surface now (the plot's C_p view), or None where nothing is sampled."""
        ...

    def watch_surface_pressure(self, on: bool = True) -> None:
        """Sample the wall pressure for C_p along the surface while `on` (the C_p view shows)."""
        ...

    def replayed_session(self) -> "Session | None":
        """The session file being replayed (its recorded units and probes), or None in the live tunnel."""
        ...
