"""The fragment-shader backend: docs/science/algorithm.md in GLSL 330 core, run through moderngl.

`GLSolver(config, ctx=moderngl_context)` implements `feelflow.solver.backend.Solver` with the same extra
methods as the numpy reference (`add_force_model`, `body_window`). It never
creates a GL context: the CLI and the tests hand it an EGL standalone one, the window Qt's.
Arithmetic is float32 whatever `config.dtype` says.

State on the GPU: the shifted post-collision populations g_i = f*_i - w_i RHO0, two nodes per
texel in five RGBA32F textures per side (solver/gl_layout.py; three sides: see 'Steps run in
blocks' below), written by one fused collide+stream pass through five colour attachments (MRT),
each fragment updating the two nodes of its texel. llvmpipe executes both sides of a
divergent branch, so the step is drawn as rectangles, each with the variant of
`shaders/lbm_step.glsl` it needs: the interior (plain streaming, the fast path), the edge rows
and columns (walls, inlet, outlet, wrap), and the body window (Bouzidi links, solid nodes).

Body: a node mask (R32UI: bit 0 solid, bit i when q[OPP[i], x] > 0, bit 8+i when that link
takes the two-node interpolation) and the link fractions q (two RGBA32F: q[1..4], q[5..8]) are
uploaded in `set_body` only, and only over the union of the old and new body windows. Wall
velocities come from uniforms (V, Omega, centre). Refill, impulses and every force model run on
the CPU on the read-back body window, with the numpy reference's code (`solver/body.py`,
`solver/bouzidi.py`, `solver/forces/`): the windows of a block of steps are read at once.

API for the app (a QOpenGLWidget sharing this context):
- `field_texture()` -> moderngl.Texture, nx x ny, RGBA32F = (rho, ux, uy, vorticity), computed
  by a pass only when called (u as `Solver.macroscopic`; vorticity duy/dx - dux/dy by central
  differences). NEAREST filtering; bind it with `.use(location=k)` in your own draw.
- `grid_size` -> (nx, ny); `renderer` -> the GL renderer string; `finish()` waits for the GPU.
- Every pass sets the state it needs: `ctx.enable_only(moderngl.NOTHING)` (Qt enters paintGL
  with blending on), no scissor, its own framebuffer and viewport, and binds every texture unit
  it samples (units 0..10) right before drawing. Nothing is restored: after `step()` or
  `field_texture()` the bound framebuffer is the solver's, so a paintGL must re-bind its own
  (`ctx.detect_framebuffer(self.defaultFramebufferObject()).use()`) and its own textures.
- Steps run in blocks of up to CHECK_EVERY (32) steps with nothing read back inside a block
  (every read drains llvmpipe's queue). With forces, the pass of each step also copies the body
  window of its source state (f*(t), what the forces of step t use) into a slot of the *band
  area*: BAND_WIDTH columns right of the lattice in every state texture, so the lattice's
  textures are nx + BAND_WIDTH wide for tunnels. One pass a step keeps llvmpipe at one scene a
  step (a separate copy pass into an atlas, which x-periodic grids, whose texture must be nx
  wide for the REPEAT wrap, and windows wider than the band area still use, cost the moving
  tunnel 25-30 %: docs/science/performance.md). At the end of the block a pass sums texture G0 (g0 of
  both nodes of a texel) of the final state over tiles (`shaders/finite_check.glsl`; NaN reaches
  every population of the neighbours within a step, so a NaN never vanishes from the fluid) and the windows and sums are read once. A non-finite sum
  replays the block from its start state, which a third state side keeps, with a check after
  every step: `feelflow.solver.backend.SolverDiverged` names the exact step, as in the reference; a
  non-finite body window raises it with the step of that window.
- Where the only force models are the momentum exchanges (LINK_SUM_MODELS; tuning
  forces="gpu", the default), their links are summed on the GPU instead of copying the window.
  With one exchange, the step's pass sums them as it streams them and keeps the block's running
  total in G4's two spare channels over the body window (lbm_step.glsl LINK_SUMS,
  `_read_pass_sums`): a block reads those texels of one attachment, and a step draws no extra
  pass. With both (four sums a texel), a link-sum pass in the step's scene writes them into the
  band area (`shaders/link_sums.glsl`: one RGBA32F texel of partial sums per state texel with a
  cut link, from a packed list, `LinkSums`; tuning forces="pass" takes it for one exchange too),
  and a block reads back those texels of one attachment of the band area instead of the
  window's five; the sums are the
  Galilean-invariant and classic momentum exchange of solver/forces/momentum_exchange.py, from
  the same stored populations and the same Bouzidi rule as the step (forces="window": the
  window and the models' own code, as for every other model). (An occlusion query counting
  fragments that a non-finite node discards, tuning divergence="discard", halved the step's
  speed on llvmpipe: docs/science/performance.md.)
"""
from __future__ import annotations

from dataclasses import dataclass

import moderngl
import numpy as np

from feelflow.shapes.raster import distinct_sorted
from feelflow.solver.backend import BackendError, Solver, SolverDiverged
from feelflow.solver.body import expand_box, move_body, shifted, union_box, unshifted
from feelflow.solver.forces.base import BodyWindow
from feelflow.solver.gl_layout import TEXTURES, pack, texel_box, texels, unpack
from feelflow.solver.gl_programs import create_program
from feelflow.solver.inflow import inlet_wall_profile, profile, ramp
from feelflow.solver.lattice import C, OPP, Q, RHO0, W, equilibrium
from feelflow.solver.numpy_backend import absorb_keep, relaxation_rates

#: texture units (fixed; every pass binds all it samples)
UNIT_G = tuple(range(TEXTURES))
UNIT_MASK, UNIT_QA, UNIT_QB, UNIT_INFLOW, UNIT_OMEGA, UNIT_LINKS = 5, 6, 7, 8, 9, 10
#: sampler uniforms of the population textures
G_NAMES = tuple(f"G{t}" for t in range(TEXTURES))
#: region rectangles are aligned to llvmpipe's 4x4 shading blocks
ALIGN = 4
#: steps whose divergence checks and force windows are read back together (one GPU sync)
CHECK_EVERY = 32
#: width in nodes of the band area right of the lattice in each state texture (tuning
#: window="state"): each step's draw copies the body window of its source state into a slot there
BAND_WIDTH = 128
#: force models whose link sums the step's pass computes on the GPU (shaders/link_sums.glsl)
LINK_SUM_MODELS = frozenset({"momentum_exchange", "momentum_exchange_classic"})
#: lbm_step.glsl's LINK_SUMS where one momentum exchange is the only model (the step's pass sums it)
LINK_SUMS_OF_MODEL = {("momentum_exchange",): 1, ("momentum_exchange_classic",): 2}
_Y_MODE = {"no_slip": 0, "free_slip": 1, "periodic": 2}


@dataclass
class LinkSums:
    """The link sums' draw (shaders/link_sums.glsl) for one body state and band-slot layout.

    texels: (n, 2) the state texels (k, y) that hold a cut link; `table` lists them packed row
    by row, (k, y, 1, 0) each, in a texture as wide as a slot; `vao` draws, per slot, one
    rectangle over the rows the list takes (llvmpipe pays per primitive, so not a point per
    texel: docs/science/performance.md). List entry j lands on texel (j % ww, j // ww) of its slot.
    """

    vao: object
    vbo: object
    table: object
    texels: np.ndarray
    layout: tuple
    body: object
    rows: int = 0  # rows of the slots the rectangles cover (rewritten only when this changes)

    def release(self) -> None:
        for obj in (self.vao, self.vbo, self.table):
            obj.release()


def _tile_block(nx: int) -> tuple[int, int]:
    """(BLOCK_X, BLOCK_Y) of the finite check: 256 nodes a tile, at least 128 tiles across
    (two of llvmpipe's 64-pixel bins, so both threads reduce) where the grid allows."""
    bx = 1
    while bx < 16 and -(-nx // (2 * bx)) >= 128:
        bx *= 2
    return bx, 256 // bx


def _triangles(rects) -> np.ndarray:
    """Two triangles per rectangle, texel-edge coordinates, float32 (k*6, 2)."""
    out = []
    for x0, y0, x1, y1 in rects:
        out += [(x0, y0), (x1, y0), (x1, y1), (x0, y0), (x1, y1), (x0, y1)]
    return np.asarray(out, dtype="f4").reshape(-1, 2)


def node_mask(solid: np.ndarray, q: np.ndarray, box, links=None, window=None) -> np.ndarray:
    """The shader's node mask over box (x0, y0, x1, y1), uint32 (h, w), from `solid` (h, w) and
    `q` (9, h, w) cut to that box (BodyRaster.crop).

    bit 0: solid; bit i (1..8): q[OPP[i], x] > 0 (rule 1a for f_i^in); bit 8+i: the link takes
    the two-node interpolation (q < 1/2 and a fluid second node x + c_i): set from the body's
    `links` (solver.bouzidi, built on the force `window` (x0, y0, ...)), so that both backends
    make the same choice, across a periodic seam too (the shader takes the second node's
    population as streamed, which wraps there).
    """
    x0, y0, x1, y1 = box
    cut = (q[OPP[1:]] > 0) & ~solid  # cut[i - 1]: bit i
    mask = solid.astype(np.uint32) | np.bitwise_or.reduce(
        cut.astype(np.uint32) << np.arange(1, Q, dtype=np.uint32)[:, None, None], axis=0)
    if links is not None and len(links):
        two = links.b != 0
        ys, xs = links.iy[two] + window[1] - y0, links.ix[two] + window[0] - x0
        inside = (ys >= 0) & (ys < y1 - y0) & (xs >= 0) & (xs < x1 - x0)
        bits = np.left_shift(np.uint32(1), (8 + links.i[two][inside]).astype(np.uint32))
        np.bitwise_or.at(mask, (ys[inside], xs[inside]), bits)
    return mask


class GLSolver(Solver):
    """docs/science/algorithm.md on the GPU (fragment shaders), float32; see the module docstring."""

    name = "gl"
    #: default tuning (docs/science/performance.md measures each choice). forces: "gpu", the momentum
    #: exchanges' link sums on the GPU (one model: summed by the step's own pass into G4's spare
    #: channels; both: by the link-sum pass into the band area), "pass" (always that pass) or
    #: "window" (the body window copied and every model's own code)
    TUNING = {"split": True, "divergence": "tiles", "check_every": CHECK_EVERY, "window": "state",
              "draw": "scissor", "forces": "gpu"}
    #: called once per block of steps after its draws are queued and before its results are
    #: read back (llvmpipe still busy with the queued steps); None in normal use. `feelflow bench
    #: --variants` puts CPU work there to measure what overlapping it with the GPU gains.
    before_read = None

    def __init__(self, config, ctx=None, tuning: dict | None = None):
        super().__init__(config)
        if ctx is None or not isinstance(ctx, moderngl.Context):
            raise BackendError("the gl backend needs a moderngl.Context (ctx=); it never creates one")
        self.ctx = ctx
        self.tuning = {**self.TUNING, **(tuning or {})}
        cfg = self.config
        nx, ny = cfg.nx, cfg.ny
        self.nx, self.ny = nx, ny
        self.renderer = ctx.info.get("GL_RENDERER", "?")
        sponge = cfg.x_boundary == "tunnel" and cfg.sponge_cells > 0
        defines = {
            "TRT": cfg.collision == "trt",
            "INCOMPRESSIBLE": cfg.incompressible,
            "GUO_FORCE": any(c != 0.0 for c in cfg.body_force),
            "X_PERIODIC": cfg.x_boundary == "periodic",
            "Y_MODE": _Y_MODE[cfg.y_boundary],
            "NX_ODD": nx % 2 == 1,
            "DIVERGENCE_DISCARD": self.tuning["divergence"] == "discard",
        }
        self._defines = defines
        self._sponge = sponge
        self._programs = {}
        op, om = relaxation_rates(cfg)
        # texels: the lattice's ceil(nx / 2) columns, then (tunnels, window="state") the band
        # area; an x-periodic grid's texture is exactly the lattice (REPEAT wraps it)
        self._kx = texels(nx)
        self._band_w = (texels(min(nx, BAND_WIDTH)) if self.tuning["window"] == "state"
                        and cfg.x_boundary != "periodic" else 0)
        self._tex_size = (self._kx + self._band_w, ny)
        tex_w = float(self._tex_size[0])
        self._uniform_values = dict(
            **dict(zip(G_NAMES, UNIT_G)), MASK=UNIT_MASK, QA=UNIT_QA, QB=UNIT_QB,
            INFLOW=UNIT_INFLOW, OMEGA=UNIT_OMEGA, N=(nx, ny), grid_size=(tex_w, float(ny)),
            inv_n=(1.0 / tex_w, 1.0 / ny), body_force=tuple(float(v) for v in cfg.body_force),
            omega_plus=float(np.ravel(op)[0]), omega_minus=float(np.ravel(om)[0]))  # column 0: no sponge
        self._objects = []  # GL objects to release

        def tex(size, components, dtype="f4", repeat=False):
            t = ctx.texture(size, components, dtype=dtype)
            t.filter = (moderngl.NEAREST, moderngl.NEAREST)
            t.repeat_x = t.repeat_y = repeat
            self._objects.append(t)
            return t

        # three sides: two ping-pong within a block of steps, the third keeps the block's start
        # state, from which a block whose final state is not finite is replayed step by step
        self._g = [[tex(self._tex_size, 4, repeat=True) for _ in range(TEXTURES)] for _ in range(3)]
        self._fbo = [ctx.framebuffer(color_attachments=side) for side in self._g]
        self._objects += self._fbo
        self._cur = 0  # the side holding f*(t)
        self._mask_tex = tex((nx, ny), 1, "u4")
        self._qa_tex, self._qb_tex = tex((nx, ny), 4), tex((nx, ny), 4)
        self._mask_tex.write(np.zeros((ny, nx), "u4"))
        self._qa_tex.write(np.zeros((ny, nx, 4), "f4"))
        self._qb_tex.write(np.zeros((ny, nx, 4), "f4"))
        self._inflow_tex = tex((ny, 1), 4)  # row profile, rule c's three inlet links
        self._omega_tex = tex((nx, 1), 3)
        keep = absorb_keep(cfg)
        rates = np.stack(np.broadcast_arrays(np.asarray(op, float) * np.ones(nx), np.asarray(om, float),
                                             np.ones(nx) if keep is None else keep), -1)
        self._omega_tex.write(rates.astype("f4").tobytes())
        self._inflow_key = None
        self._draws, self._draw_regions = [], None  # [(vertex array, scissor boxes or None)]
        self._vaos = {}  # region key -> (vertex array, vbo), made on first use
        self._fragments_per_step = 0
        self._field = None
        self._discard = self.tuning["divergence"] == "discard"
        # divergence checks and force windows of up to CHECK_EVERY steps, read back at once
        self._tile_block = _tile_block(self._kx)
        self._tile_grid = (-(-self._kx // self._tile_block[0]), -(-ny // self._tile_block[1]))
        self._atlas, self._check_progs = None, None
        self._check_every = max(1, min(CHECK_EVERY, int(self.tuning["check_every"])))
        self._window_mode = self.tuning["window"]
        self._band_copy = None  # (vao, vbo, slot layout) of the window copy into the band area
        self._band_sums = None  # LinkSums: the link sums' draw (LINK_SUM_MODELS)
        self._block_sums = False  # the block being drawn sums links instead of copying windows
        self._link_sums = 0  # lbm_step.glsl LINK_SUMS of the body variant: 0, 1 Galilean, 2 classic
        self._sums_keep = None  # the body programs' sums_keep uniform as last set
        self._pending, self._idle_queries = [], []  # divergence="discard": (step, query)

        self._impulse = (0.0, 0.0)
        self._set_rects(None)
        self._upload_body_uniforms()
        ux0, uy0 = cfg.initial_velocity
        self.set_distributions(equilibrium(np.full((ny, nx), RHO0), np.full((ny, nx), float(ux0)),
                                           np.full((ny, nx), float(uy0))))

    # --- helpers ----------------------------------------------------------------
    @staticmethod
    def _uniforms(prog, **values):
        for name, value in values.items():
            if name in prog:  # the compiler drops unused uniforms
                prog[name].value = value

    def _program(self, key):
        """The step variant for region `key` = (body, edges, sponge), compiled on first use; the
        body variants with the current link-sum mode (self._link_sums)."""
        body, edges, sponge = key
        link = self._link_sums if body else 0
        if (key, link) not in self._programs:
            defines = {**self._defines, "BODY": body, "EDGES": edges, "SPONGE": sponge, "LINK_SUMS": link}
            prog = create_program(self.ctx, "rect_vertex.glsl", "lbm_step.glsl", defines)
            self._uniforms(prog, **self._uniform_values)
            self._programs[(key, link)] = prog
            if body:
                self._upload_body_uniforms()
        return self._programs[(key, link)]

    def _regions(self, window):
        """{(body, edges, sponge): [rectangles]}: which variant draws which part of the grid.

        Rectangles are aligned to llvmpipe's 4x4 pixel blocks (a partly covered block runs the
        whole shader), so the edge strips are ALIGN wide and the body window is grown to them.
        The body window is drawn last, over the fast path or edge strip beneath it (its variant
        writes every texel it covers; _set_rects draws the keys in order, body keys last): one
        rectangle per variant instead of the interior cut into four around the window, and the
        other regions stay the same as the body moves (docs/science/performance.md, tenth session).
        """
        nx, ny, a = self._kx, self.ny, ALIGN  # texel columns
        if window is not None:
            window = texel_box(window)
        sp = int(self._sponge)
        x1, y1 = (nx - 1) // a * a, (ny - 1) // a * a
        if not self.tuning["split"] or x1 <= a or y1 <= a:
            return {(1, 1, sp): [(0, 0, nx, ny)]}
        if self._wraps_free():  # periodic box: REPEAT samplers wrap, the fast path does the edges
            parts = {(0, 0, 0): [(0, 0, nx, ny)]}
            if window is not None and window[0] < window[2] and window[1] < window[3]:
                w = (window[0] // a * a, window[1] // a * a, min(nx, -(-window[2] // a) * a),
                     min(ny, -(-window[3] // a) * a))
                parts[(1, 0, 0)] = [w]
            return parts
        interior = (a, a, x1, y1)
        edges = [(0, 0, nx, a), (0, y1, nx, ny), (0, a, a, y1), (x1, a, nx, y1)]
        parts = {(0, 0, 0): [interior], (0, 1, sp): edges}
        if window is not None and window[0] < window[2] and window[1] < window[3]:
            w = (window[0] // a * a, window[1] // a * a, min(nx, -(-window[2] // a) * a),
                 min(ny, -(-window[3] // a) * a))
            inside = w[0] >= a and w[1] >= a and w[2] <= x1 and w[3] <= y1
            parts[(1, 0, sp) if inside else (1, 1, sp)] = [w]
        if sp:  # the sponge columns (aligned down) get the variant with per-column rates
            xs = (self.nx - self.config.sponge_cells) // 2 // a * a
            plain, sponge = [], []
            for r in parts[(0, 0, 0)]:
                if r[0] < xs:
                    plain.append((r[0], r[1], min(r[2], xs), r[3]))
                if r[2] > xs:
                    sponge.append((max(r[0], xs), r[1], r[2], r[3]))
            parts[(0, 0, 0)], parts[(0, 0, 1)] = plain, sponge
        return {k: v for k, v in parts.items() if v}

    def _wraps_free(self) -> bool:
        """Both directions periodic, an even nx (whole texels), streamed through REPEAT
        samplers: no edge rules at all."""
        d = self._defines
        return bool(d["X_PERIODIC"] and d["Y_MODE"] == 2 and self.nx % 2 == 0 and not self._sponge)

    def _set_rects(self, window):
        """Draws of every region (see _regions), in key order each step, so the body window's
        variant (key[0] = 1) comes last, over what is beneath it; kept when the (block-aligned)
        regions did not change. Default (tuning draw="scissor"): per rectangle, one triangle
        covering the texture, clipped by the scissor box to the rectangle, so every 4x4 block
        inside is fully covered, and a move changes only the body window's scissor box; drawn
        as two triangles (draw="triangles"), the 4x4 blocks along the diagonal are shaded twice,
        once per triangle, which doubles the cost of the 4-texel edge strips
        (docs/science/performance.md)."""
        regions = sorted(self._regions(window).items())
        if regions == self._draw_regions:
            return
        self._draw_regions = regions
        # fragments each step writes (the body window twice): the occlusion count to expect
        self._fragments_per_step = sum((x1 - x0) * (y1 - y0) for _, rects in regions for x0, y0, x1, y1 in rects)
        w, h = self._tex_size
        draws = []
        scissor = self.tuning["draw"] == "scissor"
        self._body_rects = []  # the body variant's rectangles: where LINK_SUMS keeps its totals
        for key, rects in regions:
            # scissor: one triangle over the texture, the same for every variant and pose
            data = _triangles([(0, 0, 2 * w, 2 * h)])[[0, 1, 5]] if scissor else _triangles(rects)
            vkey = (key, self._link_sums if key[0] else 0)
            if vkey not in self._vaos:
                vbo = self.ctx.buffer(data.tobytes())
                self._vaos[vkey] = (self.ctx.vertex_array(self._program(key), [(vbo, "2f", "in_pos")]), vbo)
            elif not scissor:
                vao, vbo = self._vaos[vkey]
                vbo.orphan(data.nbytes)
                vbo.write(data.tobytes())
                vao.vertices = len(data)
            draws.append((self._vaos[vkey][0], rects if scissor else None))
            if key[0]:
                self._body_rects += rects
        self._draws = draws
        self._sums_keep = None

    def _link_sum_mode(self) -> int:
        """lbm_step.glsl's LINK_SUMS for the enabled models: 1 (2) where the Galilean-invariant
        (classic) momentum exchange is the body's only force model and tuning forces="gpu"; 0 else
        (both exchanges: the link-sum pass; other models: the window; divergence="discard" keeps
        no replay to find a bad step's sums)."""
        if self.tuning["forces"] != "gpu" or self.body is None or self._discard:
            return 0
        return LINK_SUMS_OF_MODEL.get(tuple(self._models), 0)

    def _use_link_sum_mode(self, mode: int) -> None:
        """Switch the body variant's LINK_SUMS (its programs and vertex arrays are kept per mode)."""
        if mode != self._link_sums:
            self._link_sums = mode
            self._draw_regions = None
            self._set_rects(None if self.body is None else self.body.raster.window)

    def _set_sums_keep(self, keep: float) -> None:
        if keep != self._sums_keep:
            for (key, link), prog in self._programs.items():
                if key[0] and link:
                    self._uniforms(prog, sums_keep=keep)
            self._sums_keep = keep

    def _render_regions(self):
        for vao, scissors in self._draws:
            if scissors is None:
                vao.render(moderngl.TRIANGLES)
                continue
            for x0, y0, x1, y1 in scissors:
                self.ctx.scissor = (x0, y0, x1 - x0, y1 - y0)
                vao.render(moderngl.TRIANGLES, vertices=3)
        self.ctx.scissor = None

    def _upload_body_uniforms(self):
        b = self.body
        centre = (0.0, 0.0) if b is None else (float(b.shape.x), float(b.shape.y))
        velocity = (0.0, 0.0) if b is None else tuple(float(v) for v in b.velocity)
        omega = 0.0 if b is None else float(b.omega)
        for (key, _), prog in self._programs.items():
            if key[0]:
                self._uniforms(prog, body_velocity=velocity, body_omega=omega, body_centre=centre)
        if self._band_sums is not None:
            window = (0, 0, 0, 0) if b is None else tuple(int(v) for v in b.window)
            self._uniforms(self._band_sums.vao.program, body_velocity=velocity, body_omega=omega,
                           body_centre=centre, window=window)

    def _update_inflow(self, t):
        """u_in(iy, t) = ramp(t) profile(iy) (solver/inflow.py): the ramp as a uniform each
        step, the profile texture (r: the row, gba: rule c's links 1, 5, 8, inlet_wall_profile)
        rewritten only when the speed changes (a texture write while
        a queued step reads it would stall the pipeline)."""
        cfg = self.config
        if cfg.x_boundary != "tunnel":
            return
        if self._inflow_key != self.inflow_speed:
            self._inflow_key = self.inflow_speed
            rows = profile(cfg.ny, self.inflow_speed, cfg.inflow_profile)
            links = inlet_wall_profile(cfg.ny, self.inflow_speed, cfg.inflow_profile)
            self._inflow_tex.write(np.stack([rows, *links], -1).astype("f4").tobytes())
        r = float(ramp(t, cfg.inflow_ramp_steps))
        if self._uniform_values.get("inflow_ramp") != r:  # constant once the ramp is over
            self._uniform_values["inflow_ramp"] = r  # also for programs compiled later
            for (key, _), prog in self._programs.items():
                if key[1] or key[2]:  # edges (the inlet), sponge (the absorbing layer's target)
                    self._uniforms(prog, inflow_ramp=r)

    def _begin_pass(self, fbo, size):
        """The state every pass needs, whatever the host (Qt) left: see the module docstring."""
        ctx = self.ctx
        ctx.enable_only(moderngl.NOTHING)
        ctx.scissor = None
        fbo.use()
        ctx.viewport = (0, 0, *size)

    def _bind_sources(self, side):
        for unit, texture in zip(UNIT_G, self._g[side]):
            texture.use(location=unit)
        self._mask_tex.use(location=UNIT_MASK)
        self._qa_tex.use(location=UNIT_QA)
        self._qb_tex.use(location=UNIT_QB)
        self._inflow_tex.use(location=UNIT_INFLOW)
        self._omega_tex.use(location=UNIT_OMEGA)

    # --- stepping ---------------------------------------------------------------
    def _draw_step(self, dst: int, slot: int | None = None):
        """Queue step t -> t+1 from the current side into side `dst`; with `slot`, the same
        pass copies the body window of the current side (f*(t), what the forces of step t use)
        into that slot of dst's band area (one llvmpipe scene per step, not two)."""
        self._update_inflow(self.time)
        self._begin_pass(self._fbo[dst], self._tex_size)
        self._bind_sources(self._cur)
        if self._discard:
            query = self._idle_queries.pop() if self._idle_queries else self.ctx.query(samples=True)
            with query:
                self._render_regions()
        else:
            self._render_regions()
        if slot is not None:
            vao, _, (cols, ww, wh) = self._band_copy
            if self._block_sums:  # the link sums over the list of texels with links
                sums = self._band_sums
                if len(sums.texels):
                    sums.table.use(location=UNIT_LINKS)
                    sums.vao.program["slot_origin"].value = (self._kx + (slot % cols) * ww, (slot // cols) * wh)
                    sums.vao.render(moderngl.TRIANGLES, vertices=6, first=6 * slot)
            else:
                k0, y0 = texel_box(self.body.window)[:2]
                vao.program["shift"].value = (k0 - self._kx - (slot % cols) * ww, y0 - (slot // cols) * wh)
                vao.render(moderngl.TRIANGLES, vertices=6, first=6 * slot)
        self._cur = dst
        self.time += 1
        if self._discard:
            self._pending.append((self.time, query))

    def step(self, n: int = 1) -> None:
        """Steps in blocks of up to `check_every`: nothing is read back inside a block (a read
        drains llvmpipe's queue). Per step, with forces, one pass copies the body window into
        the check atlas; at the end of the block the final state's tile sums are queued and the
        atlas read once. A non-finite final state replays the block from its start state (kept
        in the third side) with a check after every step, so SolverDiverged names the exact step."""
        n = int(n)
        sums = {name: [0.0, 0.0] for name in self._models}
        done = 0
        self._use_link_sum_mode(self._link_sum_mode())
        while done < n:
            with_forces = bool(self._models) and self.body is not None
            in_pass = with_forces and self._link_sums > 0  # the step's own pass sums the links
            slots = self._band_slots() if with_forces and not in_pass else 0
            k = min(n - done, self._check_every, self._ensure_atlas(with_forces and not slots and not in_pass))
            if slots:
                k = min(k, 2 * slots)
            t0, start, impulses = self.time, self._cur, []
            others = [side for side in range(3) if side != start]
            self._block_sums = bool(slots) and self._sums_forces()
            read_now = []  # tuning window="read": each window read right after its step is queued
            for band in range(k):
                impulses.append(self._impulse)
                self._impulse = (0.0, 0.0)
                src = self._cur
                if in_pass:
                    self._set_sums_keep(0.0 if band == 0 else 1.0)
                self._draw_step(others[band % 2], band // 2 if slots else None)
                if slots or in_pass:
                    continue
                if with_forces and self._window_mode == "read":
                    read_now.append(self._window(src, impulses[-1]))
                    if not np.all(np.isfinite(read_now[-1].f)):
                        raise SolverDiverged(self.time - 1, "non-finite populations around the body")
                elif with_forces:
                    self._queue_checks(band, src, tiles=False)
            self._queue_checks(0, None, tiles=not self._discard)
            if self.before_read is not None:
                self.before_read()
            try:
                windows = self._resolve_checks(t0, k, impulses if with_forces and not read_now and not in_pass
                                               else None, others if slots else None)
                windows = read_now or windows
                if in_pass:
                    windows = [self._pass_sums_forces(k, impulses)]
            except SolverDiverged as exc:
                if exc.step == self.time and not self._discard:  # only the final state is known bad
                    self._replay(start, t0, k, sums=in_pass)
                raise
            for win in windows:  # a BodyWindow, or (block_sums, in_pass) forces already
                forces = (win if self._block_sums or in_pass else
                          {name: model.compute(win) for name, model in self._models.items()})
                for name, (fx, fy) in forces.items():
                    sums[name][0] += fx
                    sums[name][1] += fy
            done += k
        if n > 0:
            self._forces = {name: (s[0] / n, s[1] / n) for name, s in sums.items()}

    def _band_slots(self) -> int:
        """Slots for the body window in one side's band area (0: the window does not fit, or
        no band area: the atlas path); builds the copy pass's rectangles for this window size."""
        if not self._band_w:
            return 0
        k0, y0, k1, y1 = texel_box(self.body.window)
        ww, wh = k1 - k0, y1 - y0
        cols, rows = self._band_w // ww, self.ny // wh
        if cols * rows == 0:
            return 0
        layout = (cols, ww, wh)
        if self._band_copy is None or self._band_copy[2] != layout:
            if self._band_copy is None:
                prog = create_program(self.ctx, "rect_vertex.glsl", "copy_window.glsl")
                self._uniforms(prog, **dict(zip(G_NAMES, UNIT_G)),
                               grid_size=(float(self._tex_size[0]), float(self.ny)))
                vbo = self.ctx.buffer(reserve=1)
                self._objects.append(prog)
            else:
                vao, vbo, _ = self._band_copy
                prog = vao.program
                vao.release()
            rects = [(self._kx + c * ww, r * wh, self._kx + (c + 1) * ww, (r + 1) * wh)
                     for r in range(rows) for c in range(cols)]
            data = _triangles(rects).tobytes()
            vbo.orphan(len(data))
            vbo.write(data)
            self._band_copy = (self.ctx.vertex_array(prog, [(vbo, "2f", "in_pos")]), vbo, layout)
        if self._sums_forces() and (self._band_sums is None or self._band_sums.body is not self.body):
            self._build_link_sums()
        return cols * rows

    def _build_link_sums(self):
        """The LinkSums of the current body and band layout. Its list texture and rectangles are
        made once per layout and rewritten when the set of texels with links changes (at a move,
        when llvmpipe's queue is empty: a write to a texture a queued step reads would wait)."""
        links = self.body.links
        x0w, y0w = self.body.window[:2]
        key = distinct_sorted((y0w + links.iy) * self._kx + (x0w + links.ix) // 2)  # sorted by (y, k)
        texel = np.stack([key % self._kx, key // self._kx], axis=1)
        layout = self._band_copy[2]
        cols, ww, wh = layout
        sums = self._band_sums
        if sums is not None and sums.layout == layout and np.array_equal(sums.texels, texel):
            sums.body = self.body  # the same list: keep it (set_body has set the body's uniforms)
            return
        if sums is None or sums.layout != layout:
            if sums is None:
                prog = create_program(self.ctx, "rect_vertex.glsl", "link_sums.glsl")
                self._uniforms(prog, **dict(zip(G_NAMES, UNIT_G)), MASK=UNIT_MASK, QA=UNIT_QA, QB=UNIT_QB,
                               LINK_TEXELS=UNIT_LINKS, N=(self.nx, self.ny),
                               grid_size=(float(self._tex_size[0]), float(self.ny)))
                self._objects.append(prog)
            else:
                prog = sums.vao.program
                sums.release()
            table = self.ctx.texture((ww, wh), 4, dtype="f4")  # the list never outgrows the window
            table.filter = (moderngl.NEAREST, moderngl.NEAREST)
            vbo = self.ctx.buffer(reserve=cols * (self.ny // wh) * 6 * 2 * 4)
            vao = self.ctx.vertex_array(prog, [(vbo, "2f", "in_pos")])
            sums = self._band_sums = LinkSums(vao, vbo, table, texel[:0], layout, self.body)
            self._upload_body_uniforms()  # a new vertex array or program: the body's uniforms
        rows = max(1, -(-len(texel) // ww))
        entries = np.zeros((rows * ww, 4), "f4")
        entries[:len(texel), :2] = texel
        entries[:len(texel), 2] = 1.0
        sums.table.write(entries.tobytes(), viewport=(0, 0, ww, rows))
        if rows != sums.rows:
            slots = [(self._kx + c * ww, r * wh, self._kx + (c + 1) * ww, r * wh + rows)
                     for r in range(self.ny // wh) for c in range(cols)]
            sums.vbo.write(_triangles(slots).tobytes())
            sums.rows = rows
        sums.texels, sums.body = texel, self.body

    def _sums_forces(self) -> bool:
        """Whether the enabled force models are all link sums the pass computes (LINK_SUM_MODELS)."""
        return (self.tuning["forces"] in ("gpu", "pass") and bool(self._models)
                and set(self._models) <= LINK_SUM_MODELS and self.body is not None)

    def _band_link_forces(self, sides, bands: int, impulses, t0: int):
        """Each step's forces {model: (fx, fy)} from its slot of link sums (shaders/link_sums.glsl)
        in the band areas (step b: slot b // 2 of side sides[b % 2]; attachment 0 only, summed
        in float64), plus the links' constant K and, for the Galilean-invariant form, the step's
        cover/uncover impulse. Returns (forces per step, the first step whose sums are not finite
        or None)."""
        _, _, (cols, ww, wh) = self._band_copy
        rows, cols_ = np.divmod(np.arange(len(self._band_sums.texels)), ww)  # list entry j in its slot
        kx, ky = self._links_constant()
        sums = np.empty((bands, 4))
        for first in (0, 1):  # the steps whose slots side sides[first] holds: first, first + 2, ...
            band = np.arange(first, bands, 2)
            if not len(band):
                continue
            slot = band // 2
            h = -(-(int(slot[-1]) + 1) // cols) * wh  # the rows of the band area those slots use
            data = self._fbo[sides[first]].read(viewport=(self._kx, 0, cols * ww, h), components=4,
                                                attachment=0, dtype="f4")
            area = np.frombuffer(data, dtype="f4").reshape(h, cols * ww, 4)
            texels = area[(slot // cols * wh)[:, None] + rows, (slot % cols * ww)[:, None] + cols_]
            sums[band] = texels.sum(axis=1, dtype=np.float64)  # (steps, 4), each step's in float64
        finite = np.isfinite(sums).all(axis=1)
        good = bands if finite.all() else int(np.argmin(finite))
        out = []
        for b in range(good):
            s = sums[b]
            forces = {}
            if "momentum_exchange" in self._models:
                forces["momentum_exchange"] = (float(s[0] + s[2] + kx + impulses[b][0]),
                                               float(s[1] + s[3] + ky + impulses[b][1]))
            if "momentum_exchange_classic" in self._models:
                forces["momentum_exchange_classic"] = (float(s[0] + kx), float(s[1] + ky))
            out.append(forces)
        return out, (None if good == bands else t0 + good)

    def _links_constant(self):
        """The links' constant K = -2 RHO0 sum w_i c_i of the body's links, per step (the part of
        the momentum exchange that the sums of shifted populations leave out)."""
        i = self.body.links.i
        return tuple(-2.0 * RHO0 * (W[i, None] * C[i]).sum(axis=0)) if len(i) else (0.0, 0.0)

    def _read_pass_sums(self) -> np.ndarray:
        """The running total of link sums (LINK_SUMS) of the current side: channels zw of
        texture G4 over the body variant's rectangles, summed in float64."""
        total = np.zeros(2)
        for x0, y0, x1, y1 in self._body_rects:
            data = self._fbo[self._cur].read(viewport=(x0, y0, x1 - x0, y1 - y0), components=4,
                                             attachment=TEXTURES - 1, dtype="f4")
            total += np.frombuffer(data, dtype="f4").reshape(-1, 4)[:, 2:].sum(axis=0, dtype=np.float64)
        return total

    def _pass_sums_forces(self, bands: int, impulses) -> dict:
        """The forces summed over the block's `bands` steps from the step pass's link sums
        (LINK_SUMS 1: Galilean-invariant S1 + S2 per step, 2: classic S1), plus the links'
        constant K each step and, Galilean-invariant, each step's cover/uncover impulse (as
        _band_link_forces). Non-finite sums raise SolverDiverged at the block's end, which the
        caller replays to find the step."""
        s = self._read_pass_sums()
        if not np.all(np.isfinite(s)):
            raise SolverDiverged(self.time, "non-finite populations around the body")
        kx, ky = self._links_constant()
        fx, fy = float(s[0] + bands * kx), float(s[1] + bands * ky)
        if self._link_sums == 2:
            return {"momentum_exchange_classic": (fx, fy)}
        return {"momentum_exchange": (fx + sum(j[0] for j in impulses), fy + sum(j[1] for j in impulses))}

    def _band_windows(self, sides, bands: int) -> list[np.ndarray]:
        """The stored g (9, h, w) of each step's body window from the band areas: step b's
        window is slot b // 2 of side sides[b % 2]; each side's used rows are read once."""
        _, _, (cols, ww, wh) = self._band_copy
        x0, _, x1, _ = self.body.window
        lo = x0 - 2 * (x0 // 2)  # the window's first node within its first texel
        out = []
        areas = {}
        for b in range(bands):
            side, slot = sides[b % 2], b // 2
            if side not in areas:
                used = (bands - 1 - b % 2) // 2 + 1  # slots this side holds
                h = -(-used // cols) * wh
                areas[side] = self._read_texels((self._kx, 0, self._kx + cols * ww, h), side)
            c, r = slot % cols, slot // cols
            nodes = areas[side][:, r * wh:(r + 1) * wh, 2 * c * ww:2 * (c + 1) * ww]
            out.append(nodes[:, :, lo:lo + x1 - x0])
        return out

    def _replay(self, start: int, t0: int, k: int, sums: bool = False):
        """Rerun the k steps after time t0 from side `start`, checking each state (and, `sums`:
        each step's link sums, LINK_SUMS): raises SolverDiverged with the first step whose
        state (or body window) is not finite (the GPU is deterministic)."""
        end = self.time
        self._cur, self.time = start, t0
        others = [side for side in range(3) if side != start]
        for band in range(k):
            if sums:
                self._set_sums_keep(0.0)
            self._draw_step(others[band % 2])
            if sums and not np.all(np.isfinite(self._read_pass_sums())):
                raise SolverDiverged(self.time - 1, "non-finite populations around the body")
            self._queue_checks(0, None, tiles=True)
            if not self._tiles_finite(0):
                raise SolverDiverged(self.time, "density is no longer finite")
        raise SolverDiverged(end, "density is no longer finite (not reproduced on replay)")

    def time_variant(self, key, draws: int) -> float:
        """Seconds to draw step variant `key` = (body, edges, sponge) over the whole grid
        `draws` times (the state is advanced: for docs/science/performance.md's cost table only)."""
        import time

        vbo = self.ctx.buffer(_triangles([(0, 0, self._kx, self.ny)]).tobytes())
        vao = self.ctx.vertex_array(self._program(key), [(vbo, "2f", "in_pos")])
        self._update_inflow(self.time)
        self.finish()
        t0 = time.perf_counter()
        for _ in range(draws):
            dst = (self._cur + 1) % 3
            self._begin_pass(self._fbo[dst], self._tex_size)
            self._bind_sources(self._cur)
            vao.render(moderngl.TRIANGLES)
            self._cur = dst
        self.finish()
        elapsed = time.perf_counter() - t0
        vao.release()
        vbo.release()
        return elapsed

    def finish(self) -> None:
        """Wait until the GPU has done all queued work (for honest timing)."""
        self.ctx.finish()

    # --- divergence -------------------------------------------------------------
    def _aux_pass(self, fragment, size, defines=None):
        """(program, texture, framebuffer, vao) of a one-rectangle pass into an RGBA32F target."""
        prog = create_program(self.ctx, "rect_vertex.glsl", fragment, defines)
        tex = self.ctx.texture(size, 4, dtype="f4")
        tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
        fbo = self.ctx.framebuffer(color_attachments=[tex])
        vbo = self.ctx.buffer(_triangles([(0, 0, *size)]).tobytes())
        vao = self.ctx.vertex_array(prog, [(vbo, "2f", "in_pos")])
        self._objects += [vao, vbo, fbo, tex, prog]
        self._uniforms(prog, **dict(zip(G_NAMES, UNIT_G)), N=(self.nx, self.ny),
                       grid_size=(float(size[0]), float(size[1])),
                       body_force=tuple(float(v) for v in self.config.body_force))
        return prog, tex, fbo, vao

    def _ensure_atlas(self, with_window: bool) -> int:
        """The check atlas: per step one band of tile sums (columns [0, TW)) and, with forces,
        one band of the body window (columns [TW, TW + w), in texels), 5 RGBA32F attachments. Returns how
        many bands (steps) fit: CHECK_EVERY, fewer for a body window too tall for the texture."""
        tw, th = self._tile_grid
        ww, wh = (0, 0)
        if with_window:
            k0, y0, k1, y1 = texel_box(self.body.window)
            ww, wh = k1 - k0, y1 - y0
        limit = int(self.ctx.info.get("GL_MAX_TEXTURE_SIZE", 16384))
        bands = max(1, min(CHECK_EVERY, limit // max(th, wh)))
        need = (tw + ww, max(th, wh) * bands)
        if self._atlas is None or any(a < b for a, b in zip(self._atlas["size"], need)):
            if self._atlas is not None:
                for obj in self._atlas["objects"]:
                    obj.release()
            size = (min(limit, max(need[0], self._atlas["size"][0] if self._atlas else 0)),
                    min(limit, max(need[1], self._atlas["size"][1] if self._atlas else 0)))
            texs = [self.ctx.texture(size, 4, dtype="f4") for _ in range(TEXTURES)]
            fbo = self.ctx.framebuffer(color_attachments=texs)
            self._atlas = {"size": size, "fbo": fbo, "objects": [fbo, *texs]}
        if self._check_progs is None:
            tiles = self._aux_program("finite_check.glsl", {"BLOCK_X": self._tile_block[0],
                                                             "BLOCK_Y": self._tile_block[1]})
            self._uniforms(tiles[0].program, N=(self._kx, self.ny))
            window = self._aux_program("copy_window.glsl")
            self._check_progs = (tiles, window)
        size = self._atlas["size"]
        for vao, _ in self._check_progs:
            self._uniforms(vao.program, grid_size=(float(size[0]), float(size[1])))
        if (size, ww, wh) != self._atlas.get("layout"):
            self._atlas["layout"] = (size, ww, wh)
            for _, vbo in self._check_progs:
                band_h = max(th, wh)
                rects = [(0, b * band_h, tw, b * band_h + th) for b in range(CHECK_EVERY)]
                rects += [(tw, b * band_h, tw + ww, b * band_h + wh) for b in range(CHECK_EVERY)]
                vbo.orphan(len(rects) * 6 * 8)
                vbo.write(_triangles(rects).tobytes())
        self._atlas["window"] = (ww, wh)
        return bands

    def _aux_program(self, fragment, defines=None):
        """(vao, vbo) of a pass into the check atlas; the vbo holds one rectangle per band."""
        prog = create_program(self.ctx, "rect_vertex.glsl", fragment, defines)
        vbo = self.ctx.buffer(reserve=2 * CHECK_EVERY * 6 * 8)
        vao = self.ctx.vertex_array(prog, [(vbo, "2f", "in_pos")])
        self._objects += [vao, vbo, prog]
        self._uniforms(prog, **dict(zip(G_NAMES, UNIT_G)), N=(self.nx, self.ny))
        return vao, vbo

    def _queue_checks(self, band: int, window_side: int | None, tiles: bool):
        """Into band `band` of the check atlas: the tile sums of the current state (`tiles`)
        and the body window of `window_side` (one pass: both draws share llvmpipe's scene)."""
        tw, th = self._tile_grid
        ww, wh = self._atlas["window"]
        band_h = max(th, wh)
        (tile_vao, _), (window_vao, _) = self._check_progs
        self._begin_pass(self._atlas["fbo"], self._atlas["size"])
        if tiles:
            self._g[self._cur][0].use(location=UNIT_G[0])
            tile_vao.program["band"].value = (0, band * band_h)
            tile_vao.render(moderngl.TRIANGLES, vertices=6, first=6 * band)
        if window_side is not None:
            for unit, texture in zip(UNIT_G, self._g[window_side]):
                texture.use(location=unit)
            k0, y0 = texel_box(self.body.window)[:2]
            window_vao.program["shift"].value = (k0 - tw, y0 - band * band_h)
            window_vao.render(moderngl.TRIANGLES, vertices=6, first=6 * (CHECK_EVERY + band))

    def _tiles_finite(self, band: int) -> bool:
        tw, th = self._tile_grid
        band_h = max(th, self._atlas["window"][1])
        data = self._atlas["fbo"].read(viewport=(0, band * band_h, tw, th), components=4, attachment=0, dtype="f4")
        return bool(np.all(np.isfinite(np.frombuffer(data, dtype="f4"))))

    def _resolve_checks(self, t0: int, bands: int, impulses, band_sides=None):
        """Read the atlas after a block of `bands` steps from time t0 and check it (algorithm.md,
        'Divergence'): the tile sums of the final state finite (or, tuning divergence="discard",
        every node of every step written), and each step's body window finite (from the atlas,
        or with `band_sides` from the band areas of those two sides). Raises SolverDiverged
        with the earliest bad step known; else returns the BodyWindows."""
        tw, th = self._tile_grid
        ww, wh = self._atlas["window"]
        band_h = max(th, wh)
        height = (bands - 1) * band_h + wh
        bad = []
        if self._discard:
            for step, query in self._pending:
                self._idle_queries.append(query)
                if query.samples != self._fragments_per_step and not bad:
                    bad.append((step, "density is no longer finite"))
            self._pending = []
        elif not self._tiles_finite(0):
            bad.append((self.time, "density is no longer finite"))
        windows = []
        if impulses and band_sides is not None and self._block_sums:
            windows, step = self._band_link_forces(band_sides, bands, impulses, t0)
            if step is not None:
                bad.append((step, "non-finite populations around the body"))
            impulses = None  # the forces are done
        elif impulses and band_sides is not None:
            step_windows = self._band_windows(band_sides, bands)
        elif impulses:
            g = unpack([np.frombuffer(self._atlas["fbo"].read(viewport=(tw, 0, ww, height), components=4,
                                                              attachment=k, dtype="f4"), dtype="f4")
                        .reshape(height, ww, 4) for k in range(TEXTURES)])
            x0, _, x1, _ = self.body.window
            lo = x0 - 2 * (x0 // 2)
            step_windows = [g[:, b * band_h:b * band_h + wh, lo:lo + x1 - x0] for b in range(bands)]
        if impulses:
            b_ = self.body
            solid, q = b_.window_arrays()
            for b, impulse in enumerate(impulses):
                gb = step_windows[b]
                if not np.all(np.isfinite(gb)):
                    bad.append((t0 + b, "non-finite populations around the body"))
                    break
                windows.append(BodyWindow(x0=b_.window[0], y0=b_.window[1], f=unshifted(gb), solid=solid, q=q,
                                          shape=b_.shape, velocity=b_.velocity, omega=b_.omega, impulse=impulse,
                                          config=self.config, links=b_.links))
        if bad:
            raise SolverDiverged(*min(bad))
        return windows

    # --- body -------------------------------------------------------------------
    def set_body(self, shape, velocity=(0.0, 0.0), omega: float = 0.0, *, raster=None) -> None:
        cfg = self.config
        old = self.body
        new = self._body_state(shape, velocity, omega, raster)
        read = {}

        def read_window(x0, y0, x1, y1):  # the refill box's texels, read back once
            read["kbox"] = kbox = texel_box((x0, y0, x1, y1))
            read["texels"] = self._read_texels(kbox)
            read["lo"] = lo = x0 - 2 * kbox[0]
            return unshifted(read["texels"][:, :, lo:lo + x1 - x0])

        def write_nodes(x0, y0, f, changed):  # the changed nodes merged into the texels read
            h, w = changed.shape
            g = read["texels"][:, :, read["lo"]:read["lo"] + w]
            g[:, changed] = shifted(f[:, changed]).astype("f4")
            self._write_texels(read["texels"], read["kbox"])

        # lbm_step.glsl's BODY pass gives every solid node f^eq(RHO0, u_body) each step
        jx, jy = move_body(old, new, cfg, read_window, write_nodes, step_sets_solid=True)
        self._impulse = (self._impulse[0] + jx, self._impulse[1] + jy)
        box = union_box(old.raster.window if old else None, new.raster.window if new else None)
        if box is not None:
            self._upload_raster(new, expand_box(box, 2, cfg.nx, cfg.ny))
        self.body = new
        self.speed_capped = (new.capped if new is not None else False) or self.inflow_capped
        self._set_rects(None if new is None else new.raster.window)
        self._upload_body_uniforms()

    def _upload_raster(self, body, box):
        """Node mask and q of `body` (None: no body) over box, into their textures."""
        x0, y0, x1, y1 = box
        h, w = y1 - y0, x1 - x0
        if body is None:
            mask = np.zeros((h, w), np.uint32)
            q = np.zeros((Q, h, w), np.float32)
        else:
            solid, q = body.raster.crop(box)
            mask = node_mask(solid, q, box, body.links, body.window)
            q = q.astype(np.float32)
        viewport = (x0, y0, w, h)
        self._mask_tex.write(np.ascontiguousarray(mask).tobytes(), viewport=viewport)
        self._qa_tex.write(np.ascontiguousarray(np.moveaxis(q[1:5], 0, -1)).tobytes(), viewport=viewport)
        self._qb_tex.write(np.ascontiguousarray(np.moveaxis(q[5:9], 0, -1)).tobytes(), viewport=viewport)

    # --- forces -----------------------------------------------------------------
    def body_window(self) -> BodyWindow | None:
        """The body's force window at the current time (full f*, float64): 3 small reads."""
        return None if self.body is None else self._window(self._cur, self._impulse)

    def _window(self, side, impulse) -> BodyWindow:
        b = self.body
        solid, q = b.window_arrays()
        f = unshifted(self._read_shifted(b.window, side))
        return BodyWindow(x0=b.window[0], y0=b.window[1], f=f, solid=solid, q=q, shape=b.shape,
                          velocity=b.velocity, omega=b.omega, impulse=impulse, config=self.config, links=b.links)

    # --- fields -----------------------------------------------------------------
    def _read_texels(self, kbox, side=None) -> np.ndarray:
        """Node populations g (9, h, 2 w) float32 of the texel box kbox (k0, y0, k1, y1) of the
        current ping-pong side (or `side`)."""
        k0, y0, k1, y1 = kbox
        w, h = k1 - k0, y1 - y0
        fbo = self._fbo[self._cur if side is None else side]
        return unpack([np.frombuffer(fbo.read(viewport=(k0, y0, w, h), components=4, attachment=t, dtype="f4"),
                                     dtype="f4").reshape(h, w, 4) for t in range(TEXTURES)])

    def _read_shifted(self, box=None, side=None) -> np.ndarray:
        """Stored g (9, h, w) float32 over box (x0, y0, x1, y1), default the whole grid, of the
        current ping-pong side (or `side`)."""
        x0, y0, x1, y1 = box or (0, 0, self.nx, self.ny)
        lo = x0 - 2 * (x0 // 2)
        return np.ascontiguousarray(self._read_texels(texel_box((x0, y0, x1, y1)), side)[:, :, lo:lo + x1 - x0])

    def _write_shifted(self, g: np.ndarray, box=None) -> None:
        """Store g (9, h, w) over box in the current side; a box that starts or ends inside a
        texel keeps the other node of that texel (read, merged, written back)."""
        x0, y0, x1, y1 = box or (0, 0, self.nx, self.ny)
        k0, _, k1, _ = kbox = texel_box((x0, y0, x1, y1))
        lo = x0 - 2 * k0
        if lo or (x1 - x0 + lo) % 2 and x1 < self.nx:
            nodes = self._read_texels(kbox)
        else:
            nodes = np.zeros((Q, y1 - y0, 2 * (k1 - k0)), np.float32)
        nodes[:, :, lo:lo + x1 - x0] = g
        self._write_texels(nodes, kbox)

    def _write_texels(self, nodes: np.ndarray, kbox) -> None:
        """Store node populations (9, h, 2 w) into the texel box kbox of the current side."""
        k0, y0, k1, y1 = kbox
        for t, data in enumerate(pack(nodes)):
            self._g[self._cur][t].write(np.ascontiguousarray(data).tobytes(), viewport=(k0, y0, k1 - k0, y1 - y0))

    def shifted_distributions(self) -> np.ndarray:
        return self._read_shifted()

    def set_distributions(self, f: np.ndarray) -> None:
        f = np.asarray(f, dtype=np.float64)
        if f.shape != (Q, self.ny, self.nx):
            raise ValueError(f"distributions must have shape {(Q, self.ny, self.nx)}, got {f.shape}")
        self._write_shifted(shifted(f).astype("f4"))

    @property
    def grid_size(self):
        return self.nx, self.ny

    def field_texture(self):
        """(rho, ux, uy, vorticity) as an nx x ny RGBA32F texture, computed now by one pass."""
        if self._field is None:
            self._field = self._aux_pass("field.glsl", (self.nx, self.ny),
                                         {"INCOMPRESSIBLE": self._defines["INCOMPRESSIBLE"]})
        prog, tex, fbo, vao = self._field
        self._begin_pass(fbo, tex.size)
        for unit, texture in zip(UNIT_G, self._g[self._cur]):
            texture.use(location=unit)
        vao.render(moderngl.TRIANGLES)
        return tex

    def close(self) -> None:
        for obj in [*(o for pair in self._vaos.values() for o in pair), *self._objects, *self._programs.values()]:
            obj.release()
        self._draws, self._vaos, self._objects, self._programs = [], {}, [], {}
        self._field = None
        if self._atlas is not None:
            for obj in self._atlas["objects"]:
                obj.release()
        self._atlas, self._check_progs = None, None
        if self._band_sums is not None:
            self._band_sums.release()
            self._band_sums = None
        if self._band_copy is not None:
            self._band_copy[0].release()
            self._band_copy[1].release()
            self._band_copy = None
        self._pending, self._idle_queries = [], []
