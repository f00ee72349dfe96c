"""The compiled CPU backend: the numpy reference's algorithm (docs/science/algorithm.md), n
steps in one compiled call (numba, solver/cpu_kernels.py `make_kernel`).

Each step first does, serially and in the numpy backend's order, what the boundaries own
(outlet d, inlet c with the quiet inlet's correction, walls b, body links a with the moving-wall
term) into a third buffer, `pre`, from the post-collision state, summing the momentum exchange
on the body links as it goes; then streams and collides every node, blocks of rows in parallel,
the nodes that own a boundary population taking it from `pre` (a list of nodes and bit masks by
row, rebuilt when the body's links change); then resets the solid nodes. The steps of one call
stream with the AA pattern between a first and a last step in the natural layout, so between
calls the state is the numpy backend's. Every operator is compiled: BGK, TRT,
recursive-regularised BGK and entropic KBC (the last two with or without the Smagorinsky
viscosity).
A move's raster, links, node list and (float32 storage, equilibrium scheme) cover/uncover refill
are compiled equals of the numpy backend's code (solver/body_compiled.py); the force models other
than the momentum exchanges and the fields are the numpy backend's (this class is a NumpySolver
whose step is compiled), so both compute the same numbers to float32 rounding
(tests/test_cpu_vs_numpy.py, tests/test_body_local_move.py). docs/science/cpu-backend.md says why
this layout.
"""
from __future__ import annotations

import numpy as np

from feelflow.solver import body_compiled
from feelflow.solver.backend import SolverDiverged
from feelflow.solver.cpu_kernels import rows_of_nodes
from feelflow.solver.forces.momentum_exchange import ClassicMomentumExchange, GalileanMomentumExchange
from feelflow.solver.inflow import INLET_DIRECTIONS, OUTLET_DIRECTIONS
from feelflow.solver.numpy_backend import NumpySolver, absorb_keep, relaxation_rates
from feelflow.solver.quiet_inlet import CS_OVER_RHO0
from feelflow.solver.regularised import smagorinsky_factor

_EMPTY_I = np.zeros(0, np.int64)
_EMPTY_F = np.zeros(0, np.float64)
#: the momentum-exchange models the kernel's boundary rules sum: model class -> slice of its (4,) sums
#: each momentum exchange's entries of the compiled step's link sums (cpu_kernels._links): fx, fy, moment
_LINK_SUMS = {GalileanMomentumExchange: (0, 1, 4), ClassicMomentumExchange: (2, 3, 5)}


def _bits(dirs) -> int:
    return sum(1 << int(i) for i in dirs)


def _threads() -> int:
    import numba

    return max(1, int(numba.get_num_threads()))


class CpuSolver(NumpySolver):
    """D2Q9 solver compiled for the CPU with numba: NumpySolver's algorithm, fused kernels."""

    name = "cpu"
    compiled_moves = True

    def __init__(self, config):
        from feelflow.solver.cpu_kernels import CHUNK, WALLS, make_kernel

        super().__init__(config)
        cfg = self.config
        nx, ny = cfg.nx, cfg.ny
        op, om = relaxation_rates(cfg)
        dt = self.dtype  # the kernels compute in the storage's precision, as numpy's Collider
        self._op = np.broadcast_to(np.asarray(op, dt), (nx,)).copy()
        self._om = np.broadcast_to(np.asarray(om, dt), (nx,)).copy()
        keep = absorb_keep(cfg)
        self._keep = np.ones(nx, dt) if keep is None else np.asarray(keep, dt)
        # columns 1 .. xs-1 share column 1's rates and have no absorbing layer: the kernel's
        # chunks with scalar rates; xs .. nx-2 (the sponge) chunks with per-column rates
        plain = (self._op == self._op[min(1, nx - 1)]) & (self._om == self._om[min(1, nx - 1)]) & (self._keep == 1.0)
        plain[0] = True
        xs = 1
        while xs < nx - 1 and plain[xs]:
            xs += 1
        self._xs = xs
        self._target = np.zeros(ny, dt)  # the absorbing layer's target u_in(iy, t)
        self._fx, self._fy = (dt.type(v) for v in cfg.body_force)
        smag = cfg.collision in ("rr", "kbc") and cfg.smagorinsky > 0
        self._smag = float(smagorinsky_factor(cfg.smagorinsky)) if smag else 0.0
        self._advance = make_kernel(cfg.collision, bool(cfg.incompressible), keep is not None,
                                    tuple(cfg.body_force) != (0.0, 0.0), dt.name, smag)
        blocks = _threads()
        self._scratch = np.zeros((blocks, 2, 9, CHUNK), dt)
        self._block_sums = np.zeros(blocks)
        self._pre = np.zeros_like(self.g)
        self._tunnel = cfg.x_boundary == "tunnel"
        self._walls_kind = WALLS[cfg.y_boundary]
        self._periodic_x = cfg.x_boundary == "periodic"
        self._quiet = self._tunnel and cfg.inlet_nonreflecting > 0
        self._no_profile = np.zeros((3, ny))
        self._target_zero = np.zeros(ny)
        self._empty_solid = np.zeros((9, 0), dt)
        self._link_force = np.zeros(6)
        self._edge_grid, self._edge_nodes = self._boundary_nodes()
        self._mask_links = None
        self._redo = None
        self._link_arrays = None

    def _boundary_nodes(self):
        """((ny, nx) bits, (iy, ix, bits) of the listed nodes): bit i set where a domain boundary
        rule (c, d, b) writes population i; the kernel's list holds every node of the first and
        last column (they pull across the periodic seam and own the inlet's and outlet's
        populations); a wall row takes its wall's populations chunk by chunk
        (solver/cpu_kernels.py advance, step 2)."""
        cfg = self.config
        bits = np.zeros((cfg.ny, cfg.nx), np.int64)
        if cfg.x_boundary == "tunnel":
            bits[:, 0] |= _bits(INLET_DIRECTIONS)
            bits[:, -1] |= _bits(OUTLET_DIRECTIONS)
        if cfg.y_boundary != "periodic":
            bits[0, :] |= _bits((2, 5, 6))
            bits[-1, :] |= _bits((4, 7, 8))
        listed = np.zeros_like(bits, dtype=bool)
        listed[:, 0] = listed[:, -1] = True  # the seam columns are always listed
        iy, ix = np.nonzero(listed)
        return bits, (iy.astype(np.int64), ix.astype(np.int64), bits[iy, ix])

    def _redo_nodes(self):
        """(iy, ix, bits) of every node a boundary rule or a body link writes a population of,
        and the links as flat arrays in grid coordinates; rebuilt when the body's links change,
        from the links and the body window alone (compiled: solver/body_compiled.py), and the
        same list by row for the kernel (`rows_of_nodes`). Each node comes once: a link node in a
        seam column comes only in the links' part, with its edge bits as well."""
        b = self.body
        links = None if b is None else b.links
        if self._redo is not None and links is self._mask_links:
            return self._redo, self._link_arrays
        if links is not None and len(links):
            self._redo, self._link_arrays = body_compiled.redo_nodes(self._edge_nodes, self._edge_grid, links, b.window)
        else:
            self._redo, self._link_arrays = self._edge_nodes, (_EMPTY_I,) * 5 + (_EMPTY_F,) * 8
        self._mask_links = links
        self._rows = rows_of_nodes(*self._redo, self.config.ny)
        return self._redo, self._link_arrays

    def _move_body(self, old, new) -> tuple[float, float]:
        """NumpySolver._move_body, compiled for the equilibrium refill of float32 storage, the
        window's (solver/body_compiled.py); float64 storage (scoring, validation: bodies placed
        once or seldom) and Caiazzo's refill run the numpy code, which spares a second compiled
        variant (tens of seconds on a fresh machine)."""
        if self.body_refill != "equilibrium" or self.dtype != np.float32:
            return super()._move_body(old, new)
        return body_compiled.move_body(old, new, self.config, self.g, self.body_impulse)

    # --- stepping -------------------------------------------------------------
    def step(self, n: int = 1) -> None:
        """As NumpySolver.step. The momentum exchanges come from the compiled step's link sums
        (the same formulas on the same state), so with only those models enabled the n steps
        are one compiled call; any other model needs the body window before each step, and
        then each step is one call."""
        n = int(n)
        link_models = {name: _LINK_SUMS[type(m)] for name, m in self._models.items() if type(m) in _LINK_SUMS}
        others = {name: m for name, m in self._models.items() if name not in link_models}
        sums = {name: [0.0, 0.0, 0.0] for name in self._models}
        impulse = self._impulse
        self._impulse = (0.0, 0.0)
        done = 0
        while done < n:
            if others:
                win = self.body_window()
                if win is not None:
                    for name, model in others.items():
                        fx, fy, torque = model.evaluate(win)
                        sums[name][0] += fx
                        sums[name][1] += fy
                        sums[name][2] += torque
            k = 1 if others else n
            self._advance_steps(k)
            done += k
            if link_models and self.body is not None:
                cx, cy = float(self.body.shape.x), float(self.body.shape.y)
                for name, (ix, iy, im) in link_models.items():
                    fx, fy = self._link_force[ix], self._link_force[iy]
                    sums[name][0] += fx
                    sums[name][1] += fy
                    sums[name][2] += self._link_force[im] - (cx * fy - cy * fx)  # about the centre
        if n > 0:
            if self.body is not None:  # the Galilean form books the cover/uncover impulse
                for name, (ix, _, _) in link_models.items():
                    if ix == 0:
                        sums[name][0] += impulse[0]
                        sums[name][1] += impulse[1]
            self._forces = {name: (s[0] / n, s[1] / n) for name, s in sums.items()}
            self._torques = {name: s[2] / n for name, s in sums.items()}

    def _step_once(self) -> None:
        self._advance_steps(1)

    def _advance_steps(self, n: int) -> None:
        """n steps in one compiled call (solver/cpu_kernels.py advance)."""
        cfg = self.config
        t = self.time
        wall_profile, profile, rate = self._no_profile, self._target_zero, 0.0
        if self._tunnel:
            self._inflow_ramp(t)  # rebuilds the cached profiles when the speed changed
            wall_profile, profile = self._inlet_wall_profile, self._inflow_profile
            if self._quiet:
                rate = cfg.inlet_nonreflecting
        _, links = self._redo_nodes()
        rp, nxs, nbits = self._rows
        if self._solid_idx is not None:
            sy, sx, solid_g = self._solid_idx[0], self._solid_idx[1], self._solid_g
        else:
            sy, sx, solid_g = _EMPTY_I, _EMPTY_I, self._empty_solid
        dt = self.dtype.type
        done, finite, in_out = self._advance(
            n, t, cfg.inflow_ramp_steps, self.g, self._gin, self._pre, self._op, self._om, self._keep, self._target,
            self._xs, self._fx, self._fy, self._smag, self._scratch, self._block_sums, self._tunnel, self._walls_kind,
            self._periodic_x, profile, wall_profile, dt(rate), dt(CS_OVER_RHO0), self._drho_ref, *links,
            self._link_force, rp, nxs, nbits, sy, sx, solid_g)
        if in_out:
            self.g, self._gin = self._gin, self.g
        self.time = t + done
        if not finite:
            raise SolverDiverged(t + done, "density is no longer finite")
