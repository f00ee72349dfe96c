"""A texture-layout probe for the gl backend: two nodes per fragment (docs/performance.md).

Not used by the solver. It runs the `PAIRED` variant of `shaders/lbm_step.glsl`: the fast path
(plain streaming and the collision of `GLSolver`, the same code) on a fully periodic grid, with
nodes a = (2k, y) and b = (2k + 1, y) of one fragment kept in five RGBA32F textures of width
nx / 2. Directions with the same row offset share texels, so a fragment makes 12 texture fetches
and 5 writes for 2 nodes where `GLSolver` makes 9 and 3 for one. `feelflow bench --variants`
times it against `GLSolver` on the same box, and tests/test_gl_layout_probe.py checks that it
computes the same populations, so the figure measures a layout, not a different scheme.
"""
from __future__ import annotations

import moderngl
import numpy as np

from solver.backend import BackendError
from solver.numpy_backend import relaxation_rates
from solver.gl_programs import create_program
from solver.lattice import RHO0, W, equilibrium

#: texture t, channel c holds direction PAIRED_LAYOUT[t][c // 2] of node a (c even) or b (c odd)
PAIRED_LAYOUT = ((1, 3), (5, 6), (7, 8), (2, 4), (0, None))


class PairedLayoutProbe:
    """The fast path of a fully periodic `config` with two nodes per fragment."""

    def __init__(self, config, ctx: moderngl.Context):
        if config.x_boundary != "periodic" or config.y_boundary != "periodic" or config.nx % 2:
            raise BackendError("the layout probe runs fully periodic grids of even width only")
        if any(v != 0.0 for v in config.body_force) or config.sponge_cells:
            raise BackendError("the layout probe has no body force and no sponge")
        self.config, self.ctx = config, ctx
        self.nx, self.ny = config.nx, config.ny
        half = self.nx // 2
        defines = {"TRT": config.collision == "trt", "GUO_FORCE": False, "X_PERIODIC": True, "Y_MODE": 2,
                   "FETCH_NORMALIZED": 2, "DIVERGENCE_DISCARD": False, "BODY": False, "EDGES": False,
                   "SPONGE": False, "PAIRED": True}
        self.program = create_program(ctx, "rect_vertex.glsl", "lbm_step.glsl", defines)
        op, om = relaxation_rates(config)
        values = {"grid_size": (float(half), float(self.ny)), "inv_n": (1.0 / half, 1.0 / self.ny),
                  "omega_plus": float(np.ravel(op)[0]), "omega_minus": float(np.ravel(om)[0]),
                  **{f"G{t}": t for t in range(5)}}
        for name, value in values.items():
            if name in self.program:
                self.program[name].value = value
        self._objects = []
        self._sides = []
        for _ in range(2):
            texs = []
            for _ in range(5):
                t = ctx.texture((half, self.ny), 4, dtype="f4")
                t.filter = (moderngl.NEAREST, moderngl.NEAREST)
                t.repeat_x = t.repeat_y = True
                texs.append(t)
            fbo = ctx.framebuffer(color_attachments=texs)
            self._sides.append((texs, fbo))
            self._objects += texs + [fbo]
        corners = np.array([0, 0, half, 0, 0, self.ny, half, 0, half, self.ny, 0, self.ny], "f4")
        self._vbo = ctx.buffer(corners.tobytes())
        self._vao = ctx.vertex_array(self.program, [(self._vbo, "2f", "in_pos")])
        self._objects += [self._vbo, self._vao]
        self._cur = 0
        ux0, uy0 = config.initial_velocity
        shape = (self.ny, self.nx)
        self.set_distributions(equilibrium(np.full(shape, RHO0), np.full(shape, float(ux0)),
                                           np.full(shape, float(uy0))))

    def set_distributions(self, f: np.ndarray) -> None:
        """Upload populations f (9, ny, nx), stored shifted (f - w RHO0) in the paired layout."""
        g = (np.asarray(f, np.float64) - (W * RHO0)[:, None, None]).astype(np.float32)
        for t, pair in enumerate(PAIRED_LAYOUT):
            texel = np.zeros((self.ny, self.nx // 2, 4), np.float32)
            for slot, i in enumerate(pair):
                if i is not None:
                    texel[:, :, 2 * slot] = g[i, :, 0::2]
                    texel[:, :, 2 * slot + 1] = g[i, :, 1::2]
            self._sides[self._cur][0][t].write(texel.tobytes())

    def distributions(self) -> np.ndarray:
        """The populations f (9, ny, nx), float64, read back from the paired layout."""
        g = np.zeros((9, self.ny, self.nx), np.float32)
        for t, pair in enumerate(PAIRED_LAYOUT):
            raw = self._sides[self._cur][0][t].read()
            texel = np.frombuffer(raw, np.float32).reshape(self.ny, self.nx // 2, 4)
            for slot, i in enumerate(pair):
                if i is not None:
                    g[i, :, 0::2] = texel[:, :, 2 * slot]
                    g[i, :, 1::2] = texel[:, :, 2 * slot + 1]
        return g.astype(np.float64) + (W * RHO0)[:, None, None]

    def step(self, n: int = 1) -> None:
        """n steps, queued; `finish` waits for them."""
        for _ in range(n):
            src, dst = self._sides[self._cur], self._sides[1 - self._cur]
            for unit, tex in enumerate(src[0]):
                tex.use(unit)
            dst[1].use()
            self._vao.render(moderngl.TRIANGLES)
            self._cur = 1 - self._cur

    def finish(self) -> None:
        self.ctx.finish()

    def close(self) -> None:
        for obj in self._objects:
            obj.release()
        self._objects = []
