"""The momentum exchange summed on the GPU: the body's link sums instead of its window.

Momentum exchange (Ladd 1994; the Galilean-invariant form of Wen, Zhang, Tu, Wang & Fang,
J. Comput. Phys. 266 (2014) 161), from the stored post-collision populations g* = f* - w RHO0
and the incoming ones g_i^in that the step streams over each cut link (x, ib) (Bouzidi rule):
    S1 = sum -c_i (g*_ib(x) + g_i^in(x)),   S2 = sum -u_w (g*_ib(x) - g_i^in(x)),
    Galilean-invariant F = S1 + S2 + K + J,   classic F = S1 + K,
with the links' constant K = -2 RHO0 sum w_i c_i (what the sums of shifted populations leave
out) and the cover/uncover impulse J of the step's move: the numbers
solver/forces/momentum_exchange.py computes from the window, to float32 round-off of the sums.

Two ways to sum, chosen by the enabled force models (LINK_SUM_MODELS):
- one momentum exchange only: the step's own pass sums it while streaming the links and keeps
  the block's running total in texture G4's spare channels over the body window (lbm_step.glsl
  LINK_SUMS 1 Galilean-invariant, 2 classic; `read_pass_sums`): no extra pass, and a block
  reads those texels of one attachment;
- both exchanges, or the torque wanted (four sums and two moments a texel): a link-sum pass in
  the step's scene (LinkSums, shaders/link_sums.glsl) writes two RGBA32F texels of partial sums
  (attachments 0 and 1) per state texel with a cut link into the band area (solver/gl_band.py);
  a block reads those texels of two attachments.
"""
from __future__ import annotations

import math

import moderngl
import numpy as np

from feelflow.shapes.raster import distinct_sorted
from feelflow.solver.backend import SolverDiverged
from feelflow.solver.gl_layout import (G_NAMES, TEXTURES, UNIT_G, UNIT_LINKS, UNIT_MASK, UNIT_QA,
                                       UNIT_QB)
from feelflow.solver.gl_programs import create_program, set_uniforms, triangles
from feelflow.solver.lattice import C, RHO0, W

#: force models whose link sums the GPU computes
LINK_SUM_MODELS = frozenset({"momentum_exchange", "momentum_exchange_classic"})
#: lbm_step.glsl's LINK_SUMS where one momentum exchange is the only model (the step's pass sums it)
LINK_SUMS_OF_MODEL = {("momentum_exchange",): 1, ("momentum_exchange_classic",): 2}


def links_constant(links) -> tuple[float, float]:
    """K = -2 RHO0 sum w_i c_i over the body's links, per step."""
    i = links.i
    return tuple(-2.0 * RHO0 * (W[i, None] * C[i]).sum(axis=0)) if len(i) else (0.0, 0.0)


def links_constant_moment(body) -> float:
    """M_K: the moment of K's terms -2 RHO0 w_i c_i about the body's centre, each at its link's
    wall crossing x - q c_i, per step."""
    links = body.links
    i = links.i
    if not len(i):
        return 0.0
    k = -2.0 * RHO0 * W[i, None] * C[i]
    rx = body.window[0] + links.ix - links.q * C[i, 0] - body.shape.x
    ry = body.window[1] + links.iy - links.q * C[i, 1] - body.shape.y
    return float(np.sum(rx * k[:, 1] - ry * k[:, 0]))


class LinkSums:
    """The link-sum pass (shaders/link_sums.glsl) for one body state and band-slot layout.

    texels: (n, 2) the state texels (k, y) that hold a cut link; `table` lists them packed row
    by row, (k, y, 1, 0) each, in a texture as wide as a slot; the vertex array draws, per slot,
    one rectangle over the rows the list takes (a software rasteriser pays per primitive, so not
    a point per texel). List entry j lands on texel (j % ww, j // ww) of its slot.
    """

    def __init__(self, ctx, kx: int, nx: int, ny: int, tex_size):
        self.ctx, self.kx, self.ny = ctx, kx, ny
        self.prog = create_program(ctx, "rect_vertex.glsl", "link_sums.glsl")
        set_uniforms(self.prog, **dict(zip(G_NAMES, UNIT_G)), MASK=UNIT_MASK, QA=UNIT_QA, QB=UNIT_QB,
                     LINK_TEXELS=UNIT_LINKS, N=(nx, ny), grid_size=(float(tex_size[0]), float(ny)))
        self.vao = self.vbo = self.table = None
        self.layout = None
        self.texels = np.zeros((0, 2), np.int64)
        self.body = None
        self.rows = 0  # rows of the slots the rectangles cover (rewritten only when this changes)

    def update(self, body, layout) -> bool:
        """List the texels with links of `body` for the band layout (cols, ww, wh). The list
        texture and rectangles are made once per layout and rewritten when the set of texels
        changes (at a move, when llvmpipe's queue is empty: a write to a texture a queued step
        reads would wait). Returns True where a new vertex array was made."""
        links = body.links
        x0w, y0w = body.window[:2]
        key = distinct_sorted((y0w + links.iy) * self.kx + (x0w + links.ix) // 2)  # sorted by (y, k)
        texel = np.stack([key % self.kx, key // self.kx], axis=1)
        if self.layout == layout and np.array_equal(self.texels, texel):
            self.body = body  # the same list: keep it
            return False
        new = self.layout != layout
        cols, ww, wh = layout
        if new:
            self._release_draw()
            self.table = self.ctx.texture((ww, wh), 4, dtype="f4")  # the list never outgrows the window
            self.table.filter = (moderngl.NEAREST, moderngl.NEAREST)
            self.vbo = self.ctx.buffer(reserve=cols * (self.ny // wh) * 6 * 2 * 4)
            self.vao = self.ctx.vertex_array(self.prog, [(self.vbo, "2f", "in_pos")])
            self.layout, self.texels, self.rows = layout, texel[:0], 0
        rows = max(1, -(-len(texel) // ww))
        entries = np.zeros((rows * ww, 4), "f4")
        entries[:len(texel), :2] = texel
        entries[:len(texel), 2] = 1.0
        self.table.write(entries.tobytes(), viewport=(0, 0, ww, rows))
        if rows != self.rows:
            slots = [(self.kx + c * ww, r * wh, self.kx + (c + 1) * ww, r * wh + rows)
                     for r in range(self.ny // wh) for c in range(cols)]
            self.vbo.write(triangles(slots).tobytes())
            self.rows = rows
        self.texels, self.body = texel, body
        return new

    def draw(self, slot: int, origin) -> None:
        """Sum the links of the bound source state into slot `slot` (lower-left texel `origin`)
        of the bound target."""
        if len(self.texels):
            self.table.use(location=UNIT_LINKS)
            self.prog["slot_origin"].value = origin
            self.vao.render(moderngl.TRIANGLES, vertices=6, first=6 * slot)

    def forces(self, fbos, sides, bands: int, models, impulses, t0: int):
        """Each step's forces and torques {model: (fx, fy, torque)} from its slot of link sums in
        the band areas (step b: slot b // 2 of side sides[b % 2]; attachments 0 (sums) and 1
        (moments) of `fbos[side]`, summed in float64), plus K (and its moment) and,
        Galilean-invariant, the step's impulse. Returns (forces per step, the first step whose
        sums are not finite or None)."""
        cols, ww, wh = self.layout
        rows, cols_ = np.divmod(np.arange(len(self.texels)), ww)  # list entry j in its slot
        k_x, k_y = links_constant(self.body.links)
        m_k = links_constant_moment(self.body)
        sums = np.empty((bands, 6))
        for first in (0, 1):  # the steps whose slots side sides[first] holds: first, first + 2, ...
            band = np.arange(first, bands, 2)
            if not len(band):
                continue
            slot = band // 2
            h = -(-(int(slot[-1]) + 1) // cols) * wh  # the rows of the band area those slots use
            at = ((slot // cols * wh)[:, None] + rows, (slot % cols * ww)[:, None] + cols_)
            for attachment, channels in ((0, slice(0, 4)), (1, slice(4, 6))):
                data = fbos[sides[first]].read(viewport=(self.kx, 0, cols * ww, h), components=4,
                                               attachment=attachment, dtype="f4")
                area = np.frombuffer(data, dtype="f4").reshape(h, cols * ww, 4)
                texels = area[at][..., :channels.stop - channels.start]
                sums[band, channels] = texels.sum(axis=1, dtype=np.float64)  # each step's in float64
        finite = np.isfinite(sums).all(axis=1)
        good = bands if finite.all() else int(np.argmin(finite))
        out = []
        for b in range(good):
            s = sums[b]
            forces = {}
            if "momentum_exchange" in models:
                forces["momentum_exchange"] = (float(s[0] + s[2] + k_x + impulses[b][0]),
                                               float(s[1] + s[3] + k_y + impulses[b][1]),
                                               float(s[4] + s[5] + m_k))
            if "momentum_exchange_classic" in models:
                forces["momentum_exchange_classic"] = (float(s[0] + k_x), float(s[1] + k_y),
                                                       float(s[4] + m_k))
            out.append(forces)
        return out, (None if good == bands else t0 + good)

    def _release_draw(self) -> None:
        for obj in (self.vao, self.vbo, self.table):
            if obj is not None:
                obj.release()
        self.vao = self.vbo = self.table = None

    def release(self) -> None:
        self._release_draw()
        self.prog.release()


def read_pass_sums(fbo, rects) -> np.ndarray:
    """The running total of link sums (LINK_SUMS) in `fbo`'s state: channels zw of texture G4
    over the body variant's rectangles, summed in float64."""
    total = np.zeros(2)
    for x0, y0, x1, y1 in rects:
        data = fbo.read(viewport=(x0, y0, x1 - x0, y1 - y0), components=4, attachment=TEXTURES - 1, dtype="f4")
        total += np.frombuffer(data, dtype="f4").reshape(-1, 4)[:, 2:].sum(axis=0, dtype=np.float64)
    return total


def pass_sums_forces(total, mode: int, links, bands: int, impulses, step: int) -> dict:
    """The force summed over a block's `bands` steps from the step pass's running total (mode
    1: Galilean-invariant S1 + S2 per step, 2: classic S1), plus K each step and,
    Galilean-invariant, each step's impulse; {model: (fx, fy, torque)}, the torque NaN (the
    pass has no channel left for it: the backend takes the link-sum pass where a torque is wanted). Non-finite sums raise SolverDiverged at `step`, the
    block's end, which the caller replays to find the step."""
    if not np.all(np.isfinite(total)):
        raise SolverDiverged(step, "non-finite populations around the body")
    k_x, k_y = links_constant(links)
    fx, fy = float(total[0] + bands * k_x), float(total[1] + bands * k_y)
    if mode == 2:
        return {"momentum_exchange_classic": (fx, fy, math.nan)}
    return {"momentum_exchange": (fx + sum(j[0] for j in impulses), fy + sum(j[1] for j in impulses), math.nan)}
