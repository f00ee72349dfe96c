"""A session replaying in the window: a `TunnelModel` (app/model/tunnel.py), as the live
`feelflow.app.model.simulation.Simulation` is (config, params, body pose, history, field), fed
by a `SessionPlayer` instead of the mouse. Read-only: the body follows the recording, and
`drive` refuses every body input.

Qt-free, so it is testable on its own; the window swaps it in for the live simulation while a
session replays and swaps the live one back when the replay stops.
"""
from __future__ import annotations

import math
from pathlib import Path

from feelflow.app.model.body_input import BodyInput
from feelflow.app.model.readouts import ReferenceLength
from feelflow.app.sessions import SessionPlayer
from feelflow.app.sessions.format import Session
from feelflow.app.model.force_history import History
from feelflow.app.model.simulation import FORCE_MODELS, Params, shape_hit
from feelflow.solver import units
from feelflow.solver.force_average import StepWeightedMean


class ReplaySimulation:
    """A `SessionPlayer` as a `TunnelModel`. `advance(n)` replays about n steps
    and adds one history sample per replayed force row (so the plot shows the replayed series
    exactly), with the session step as its time."""

    #: what a live tunnel may have and a replay has not: no pull, no editor, no cap, no
    #: sweep, no motion script, no angle-of-attack sweep (the recording holds their effects)
    target = None
    hold_still = False
    polygon = None
    capped = False
    sweep = None
    runner = None
    polar = None

    def __init__(self, session, backend: str | None = None, *, ctx=None, factory=None):
        self.player = SessionPlayer(session, backend, ctx=ctx, factory=factory)
        self.name = Path(session.source).name
        self.history = History()
        self.last_torques: dict[str, float] = {}   # each model's torque, the mean of the last rows replayed
        self.paused = False
        self.last_steps = 0
        self._last_forces: dict = {}
        self.split_rows = True   # a force row longer than a frame's budget runs in parts (SessionPlayer)
        self._params_cache = None  # (player.events_done, Params)

    # --- what the window draws ----------------------------------------------------------
    @property
    def solver(self):
        return self.player.solver

    @property
    def config(self):
        return self.player.solver.config

    @property
    def shape(self):
        """The body where the flow last felt it, or None when the session removed it."""
        return self.player.shape

    @property
    def pos(self):
        s = self.player.shape
        return (s.x, s.y) if s is not None else (math.nan, math.nan)

    @property
    def angle(self) -> float:
        s = self.player.shape
        return s.angle if s is not None else 0.0

    @property
    def vel(self):
        return self.player.velocity

    @property
    def step(self) -> int:
        return self.player.step

    @property
    def total_steps(self) -> int:
        return self.player.total_steps

    @property
    def done(self) -> bool:
        return self.player.done

    @property
    def params(self) -> Params:
        """The panel's view of the replayed scene now (wind, viscosity, grid, body, models);
        rebuilt only when the player has applied events since (the viewport reads it many
        times a frame)."""
        key = self.player.events_done
        cached = self._params_cache
        if cached is None or cached[0] != key:
            self._params_cache = cached = (key, self._build_params())
        return cached[1]

    def _build_params(self) -> Params:
        from feelflow.app.model.bodies import params_for_shape

        geometry = self.player.shape or self.player.geometry
        kind, size = "cylinder", 0.0
        if geometry is not None:
            try:
                kind, size, _ = params_for_shape(geometry)
            except ValueError:
                kind, size = "polygon", None
            if size is None:   # a polygon: its extent
                x0, y0, x1, y1 = geometry.bounding_box()
                size = max(x1 - x0, y1 - y0)
        models = [m for m in self.player.models if m in FORCE_MODELS] \
            or [m for m in self.player.session.models if m in FORCE_MODELS] or ["momentum_exchange"]
        cfg = self.config
        return Params(grid=(cfg.nx, cfg.ny), shape=kind, size=float(size) or 1.0,
                      angle_deg=math.degrees(self.angle), wind=self.player.inflow_speed,
                      nu=self.player.solver.flow_config.nu, wall=cfg.y_boundary,
                      force_model=models[0], compare_all=len(models) > 1)

    def drive(self, request: BodyInput) -> bool:
        """Body input: refused (False), the body follows the recording."""
        return False

    def hit(self, x: float, y: float, tolerance: float = 2.0) -> bool:
        """Is the lattice point (x, y) on the replayed body, within `tolerance` cells?"""
        return shape_hit(self.player.shape, x, y, tolerance)

    def target_degrees(self) -> float:
        """The replayed body's angle in degrees (a replay is asked for no angle)."""
        return math.degrees(self.angle)

    def relative_wind(self):
        vx, vy = self.player.velocity
        return (self.player.inflow_speed - vx, -vy)

    def reference_length(self) -> ReferenceLength:
        """The body's size, the coefficients' reference length (app/model/readouts.py)."""
        return ReferenceLength(self.params.size)

    def reynolds(self) -> float:
        p = self.params
        return units.reynolds(p.wind, p.size, p.nu)

    def mach(self) -> float:
        return units.mach(self.player.inflow_speed)

    def operator_line(self) -> str:
        """The recorded run's collision operator (the recording fixed it)."""
        from feelflow.solver.operator_choice import NAMES

        c = self.config.collision
        return f"{NAMES.get(c, c)}: as recorded"

    def field_texture(self, vorticity: bool = True):
        return self.solver.field_texture(vorticity=vorticity)

    def field_rgba(self):
        return self.solver.field_rgba()

    def script_phase(self):
        return None

    def sweep_stage(self):
        return None

    def surface_pressure(self):
        """None: a session records forces, not the wall pressure along the surface."""
        return None

    def watch_surface_pressure(self, on: bool = True) -> None:
        """Nothing to sample: the replayed flow's wall pressure is not recorded."""

    def replayed_session(self) -> Session:
        """The session file this replay plays."""
        return self.player.session

    # --- running ------------------------------------------------------------------------
    def advance(self, n: int) -> dict:
        """Replay n steps (SessionPlayer.advance, a long force row in parts: a session recorded
        with one row per 100 steps replays at the window's frame rate, not one frame per row);
        returns {model: (fx, fy)} of the rows completed, averaged over them, like
        Simulation.advance (the last ones while a row is still in parts). `last_steps` says how
        many ran."""
        first = len(self.player.rows)
        self.last_steps = self.player.advance(max(1, int(n)), split_rows=self.split_rows)
        rows = self.player.rows[first:]
        mean = StepWeightedMean()
        for row in rows:
            vx, vy = (0.0, 0.0) if math.isnan(row.body[2]) else row.body[2:4]
            self.history.add(row.step, (vx, vy), (row.inflow_speed - vx, -vy), row.forces, row.torques)
            mean.add(row.forces, row.n, row.torques)
        if rows:
            self._last_forces = mean.mean()
            self.last_torques = mean.torque_mean()
        return self._last_forces

    def close(self) -> None:
        self.player.close()
