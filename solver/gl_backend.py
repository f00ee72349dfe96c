"""The fragment-shader backend: the lattice Boltzmann step in GLSL 330 core, run through moderngl.

`GLSolver(config, ctx=moderngl_context)` implements `feelflow.solver.backend.Solver` with the
same extra methods as the numpy reference (`add_force_model`, `body_window`) and the same
physics: D2Q9 BGK, TRT (Ginzburg, Verhaeghe & d'Humieres 2008) or recursive-regularised BGK
(solver/regularised.py) collision with Guo forcing
(Guo, Zheng & Shi 2002), walls, velocity inlet and pressure outlet, the outlet sponge
(solver/sponge.py), and the moving body by interpolated bounce-back (Bouzidi, Firdaouss &
Lallemand 2001). It never creates a GL context: the CLI and the tests hand it an EGL standalone
one, the window Qt's. Arithmetic is float32 whatever `config.dtype` says.

How it is organised (one module per part):
- state: the shifted post-collision populations g_i = f*_i - w_i RHO0, two nodes per texel in
  five RGBA32F textures per side (solver/gl_layout.py), three sides: two ping-pong within a
  block of steps, the third keeps the block's start state for a replay;
- the step: one fused collide-and-stream pass (shaders/lbm_step.glsl) through five colour
  attachments, drawn as rectangles, each with the shader variant its part of the grid needs
  (solver/gl_regions.py);
- the body: node mask and link fractions, uploaded at a move only (solver/gl_body.py); refill
  and the cover/uncover impulses run on the CPU with the reference's code (solver/body.py);
- steps run in blocks of up to CHECK_EVERY with nothing read back inside a block; at its end a
  tile-sum pass checks the final state (solver/gl_checks.py) and the block's forces are read
  once: link sums of the momentum exchange summed on the GPU (solver/gl_link_sums.py), or each
  step's body window, copied by the step's pass into the band area (solver/gl_band.py) or by a
  second pass into the check atlas, for every other force model's own code. A non-finite check
  replays the block from its start state with a check after every step, so
  `feelflow.solver.backend.SolverDiverged` names the exact step, as in the reference.

API for the app (the window's viewport draws with this context):
- `field_texture(vorticity=True)` -> moderngl.Texture, nx x ny, RGBA32F = (rho, ux, uy,
  vorticity), computed by a pass only when called (u as `Solver.macroscopic`; vorticity
  duy/dx - dux/dy by central differences, 0 with `vorticity=False`). NEAREST filtering; bind
  it with `.use(location=k)` in your own draw.
- `grid_size` -> (nx, ny); `renderer` -> the GL renderer string; `finish()` waits for the GPU.
- Every pass sets the state it needs (solver/gl_programs.py `begin_pass`) and binds every
  texture unit it samples (units 0..10) right before drawing. Nothing is restored: after
  `step()` or `field_texture()` the bound framebuffer is the solver's, so a draw must bind its
  own framebuffer and its textures (in a QOpenGLWidget's paintGL:
  `ctx.detect_framebuffer(self.defaultFramebufferObject()).use()`).
"""
from __future__ import annotations

import moderngl
import numpy as np

from feelflow.solver.backend import BackendError, Solver, SolverDiverged
from feelflow.solver.body import expand_box, move_body, shifted, union_box, unshifted
from feelflow.solver.forces.base import BodyWindow
from feelflow.solver.gl_band import BAND_WIDTH, BandArea
from feelflow.solver.gl_body import upload_raster
from feelflow.solver.gl_checks import CHECK_EVERY, CheckAtlas
from feelflow.solver.gl_layout import (G_NAMES, TEXTURES, UNIT_G, UNIT_INFLOW, UNIT_MASK, UNIT_OMEGA,
                                       UNIT_QA, UNIT_QB, pack, texel_box, texels, unpack)
from feelflow.solver.gl_link_sums import (LINK_SUM_MODELS, LINK_SUMS_OF_MODEL, LinkSums, pass_sums_forces,
                                          read_pass_sums)
from feelflow.solver.gl_programs import begin_pass, create_program, set_uniforms, triangles
from feelflow.solver.gl_regions import ALIGN, cover_triangle, regions
from feelflow.solver.inflow import inlet_wall_profile, profile, ramp
from feelflow.solver.lattice import Q, RHO0, equilibrium
from feelflow.solver.regularised import smagorinsky_factor
from feelflow.solver.relaxation import relaxation_rates
from feelflow.solver.quiet_inlet import CS_OVER_RHO0, checked_reference, quiet_terms
from feelflow.solver.sponge import absorb_keep

__all__ = ["BAND_WIDTH", "CHECK_EVERY", "GLSolver"]

_Y_MODE = {"no_slip": 0, "free_slip": 1, "periodic": 2}


class GLSolver(Solver):
    """The lattice Boltzmann step on the GPU (fragment shaders), float32; see the module docstring."""

    name = "gl"
    compiled_moves = True   # the moved body's raster and links (solver/body_compiled.py)

    def __init__(self, config, ctx=None):
        super().__init__(config)
        if ctx is None or not isinstance(ctx, moderngl.Context):
            raise BackendError("the gl backend needs a moderngl.Context (ctx=); it never creates one")
        self.ctx = ctx
        cfg = self.config
        nx, ny = cfg.nx, cfg.ny
        self.nx, self.ny = nx, ny
        self.renderer = ctx.info.get("GL_RENDERER", "?")
        self._defines = {
            "TRT": cfg.collision == "trt",
            "RR": cfg.collision == "rr",
            "INCOMPRESSIBLE": cfg.incompressible,
            "GUO_FORCE": any(c != 0.0 for c in cfg.body_force),
            "X_PERIODIC": cfg.x_boundary == "periodic",
            "Y_MODE": _Y_MODE[cfg.y_boundary],
            "NX_ODD": nx % 2 == 1,
            "QUIET_INLET": cfg.x_boundary == "tunnel" and cfg.inlet_nonreflecting > 0,
        }
        self._sponge = cfg.x_boundary == "tunnel" and cfg.sponge_cells > 0
        self._programs = {}
        op, om = relaxation_rates(cfg)
        # texels: the lattice's ceil(nx / 2) columns, then (tunnels) the band area; an
        # x-periodic grid's texture is exactly the lattice (REPEAT wraps it)
        self._kx = texels(nx)
        band_w = texels(min(nx, BAND_WIDTH)) if cfg.x_boundary != "periodic" else 0
        self._tex_size = (self._kx + band_w, ny)
        tex_w = float(self._tex_size[0])
        self._uniform_values = dict(
            **dict(zip(G_NAMES, UNIT_G)), MASK=UNIT_MASK, QA=UNIT_QA, QB=UNIT_QB,
            INFLOW=UNIT_INFLOW, OMEGA=UNIT_OMEGA, N=(nx, ny), grid_size=(tex_w, float(ny)),
            inv_n=(1.0 / tex_w, 1.0 / ny), body_force=tuple(float(v) for v in cfg.body_force),
            omega_plus=float(np.ravel(op)[0]), omega_minus=float(np.ravel(om)[0]),  # column 0: no sponge
            smagorinsky=smagorinsky_factor(cfg.smagorinsky),
            **({"quiet_inlet": (float(cfg.inlet_nonreflecting), CS_OVER_RHO0)}
               if cfg.x_boundary == "tunnel" and cfg.inlet_nonreflecting > 0 else {}))
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
        self._draws, self._draw_regions = [], None  # [(vertex array, scissor boxes)]
        self._vaos = {}  # (region key, link-sum mode) -> (vertex array, vbo), made on first use
        self._field = {}  # with the vorticity or not -> (program, texture, framebuffer, vao)
        self._checks = CheckAtlas(ctx, self._kx, nx, ny)
        self._band = BandArea(ctx, self._kx, band_w, ny, self._tex_size)
        self._band_sums = None  # LinkSums: the link-sum pass (LINK_SUM_MODELS), made on first use
        self._block_sums = False  # the block being drawn sums links instead of copying windows
        self._link_sums = 0  # lbm_step.glsl LINK_SUMS of the body variant: 0, 1 Galilean, 2 classic
        #: the momentum exchange's torque is summed (the link-sum pass); False: a lone momentum
        #: exchange's force is summed in the step's own pass, its torque NaN
        self.sum_torque = True
        self._sums_keep = None  # the body programs' sums_keep uniform as last set

        self._impulse = (0.0, 0.0)
        self._set_rects(None)
        self._upload_body_uniforms()
        ux0, uy0 = cfg.initial_velocity
        self.set_distributions(equilibrium(np.full((ny, nx), RHO0), np.full((ny, nx), float(ux0)),
                                           np.full((ny, nx), float(uy0))))

    # --- the step's programs and regions ----------------------------------------
    def _program(self, key):
        """The step variant for region `key` = (body, edges, sponge), compiled on first use; the
        body variants with the current link-sum mode (self._link_sums)."""
        body, edges, sponge = key
        link = self._link_sums if body else 0
        if (key, link) not in self._programs:
            defines = {**self._defines, "BODY": body, "EDGES": edges, "SPONGE": sponge, "LINK_SUMS": link}
            prog = create_program(self.ctx, "rect_vertex.glsl", "lbm_step.glsl", defines)
            set_uniforms(prog, **self._uniform_values)
            self._programs[(key, link)] = prog
            if body:
                self._upload_body_uniforms()
        return self._programs[(key, link)]

    def _regions(self, window):
        """solver/gl_regions.py `regions` for the body window (x0, y0, x1, y1) in nodes, or None."""
        sponge_from = (self.nx - self.config.sponge_cells) // 2 // ALIGN * ALIGN if self._sponge else None
        return regions(self._kx, self.ny, None if window is None else texel_box(window), sponge_from,
                       self._wraps_free())

    def _wraps_free(self) -> bool:
        """Both directions periodic, an even nx (whole texels), streamed through REPEAT
        samplers: no edge rules at all."""
        d = self._defines
        return bool(d["X_PERIODIC"] and d["Y_MODE"] == 2 and self.nx % 2 == 0 and not self._sponge)

    def _set_rects(self, window):
        """Draws of every region, in key order each step, so the body window's variant
        (key[0] = 1) comes last, over what is beneath it; kept when the (block-aligned) regions
        did not change. Per rectangle one triangle over the texture, clipped by the scissor box,
        so a move changes only the body window's scissor box (solver/gl_regions.py)."""
        regions_now = sorted(self._regions(window).items())
        if regions_now == self._draw_regions:
            return
        self._draw_regions = regions_now
        w, h = self._tex_size
        draws = []
        self._body_rects = []  # the body variant's rectangles: where LINK_SUMS keeps its totals
        for key, rects in regions_now:
            vkey = (key, self._link_sums if key[0] else 0)
            if vkey not in self._vaos:
                vbo = self.ctx.buffer(cover_triangle(w, h).tobytes())
                self._vaos[vkey] = (self.ctx.vertex_array(self._program(key), [(vbo, "2f", "in_pos")]), vbo)
            draws.append((self._vaos[vkey][0], rects))
            if key[0]:
                self._body_rects += rects
        self._draws = draws
        self._sums_keep = None

    def _render_regions(self):
        for vao, scissors in self._draws:
            for x0, y0, x1, y1 in scissors:
                self.ctx.scissor = (x0, y0, x1 - x0, y1 - y0)
                vao.render(moderngl.TRIANGLES, vertices=3)
        self.ctx.scissor = None

    # --- forces summed on the GPU (solver/gl_link_sums.py) ----------------------
    def _link_sum_mode(self) -> int:
        """lbm_step.glsl's LINK_SUMS for the enabled models: 1 (2) where the Galilean-invariant
        (classic) momentum exchange is the body's only force model and no torque is wanted
        (`sum_torque` False); 0 else (the link-sum pass, which sums the torque too; other
        models: the window)."""
        if self.body is None or self.sum_torque:
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
                    set_uniforms(prog, sums_keep=keep)
            self._sums_keep = keep

    def _sums_forces(self) -> bool:
        """Whether the enabled force models are all link sums the GPU computes (LINK_SUM_MODELS)."""
        return bool(self._models) and set(self._models) <= LINK_SUM_MODELS and self.body is not None

    def _band_slots(self) -> int:
        """Slots for the body window in one side's band area (0: the check atlas takes the
        windows); the link-sum pass brought up to date where it fills them."""
        slots = self._band.slots(texel_box(self.body.window))
        if slots and self._sums_forces() and (self._band_sums is None or self._band_sums.body is not self.body):
            if self._band_sums is None:
                self._band_sums = LinkSums(self.ctx, self._kx, self.nx, self.ny, self._tex_size)
            if self._band_sums.update(self.body, self._band.layout):
                self._upload_body_uniforms()
        return slots

    # --- uniforms and textures of a step ----------------------------------------
    def _upload_body_uniforms(self):
        b = self.body
        centre = (0.0, 0.0) if b is None else (float(b.shape.x), float(b.shape.y))
        velocity = (0.0, 0.0) if b is None else tuple(float(v) for v in b.velocity)
        omega = 0.0 if b is None else float(b.omega)
        for (key, _), prog in self._programs.items():
            if key[0]:
                set_uniforms(prog, body_velocity=velocity, body_omega=omega, body_centre=centre)
        if self._band_sums is not None:
            window = (0, 0, 0, 0) if b is None else tuple(int(v) for v in b.window)
            set_uniforms(self._band_sums.prog, body_velocity=velocity, body_omega=omega,
                         body_centre=centre, window=window)

    def _update_inflow(self, t):
        """u_in(iy, t) = ramp(t) profile(iy) (solver/inflow.py): the ramp as a uniform each
        step, the profile texture (r: the row, gba: rule c's links 1, 5, 8, inlet_wall_profile)
        rewritten only when the speed changes (a texture write while a queued step reads it
        would stall the pipeline)."""
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
            quiet = {}
            if self._defines["QUIET_INLET"]:  # bare inlet, reference held, during the ramp
                quiet["quiet_inlet"] = quiet_terms(cfg.inlet_nonreflecting, r)
                self._uniform_values.update(quiet)
            for (key, _), prog in self._programs.items():
                if key[1] or key[2]:  # edges (the inlet), sponge (the absorbing layer's target)
                    set_uniforms(prog, inflow_ramp=r, **quiet)

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
        pass fills that slot of dst's band area from the current side (f*(t), what the forces
        of step t use): the body window, or its link sums (one llvmpipe scene per step)."""
        self._update_inflow(self.time)
        begin_pass(self.ctx, self._fbo[dst], self._tex_size)
        self._bind_sources(self._cur)
        self._render_regions()
        if slot is not None:
            if self._block_sums:
                self._band_sums.draw(slot, self._band.slot_origin(slot))
            else:
                self._band.draw_copy(slot, texel_box(self.body.window))
        self._cur = dst
        self.time += 1

    def step(self, n: int = 1) -> None:
        """Steps in blocks of up to CHECK_EVERY: nothing is read back inside a block (a read
        drains llvmpipe's queue). With forces, each step's pass sums the links or copies the
        body window (to the band area, else by a second pass to the check atlas); at the end of
        the block the final state's tile sums are queued and everything is read once. A
        non-finite final state replays the block from its start state (kept in the third
        side) with a check after every step, so SolverDiverged names the exact step."""
        n = int(n)
        sums = {name: [0.0, 0.0, 0.0] for name in self._models}
        done = 0
        self._use_link_sum_mode(self._link_sum_mode())
        while done < n:
            with_forces = bool(self._models) and self.body is not None
            in_pass = with_forces and self._link_sums > 0  # the step's own pass sums the links
            slots = self._band_slots() if with_forces and not in_pass else 0
            atlas_window = with_forces and not slots and not in_pass
            k = min(n - done, CHECK_EVERY,
                    self._checks.ensure(texel_box(self.body.window) if atlas_window else None))
            if slots:
                k = min(k, 2 * slots)
            t0, start, impulses = self.time, self._cur, []
            others = [side for side in range(3) if side != start]
            self._block_sums = bool(slots) and self._sums_forces()
            for band in range(k):
                impulses.append(self._impulse)
                self._impulse = (0.0, 0.0)
                src = self._cur
                if in_pass:
                    self._set_sums_keep(0.0 if band == 0 else 1.0)
                self._draw_step(others[band % 2], band // 2 if slots else None)
                if atlas_window:
                    self._checks.queue(band, window_state=self._g[src],
                                       window_origin=texel_box(self.body.window)[:2])
            self._checks.queue(0, state=self._g[self._cur])
            try:
                windows = self._resolve_checks(t0, k, impulses if with_forces and not in_pass else None,
                                               others if slots else None)
                if in_pass:
                    total = read_pass_sums(self._fbo[self._cur], self._body_rects)
                    windows = [pass_sums_forces(total, self._link_sums, self.body.links, k, impulses, self.time)]
            except SolverDiverged as exc:
                if exc.step == self.time:  # only the final state is known bad
                    self._replay(start, t0, k, sums=in_pass)
                raise
            for win in windows:  # a BodyWindow, or (block_sums, in_pass) forces already
                forces = (win if self._block_sums or in_pass else
                          {name: model.evaluate(win) for name, model in self._models.items()})
                for name, (fx, fy, torque) in forces.items():
                    sums[name][0] += fx
                    sums[name][1] += fy
                    sums[name][2] += torque
            done += k
        if n > 0:
            self._forces = {name: (s[0] / n, s[1] / n) for name, s in sums.items()}
            self._torques = {name: s[2] / n for name, s in sums.items()}

    def _resolve_checks(self, t0: int, bands: int, impulses, band_sides=None):
        """Read back a block of `bands` steps from time t0 and check it: the tile sums of the
        final state finite, and each step's body window (from the band areas of the two sides
        `band_sides`, or from the check atlas) or link sums finite. Raises SolverDiverged with
        the earliest bad step known; else returns the BodyWindows (or, link-sum pass, the
        forces) of the steps."""
        bad = []
        if not self._checks.tiles_finite(0):
            bad.append((self.time, "density is no longer finite"))
        windows = []
        if impulses and band_sides is not None and self._block_sums:
            windows, step = self._band_sums.forces(self._fbo, band_sides, bands, self._models, impulses, t0)
            if step is not None:
                bad.append((step, "non-finite populations around the body"))
            impulses = None  # the forces are done
        elif impulses and band_sides is not None:
            step_windows = self._band.windows(self._read_texels, band_sides, bands, self.body.window)
        elif impulses:
            step_windows = self._checks.windows(self.body.window, bands)
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
            if sums and not np.all(np.isfinite(read_pass_sums(self._fbo[self._cur], self._body_rects))):
                raise SolverDiverged(self.time - 1, "non-finite populations around the body")
            self._checks.queue(0, state=self._g[self._cur])
            if not self._checks.tiles_finite(0):
                raise SolverDiverged(self.time, "density is no longer finite")
        raise SolverDiverged(end, "density is no longer finite (not reproduced on replay)")

    def finish(self) -> None:
        """Wait until the GPU has done all queued work (for honest timing)."""
        self.ctx.finish()

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
        jx, jy = move_body(old, new, cfg, read_window, write_nodes, step_sets_solid=True,
                           refill_scheme=self.body_refill, impulse=self.body_impulse)
        self._impulse = (self._impulse[0] + jx, self._impulse[1] + jy)
        box = union_box(old.raster.window if old else None, new.raster.window if new else None)
        if box is not None:
            upload_raster(self._mask_tex, self._qa_tex, self._qb_tex, new, expand_box(box, 2, cfg.nx, cfg.ny))
        self.body = new
        self.speed_capped = (new.capped if new is not None else False) or self.inflow_capped
        self._set_rects(None if new is None else new.raster.window)
        self._upload_body_uniforms()

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

    def inlet_reference(self) -> np.ndarray | None:
        """Channel z of texture G4's texel column 0 (solver/gl_layout.py), current side."""
        if not self.has_quiet_inlet:
            return None
        return self._g4_column()[:, 2].astype(np.float64)

    def set_inlet_reference(self, row) -> None:
        row = checked_reference(self, row)
        column = self._g4_column()
        column[:, 2] = row
        self._g[self._cur][4].write(column.tobytes(), viewport=(0, 0, 1, self.ny))

    def _g4_column(self) -> np.ndarray:
        """Texel column 0 of texture G4, current side: (ny, 4) float32, a copy."""
        raw = self._fbo[self._cur].read(viewport=(0, 0, 1, self.ny), components=4, attachment=4, dtype="f4")
        return np.frombuffer(raw, dtype="f4").reshape(self.ny, 4).copy()

    @property
    def grid_size(self):
        return self.nx, self.ny

    def field_texture(self, vorticity: bool = True):
        """(rho, ux, uy, vorticity) as an nx x ny RGBA32F texture, computed now by one pass;
        with `vorticity=False` the fourth component is 0. Two programs (VORTICITY 1 or 0: a
        uniform branch would not help, llvmpipe runs both sides) drawing into one texture; the
        one without reads one node per texel, not five."""
        key = bool(vorticity)
        if key not in self._field:
            target = next(iter(self._field.values()), None)
            self._field[key] = self._field_pass(
                "field.glsl", (self.nx, self.ny), {"INCOMPRESSIBLE": self._defines["INCOMPRESSIBLE"], "VORTICITY": key},
                target=None if target is None else target[1:3])
        prog, tex, fbo, vao = self._field[key]
        begin_pass(self.ctx, fbo, tex.size)
        for unit, texture in zip(UNIT_G, self._g[self._cur]):
            texture.use(location=unit)
        vao.render(moderngl.TRIANGLES)
        return tex

    def _field_pass(self, fragment, size, defines=None, target=None):
        """(program, texture, framebuffer, vao) of a one-rectangle pass into an RGBA32F target:
        a new one, or `target` = (texture, framebuffer) of another such pass."""
        prog = create_program(self.ctx, "rect_vertex.glsl", fragment, defines)
        if target is None:
            tex = self.ctx.texture(size, 4, dtype="f4")
            tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
            fbo = self.ctx.framebuffer(color_attachments=[tex])
            self._objects += [fbo, tex]
        else:
            tex, fbo = target
        vbo = self.ctx.buffer(triangles([(0, 0, *size)]).tobytes())
        vao = self.ctx.vertex_array(prog, [(vbo, "2f", "in_pos")])
        self._objects += [vao, vbo, prog]
        set_uniforms(prog, **dict(zip(G_NAMES, UNIT_G)), N=(self.nx, self.ny),
                     grid_size=(float(size[0]), float(size[1])),
                     body_force=tuple(float(v) for v in self.config.body_force))
        return prog, tex, fbo, vao

    @property
    def gl_context(self):
        """The moderngl.Context handed in (Solver.gl_context)."""
        return self.ctx

    def close(self) -> None:
        for obj in [*(o for pair in self._vaos.values() for o in pair), *self._objects, *self._programs.values()]:
            obj.release()
        self._draws, self._vaos, self._objects, self._programs = [], {}, [], {}
        self._field = {}
        self._checks.release()
        self._band.release()
        if self._band_sums is not None:
            self._band_sums.release()
            self._band_sums = None
