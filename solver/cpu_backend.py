"""The compiled CPU backend: the numpy reference's algorithm (docs/algorithm.md), its hot loop
compiled with numba (solver/cpu_kernels.py).

One fused pass pulls every population from its upwind neighbour (periodic in x and y) and
collides, rows in parallel, writing the other of two float32 (or float64) buffers. What the
boundaries own (outlet d, inlet c, walls b, body links a) the numpy backend's own code writes
into a third buffer, `pre`, from the same post-collision state; a second, small pass then redoes
exactly the nodes that own such a population (a per-node bit mask, rebuilt when the body's links
change) with those values in place of the periodic pull. The moving body's cover/uncover
bookkeeping, the frozen solid nodes, the force models and the fields are the numpy backend's
(this class is a NumpySolver whose step is compiled), so both compute the same numbers to
float32 rounding (tests/test_cpu_vs_numpy.py).
"""
from __future__ import annotations

import numpy as np

from feelflow.solver.backend import SolverDiverged
from feelflow.solver.inflow import INLET_DIRECTIONS, OUTLET_DIRECTIONS
from feelflow.solver.numpy_backend import NumpySolver, absorb_keep, relaxation_rates


def _bits(dirs) -> int:
    return sum(1 << int(i) for i in dirs)


class CpuSolver(NumpySolver):
    """D2Q9 solver compiled for the CPU with numba: NumpySolver's algorithm, fused kernels."""

    name = "cpu"

    def __init__(self, config):
        from feelflow.solver.cpu_kernels import make_kernels

        super().__init__(config)
        cfg = self.config
        #: the recursive-regularised operator is not compiled: it runs numpy's reference step
        #: (the same numbers, numpy's speed)
        self._reference_step = cfg.collision == "rr"
        if self._reference_step:
            return
        nx, ny = cfg.nx, cfg.ny
        op, om = relaxation_rates(cfg)
        dt = self.dtype  # the kernels compute in the storage's precision, as numpy's Collider
        self._op = np.broadcast_to(np.asarray(op, dt), (nx,)).copy()
        self._om = np.broadcast_to(np.asarray(om, dt), (nx,)).copy()
        keep = absorb_keep(cfg)
        self._keep = np.ones(nx, dt) if keep is None else np.asarray(keep, dt)
        # columns 1 .. xs-1 share column 1's rates and have no absorbing layer: the chunked,
        # vectorised part of the kernel; xs .. nx-1 (the sponge, the last column) node by node
        plain = (self._op == self._op[min(1, nx - 1)]) & (self._om == self._om[min(1, nx - 1)]) & (self._keep == 1.0)
        plain[0] = True
        xs = 1
        while xs < nx - 1 and plain[xs]:
            xs += 1
        self._xs = xs
        self._no_target = np.zeros(ny, dt)
        self._fx, self._fy = (dt.type(v) for v in cfg.body_force)
        self._stream_collide, self._redo_kernel = make_kernels(
            cfg.collision == "trt", bool(cfg.incompressible), keep is not None,
            tuple(cfg.body_force) != (0.0, 0.0), dt.name)
        self._pre = np.zeros_like(self.g)
        self._edge_bits = self._boundary_bits()
        self._mask_links = None
        self._redo = None

    def _boundary_bits(self) -> np.ndarray:
        """(ny, nx) uint16: bit i set where a domain boundary rule (c, d, b) writes population i."""
        cfg = self.config
        bits = np.zeros((cfg.ny, cfg.nx), np.uint16)
        if cfg.x_boundary == "tunnel":
            bits[:, 0] |= _bits(INLET_DIRECTIONS)
            bits[:, -1] |= _bits(OUTLET_DIRECTIONS)
        if cfg.y_boundary != "periodic":
            bits[0, :] |= _bits((2, 5, 6))
            bits[-1, :] |= _bits((4, 7, 8))
        return bits

    def _redo_nodes(self):
        """(iy, ix, bits) of every node a boundary rule or a body link touches, rebuilt when
        the body's links change."""
        b = self.body
        links = None if b is None else b.links
        if self._redo is not None and links is self._mask_links:
            return self._redo
        bits = self._edge_bits
        if links is not None and len(links):
            bits = bits.copy()
            np.bitwise_or.at(bits, (links.iy + b.window[1], links.ix + b.window[0]),
                             (1 << links.i.astype(np.int64)).astype(np.uint16))
        iy, ix = np.nonzero(bits)
        self._redo = (iy.astype(np.int64), ix.astype(np.int64), bits[iy, ix].astype(np.int64))
        self._mask_links = links
        return self._redo

    def _step_once(self) -> None:
        if self._reference_step:
            return NumpySolver._step_once(self)
        g, out, pre = self.g, self._gin, self._pre
        t = self.time
        u_in = self._boundaries(g, pre, t)
        target = self._no_target if u_in is None else np.asarray(u_in, self.dtype)
        rates = (self._op, self._om, self._keep, target)
        total = self._stream_collide(g, out, *rates, self._xs, self._fx, self._fy)
        iy, ix, bits = self._redo_nodes()
        if len(iy):
            total += self._redo_kernel(g, pre, bits, iy, ix, out, *rates, self._fx, self._fy)
        if self._solid_idx is not None:
            out[:, self._solid_idx[0], self._solid_idx[1]] = self._solid_g
        self.g, self._gin = out, g
        self.time = t + 1
        if not np.isfinite(total):
            raise SolverDiverged(t + 1, "density is no longer finite")
