"""The numpy reference backend: docs/science/algorithm.md, vectorised over the whole grid.

Storage: post-collision populations shifted by their rest value, g_i = f*_i - w_i RHO0, so
float32 keeps density fluctuations of 1e-5 (Skordos 1993). Streaming is a periodic shift of
each population by slicing, then the boundary rules overwrite what they own in reverse order
of priority (d outlet, c inlet, b walls, a body), then collision (BGK, TRT, recursive-regularised BGK or entropic KBC, Guo forcing).
Every boundary rule is affine with coefficients summing to one, so it applies to g unchanged.
"""
from __future__ import annotations

import numpy as np

from feelflow.solver.backend import Solver, SolverDiverged
from feelflow.solver.body import move_body, same_solid_motion, shifted, unshifted
from feelflow.solver.bouzidi import incoming
from feelflow.solver.collision import Collider
from feelflow.solver.config import FlowConfig
from feelflow.solver.forces.base import BodyWindow
from feelflow.solver.inflow import INLET_DIRECTIONS, OUTLET_DIRECTIONS, inlet_wall_profile, outlet_incoming, profile, ramp
from feelflow.solver.lattice import C, OPP, Q, RHO0, W, equilibrium
from feelflow.solver.kbc import KBCCollider
from feelflow.solver.regularised import RegularisedCollider
from feelflow.solver.relaxation import relaxation_rates
from feelflow.solver.quiet_inlet import checked_reference, quiet_terms, wall_velocity_correction
from feelflow.solver.sponge import absorb_keep

#: i -> j with c_j = (c_i,x, -c_i,y): specular reflection at a horizontal wall
MIRROR_Y = np.array([0, 1, 4, 3, 2, 8, 7, 6, 5])


def _roll_segments(s: int, n: int):
    """(dst, src) slice pairs so that dst[k] = src[k - s] with wrap-around, s in {-1, 0, 1}."""
    if s == 0:
        return [(slice(0, n), slice(0, n))]
    if s == 1:
        return [(slice(1, n), slice(0, n - 1)), (slice(0, 1), slice(n - 1, n))]
    return [(slice(0, n - 1), slice(1, n)), (slice(n - 1, n), slice(0, 1))]


class NumpySolver(Solver):
    """Reference D2Q9 solver (docs/science/algorithm.md), numpy, float64 or float32 storage."""

    name = "numpy"

    def __init__(self, config: FlowConfig):
        super().__init__(config)
        cfg = self.config
        self.dtype = np.dtype(cfg.dtype)
        nx, ny = cfg.nx, cfg.ny
        ux0, uy0 = cfg.initial_velocity
        feq = equilibrium(np.full((ny, nx), RHO0), np.full((ny, nx), float(ux0)), np.full((ny, nx), float(uy0)))
        self.g = shifted(feq).astype(self.dtype)
        self._gin = np.empty_like(self.g)
        self._drho_ref = np.zeros(ny, dtype=self.dtype)  # the quiet inlet's reference (quiet_inlet.py)
        self._w = W.astype(self.dtype)
        op, om = relaxation_rates(cfg)
        if cfg.collision == "kbc":
            self._collide = KBCCollider(ny, nx, self.dtype, op, cfg.body_force, keep=absorb_keep(cfg),
                                        incompressible=cfg.incompressible, smagorinsky=cfg.smagorinsky)
        elif cfg.collision == "rr":
            self._collide = RegularisedCollider(ny, nx, self.dtype, op, cfg.body_force, keep=absorb_keep(cfg),
                                                incompressible=cfg.incompressible, smagorinsky=cfg.smagorinsky)
        else:
            self._collide = Collider(ny, nx, self.dtype, op, om, cfg.collision == "trt", cfg.body_force,
                                     keep=absorb_keep(cfg), incompressible=cfg.incompressible)
        self._roll = []
        for i in range(Q):
            cx, cy = int(C[i, 0]), int(C[i, 1])
            self._roll.append([((yd, xd), (ys, xs))
                               for yd, ys in _roll_segments(cy, ny) for xd, xs in _roll_segments(cx, nx)])
        self._solid_idx = None
        self._solid_g = None
        self._impulse = (0.0, 0.0)
        self._inflow_key = self._inflow_profile = self._inlet_wall_profile = None

    # --- body -----------------------------------------------------------------
    def set_body(self, shape, velocity=(0.0, 0.0), omega: float = 0.0, *, raster=None) -> None:
        old = self.body
        new = self._body_state(shape, velocity, omega, raster)
        if same_solid_motion(old, new):   # a sub-cell move at the same motion: nothing to write
            self.body = new
            self.speed_capped = new.capped or self.inflow_capped
            return
        jx, jy = self._move_body(old, new)
        self._impulse = (self._impulse[0] + jx, self._impulse[1] + jy)
        self.body = new
        if new is not None:
            bx0, by0 = new.raster.box[:2]  # the raster's box holds every solid node
            sy, sx = np.nonzero(new.raster.box_solid)
            sy, sx = sy + by0, sx + bx0
            self._solid_idx = (sy, sx)
            self._solid_g = self.g[:, sy, sx].copy()
            self.speed_capped = new.capped or self.inflow_capped
        else:
            self._solid_idx = self._solid_g = None
            self.speed_capped = self.inflow_capped

    def _move_body(self, old, new) -> tuple[float, float]:
        """Cover/uncover bookkeeping and refill between two body states (solver/body.py
        `move_body`); the impulse (Jx, Jy)."""
        return move_body(old, new, self.config, self._read_window, self._write_nodes,
                         refill_scheme=self.body_refill, impulse=self.body_impulse)

    def _read_window(self, x0, y0, x1, y1) -> np.ndarray:
        return unshifted(self.g[:, y0:y1, x0:x1])

    def _write_nodes(self, x0, y0, f, changed) -> None:
        h, w = changed.shape
        sub = self.g[:, y0:y0 + h, x0:x0 + w]
        sub[:, changed] = shifted(f[:, changed]).astype(self.dtype)

    # --- forces ---------------------------------------------------------------
    def body_window(self) -> BodyWindow | None:
        """The body's force window at the current time (full f*, float64)."""
        b = self.body
        if b is None:
            return None
        ys, xs = b.window_slices()
        solid, q = b.window_arrays()
        return BodyWindow(x0=b.window[0], y0=b.window[1], f=unshifted(self.g[:, ys, xs]), solid=solid, q=q,
                          shape=b.shape, velocity=b.velocity, omega=b.omega, impulse=self._impulse,
                          config=self.config, links=b.links)

    # --- stepping -------------------------------------------------------------
    def step(self, n: int = 1) -> None:
        sums = {name: [0.0, 0.0, 0.0] for name in self._models}
        for _ in range(int(n)):
            if self._models:
                win = self.body_window()
                if win is not None:
                    for name, model in self._models.items():
                        fx, fy, torque = model.evaluate(win)
                        sums[name][0] += fx
                        sums[name][1] += fy
                        sums[name][2] += torque
            self._impulse = (0.0, 0.0)
            self._step_once()
        if n > 0:
            self._forces = {name: (s[0] / n, s[1] / n) for name, s in sums.items()}
            self._torques = {name: s[2] / n for name, s in sums.items()}

    def _step_once(self) -> None:
        g, gin = self.g, self._gin
        t = self.time
        # e/f: periodic shift of every population (pull: gin_i(x) = g_i(x - c_i))
        for i in range(Q):
            gi, di = g[i], gin[i]
            for (yd, xd), (ys, xs) in self._roll[i]:
                di[yd, xd] = gi[ys, xs]
        u_in = self._boundaries(g, gin, t)
        total = self._collide(gin, u_in)  # u_in: the absorbing layer's target (tunnels only)
        if self._solid_idx is not None:
            gin[:, self._solid_idx[0], self._solid_idx[1]] = self._solid_g
        self.g, self._gin = gin, g
        self.time = t + 1
        if not np.isfinite(total):
            raise SolverDiverged(t + 1, "density is no longer finite")

    def _boundaries(self, g, gin, t: int):
        """Rules d, c, b, a: write what the boundaries own into gin (from the post-collision g
        of step t), in reverse order of priority; return the inlet's u_in(iy, t) (tunnel) or
        None. The compiled cpu backend calls this too (solver/cpu_backend.py)."""
        cfg = self.config
        nx = cfg.nx
        u_in = None
        if cfg.x_boundary == "tunnel":
            # d: outlet, anti-bounce-back at x = nx - 1/2 with rho = RHO0 (pressure outlet)
            gin[OUTLET_DIRECTIONS, :, nx - 1] = outlet_incoming(g[:, :, nx - 2:])
            # c: inlet, moving-wall half-way bounce-back at x = -1/2, each link with the inflow
            # at its own midpoint (solver.inflow.inlet_wall_profile)
            r = self._inflow_ramp(t)
            u_in = r * self._inflow_profile  # u_in(iy, t), as solver.inflow.inflow_velocity
            for k, i in enumerate(INLET_DIRECTIONS):
                gin[i, :, 0] = g[OPP[i], :, 0] + (6.0 * W[i] * RHO0 * r) * self._inlet_wall_profile[k]
            if cfg.inlet_nonreflecting > 0:  # the quiet inlet (solver/quiet_inlet.py)
                corr = wall_velocity_correction(g[:, :, 0].sum(axis=0), self._drho_ref,
                                                *quiet_terms(cfg.inlet_nonreflecting, r))
                for i in INLET_DIRECTIONS:
                    gin[i, :, 0] += (6.0 * W[i] * RHO0) * corr
        if cfg.y_boundary != "periodic":
            self._walls(g, gin)
        b = self.body
        if b is not None and len(b.links):
            L = b.links
            ys, xs = b.window_slices()
            gin[L.i, L.iy + b.window[1], L.ix + b.window[0]] = incoming(g[:, ys, xs], L)
        return u_in

    def _inflow_ramp(self, t: int) -> float:
        """ramp(t), with the cached profiles (per row, and rule c's per inlet link) rebuilt only
        when the speed changes (the config is fixed for a solver's life), as the gl backend does
        with its profile texture."""
        cfg = self.config
        if self._inflow_key != self.inflow_speed:
            self._inflow_key = self.inflow_speed
            self._inflow_profile = profile(cfg.ny, self.inflow_speed, cfg.inflow_profile)
            self._inlet_wall_profile = inlet_wall_profile(cfg.ny, self.inflow_speed, cfg.inflow_profile)
        return ramp(t, cfg.inflow_ramp_steps)

    def _walls(self, g, gin) -> None:
        """Rule b: half-way bounce-back (no_slip) or specular reflection (free_slip) at
        y = -1/2 and y = ny - 1/2; a free-slip tunnel corner keeps the inlet/outlet rule."""
        cfg = self.config
        nx, ny = cfg.nx, cfg.ny
        periodic_x = cfg.x_boundary == "periodic"
        for row, dirs in ((0, (2, 5, 6)), (ny - 1, (4, 7, 8))):
            for i in dirs:
                ib = OPP[i]
                if cfg.y_boundary == "no_slip":
                    gin[i, row, :] = g[ib, row, :]
                    continue
                j = MIRROR_Y[i]
                cx = int(C[i, 0])
                src = g[j, row, :]
                if cx == 0:
                    gin[i, row, :] = src
                elif cx == 1:  # tunnel corner: the inlet rule (c) already set it
                    gin[i, row, 1:] = src[:-1]
                    if periodic_x:
                        gin[i, row, 0] = src[-1]
                else:          # tunnel corner: the outlet rule (d) already set it
                    gin[i, row, :-1] = src[1:]
                    if periodic_x:
                        gin[i, row, nx - 1] = src[0]

    # --- fields ---------------------------------------------------------------
    def shifted_distributions(self) -> np.ndarray:
        return self.g

    def set_distributions(self, f: np.ndarray) -> None:
        f = np.asarray(f, dtype=np.float64)
        if f.shape != self.g.shape:
            raise ValueError(f"distributions must have shape {self.g.shape}, got {f.shape}")
        self.g[...] = shifted(f)
        self._drho_ref = np.zeros(self.config.ny, dtype=self.dtype)  # the quiet inlet's reference

    def inlet_reference(self) -> np.ndarray | None:
        return self._drho_ref.astype(np.float64) if self.has_quiet_inlet else None

    def set_inlet_reference(self, row) -> None:
        row = checked_reference(self, row)
        self._drho_ref = row.astype(self.dtype)

