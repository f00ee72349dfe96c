"""Local grid refinement around the body: a patch of half-size cells inside the coarse lattice
(numpy reference; docs/science/algorithm.md, 'Local refinement').

Two-level, refinement ratio 2, acoustic scaling (dx and dt halve, so velocities and the 2D
force per unit span keep their lattice values up to a factor below), in the overlapping form
of Dupuis & Chopard (Phys. Rev. E 67 (2003) 066707), with the non-equilibrium rescaled per
TRT parity (Ginzburg, Verhaeghe & d'Humieres 2008: the even part relaxes with tau+, the odd
part with tau-).

- The patch covers the coarse nodes x0..x1, y0..y1 (its border lies on coarse grid lines);
  the fine lattice has (2 (x1 - x0) + 1) x (2 (y1 - y0) + 1) nodes, fine node (I, J) at the
  coarse position (x0 + I / 2, y0 + J / 2), and nu_f = 2 nu (nu dx^2 / dt is the physical
  viscosity), tau+_f - 1/2 = 2 (tau+ - 1/2), the same TRT Lambda.
- The body, a fixed one, lives on the fine lattice only (at twice its size); the coarse lattice
  has none.
- Per coarse step t -> t + 1: the coarse lattice steps; the fine lattice takes two steps, its
  outermost ring of nodes (on the coarse border lines) first set from the coarse lattice at t,
  then at t + 1/2 (linear in time), cubic (4-point) in space between coarse nodes; then the
  coarse nodes strictly inside the border take the fine lattice's values at t + 1 (the
  restriction).
- A population passes between the levels as f^eq(rho, u) + r+ n+ + r- n-, with n+- the even
  and odd parts of its post-collision non-equilibrium and r+- = (tau+-_to - 1) /
  (k (tau+-_from - 1)), k = 2 from coarse to fine and 1/2 back: the pre-collision
  non-equilibrium scales with tau dt, the post-collision one carries the extra factor
  (1 - 1/tau). A tau+- of 1 exactly (BGK at tau 1) leaves no post-collision non-equilibrium
  to rescale and is refused.
- Forces: the fine lattice's force models, averaged over its two steps, divided by 2
  (F = f rho dx^3 / dt^2 per unit span: halving dx and dt halves it in lattice units); torques
  divided by 4 (T = t rho dx^4 / dt^2 per unit span).
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from feelflow.solver.backend import Solver
from feelflow.solver.body import shifted, unshifted
from feelflow.solver.config import ConfigError, FlowConfig
from feelflow.solver.lattice import C, OPP, equilibrium
from feelflow.solver.numpy_backend import NumpySolver
from feelflow.solver.relaxation import relaxation_rates

#: coarse cells between the patch's border and the body, and between the border and the domain edge
BODY_MARGIN = 3
EDGE_MARGIN = 2
#: length keys of each shape kind that scale with the lattice (shapes.to_dict)
_LENGTH_KEYS = ("diameter", "length", "thickness", "chord")
#: closest |tau - 1| the rescaling accepts (module docstring)
_TAU_ONE_GAP = 0.02


def _taus(config: FlowConfig) -> tuple[float, float]:
    """(tau+, tau-) of a config away from any sponge."""
    op, om = relaxation_rates(replace(config, sponge_cells=0))
    return 1.0 / op, 1.0 / om


def rescale(f: np.ndarray, ratio_p: float, ratio_m: float, config: FlowConfig) -> np.ndarray:
    """f^eq(rho, u) + ratio_p n+ + ratio_m n- of full post-collision populations f (9, ...), with
    the equilibrium `config` names."""
    rho = f.sum(axis=0)
    per = config.velocity_divisor(rho)
    ux = np.tensordot(C[:, 0].astype(np.float64), f, axes=1) / per
    uy = np.tensordot(C[:, 1].astype(np.float64), f, axes=1) / per
    feq = equilibrium(rho, ux, uy, incompressible=config.incompressible).astype(np.float64)
    neq = f - feq
    neq_opp = neq[OPP]
    return feq + 0.5 * ratio_p * (neq + neq_opp) + 0.5 * ratio_m * (neq - neq_opp)


def cubic_midpoints(v: np.ndarray) -> np.ndarray:
    """Values at the fine nodes of coarse lines along the last axis: v (..., n + 2) holds n
    coarse nodes with one halo node at each end; returns (..., 2 n - 1), the nodes as they are
    and the midpoints by 4-point Lagrange interpolation (-1, 9, 9, -1) / 16 (fourth order)."""
    n = v.shape[-1] - 2
    out = np.empty(v.shape[:-1] + (2 * n - 1,))
    out[..., 0::2] = v[..., 1:-1]
    out[..., 1::2] = (9.0 * (v[..., 1:n] + v[..., 2:n + 1]) - v[..., 0:n - 1] - v[..., 3:n + 2]) / 16.0
    return out


def fine_point(x: float, y: float, x0: int, y0: int) -> tuple[float, float]:
    """A coarse position on the fine lattice of a patch with its corner at coarse node (x0, y0)."""
    return 2.0 * (x - x0), 2.0 * (y - y0)


def fine_shape(shape, x0: int, y0: int):
    """The shape on the fine lattice of a patch with its corner at coarse node (x0, y0)."""
    from feelflow.shapes.io import from_dict

    d = shape.to_dict()
    for key in _LENGTH_KEYS:
        if key in d:
            d[key] = 2.0 * d[key]
    if "vertices" in d:
        d["vertices"] = [[2.0 * a, 2.0 * b] for a, b in d["vertices"]]
    d["x"], d["y"] = fine_point(shape.x, shape.y, x0, y0)
    return from_dict(d)


class RefinedSolver(Solver):
    """The numpy reference with a patch of twice the resolution (module docstring).

    `patch` = (x0, y0, x1, y1), coarse node indices of the patch's border lines. `macroscopic`,
    `distributions` and the rest of the Solver interface report the coarse lattice (inside the
    patch: the fine lattice's values at the coincident nodes); `fine` is the fine lattice."""

    name = "numpy-refined"

    def __init__(self, config: FlowConfig, patch):
        super().__init__(config)
        cfg = self.config
        x0, y0, x1, y1 = (int(v) for v in patch)
        if not (EDGE_MARGIN <= x0 and x1 <= cfg.nx - 1 - EDGE_MARGIN and EDGE_MARGIN <= y0
                and y1 <= cfg.ny - 1 - EDGE_MARGIN and x1 - x0 >= 4 and y1 - y0 >= 4):
            raise ConfigError("refine", f"the patch {patch} must span at least 4 cells each way and keep "
                                        f"{EDGE_MARGIN} cells from the edges of the {cfg.nx} x {cfg.ny} lattice")
        if cfg.x_boundary == "tunnel" and cfg.sponge_cells and x1 >= cfg.nx - cfg.sponge_cells:
            raise ConfigError("refine", f"the patch {patch} reaches into the outlet sponge (its last "
                                        f"{cfg.sponge_cells} columns), where the viscosity varies")
        if cfg.body_force != (0.0, 0.0):
            raise ConfigError("refine", "a refined patch does not take a body force")
        self.patch = (x0, y0, x1, y1)
        self.coarse = NumpySolver(cfg)
        fine_cfg = FlowConfig(nx=2 * (x1 - x0) + 1, ny=2 * (y1 - y0) + 1, nu=2.0 * cfg.nu,
                              collision=cfg.collision, trt_magic=cfg.trt_magic, equilibrium=cfg.equilibrium,
                              dtype=cfg.dtype, x_boundary="periodic", y_boundary="periodic",
                              inflow_speed=0.0, inflow_ramp_steps=0, mach_limit=cfg.mach_limit)
        self.fine = NumpySolver(fine_cfg)
        (tpc, tmc), (tpf, tmf) = _taus(cfg), _taus(fine_cfg)
        if min(abs(t - 1.0) for t in (tpc, tmc, tpf, tmf)) < _TAU_ONE_GAP:
            raise ConfigError("refine", f"a relaxation time of 1 (tau+ {tpc:.3f}, tau- {tmc:.3f} coarse; "
                                        f"{tpf:.3f}, {tmf:.3f} fine) leaves no non-equilibrium to pass between "
                                        "the levels: change nu or trt_magic")
        self._to_fine = ((tpf - 1.0) / (2.0 * (tpc - 1.0)), (tmf - 1.0) / (2.0 * (tmc - 1.0)))
        self._to_coarse = (1.0 / self._to_fine[0], 1.0 / self._to_fine[1])
        self._sync_fine_from_coarse()

    @property
    def nodes_per_step(self) -> int:
        """Node updates per coarse step: the coarse lattice and two steps of the fine one."""
        return self.config.nx * self.config.ny + 2 * self.fine.config.nx * self.fine.config.ny

    # --- the two levels ---------------------------------------------------------
    def _rescaled(self, f, ratios):
        return rescale(f, ratios[0], ratios[1], self.config)

    def _ring(self) -> list[np.ndarray]:
        """The coarse border lines with one halo node at each end, rescaled for the fine
        lattice: bottom, top (along x), left, right (along y)."""
        x0, y0, x1, y1 = self.patch
        g = self.coarse.g
        lines = (g[:, y0, x0 - 1:x1 + 2], g[:, y1, x0 - 1:x1 + 2], g[:, y0 - 1:y1 + 2, x0], g[:, y0 - 1:y1 + 2, x1])
        return [self._rescaled(unshifted(line.astype(np.float64)), self._to_fine) for line in lines]

    def _set_fine_ring(self, ring) -> None:
        fg = self.fine.g
        bottom, top, left, right = (shifted(cubic_midpoints(line)).astype(fg.dtype) for line in ring)
        fg[:, 0, :], fg[:, -1, :] = bottom, top
        fg[:, :, 0], fg[:, :, -1] = left, right

    @staticmethod
    def _ring_between(ring_t, ring_t1):
        """The border at t + 1/2 for the fine lattice's second step: linear in time."""
        return [0.5 * (a + b) for a, b in zip(ring_t, ring_t1)]

    def _restrict(self) -> None:
        """Coarse nodes strictly inside the border take the fine values at the same place."""
        x0, y0, x1, y1 = self.patch
        f = unshifted(self.fine.g[:, 2:-2:2, 2:-2:2].astype(np.float64))
        self.coarse.g[:, y0 + 1:y1, x0 + 1:x1] = shifted(self._rescaled(f, self._to_coarse)).astype(self.coarse.g.dtype)

    def _sync_fine_from_coarse(self) -> None:
        """The whole fine lattice from the coarse one (bicubic), for a new state; and the coarse
        border the fine ring then holds (`_ring_now`)."""
        x0, y0, x1, y1 = self.patch
        f = self._rescaled(unshifted(self.coarse.g[:, y0 - 1:y1 + 2, x0 - 1:x1 + 2].astype(np.float64)),
                           self._to_fine)
        full = cubic_midpoints(cubic_midpoints(f.swapaxes(1, 2)).swapaxes(1, 2))  # along y, then x
        self.fine.g[...] = shifted(full).astype(self.fine.g.dtype)
        self._ring_now = self._ring()

    # --- Solver interface -------------------------------------------------------------
    def set_body(self, shape, velocity=(0.0, 0.0), omega: float = 0.0, *, raster=None) -> None:
        if raster is not None:
            raise ConfigError("refine", "a refined solver rasterises its body itself")
        if tuple(velocity) != (0.0, 0.0) or omega != 0.0:
            raise ConfigError("refine", "the refined patch holds a fixed body (validation); "
                                        "a moving one would leave the patch")
        if shape is not None:
            x0, y0, x1, y1 = self.patch
            bx0, by0, bx1, by1 = shape.bounding_box()
            if not (bx0 >= x0 + BODY_MARGIN and bx1 <= x1 - BODY_MARGIN and by0 >= y0 + BODY_MARGIN
                    and by1 <= y1 - BODY_MARGIN):
                raise ConfigError("refine", f"the body ({bx0:.1f}, {by0:.1f}) - ({bx1:.1f}, {by1:.1f}) must stay "
                                            f"{BODY_MARGIN} cells inside the refined patch {self.patch}")
            shape = fine_shape(shape, x0, y0)
        self.fine.set_body(shape)
        self.body = self.fine.body
        self.speed_capped = self.fine.speed_capped

    def enable_force_models(self, names) -> None:
        self.fine.enable_force_models(names)
        self._forces = {}

    def add_force_model(self, model) -> None:
        self.fine.add_force_model(model)

    def set_inflow_speed(self, speed: float) -> None:
        self.coarse.set_inflow_speed(speed)
        self.inflow_speed, self.inflow_capped = self.coarse.inflow_speed, self.coarse.inflow_capped
        self.speed_capped = self.inflow_capped or self.fine.speed_capped

    def step(self, n: int = 1) -> None:
        sums: dict[str, list[float]] = {}
        for _ in range(int(n)):
            ring_t = self._ring_now  # what the fine ring holds now; restriction leaves the border alone
            self.coarse.step(1)
            ring_t1 = self._ring()
            for ring in (None, self._ring_between(ring_t, ring_t1)):
                if ring is not None:
                    self._set_fine_ring(ring)
                self.fine.step(1)
                torques = self.fine.torques()
                for name, (fx, fy) in self.fine.forces().items():
                    s = sums.setdefault(name, [0.0, 0.0, 0.0])
                    s[0] += fx
                    s[1] += fy
                    s[2] += torques.get(name, 0.0)
            self._restrict()
            self._set_fine_ring(ring_t1)  # the fine lattice whole at t + 1 (its ring was streamed over)
            self._ring_now = ring_t1
            self.time = self.coarse.time
        if n > 0:
            # mean over the 2 n fine steps, and F_coarse = F_fine / 2 (module docstring)
            self._forces = {name: (s[0] / (4 * n), s[1] / (4 * n)) for name, s in sums.items()}
            # and T_coarse = T_fine / 4 (a moment arm of half the cells)
            self._torques = {name: s[2] / (8 * n) for name, s in sums.items()}

    def shifted_distributions(self) -> np.ndarray:
        return self.coarse.shifted_distributions()

    def set_distributions(self, f: np.ndarray) -> None:
        """The coarse state, and the fine lattice interpolated from it (its solid nodes are
        reset by its next step; every link into them is a Bouzidi link)."""
        self.coarse.set_distributions(f)
        self._sync_fine_from_coarse()
