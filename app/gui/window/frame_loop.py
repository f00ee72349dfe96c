"""The frame loop: each frame runs as many solver steps as fit its length (adaptive stepping:
the cost of a step and of the rest of the frame, each smoothed; `FrameLoop.frame_seconds`:
60 frames per second where drawing takes at most half a frame, down to 30 as it takes more,
so that the solver keeps at least half of each frame), uploads
the field, moves the tracers, sets the force arrows and redraws; twice a second the readouts
follow. Pause, the display mode and the unstable-flow dialog live here too.

A frame advances the model shown (`MainWindow.shown`, a `TunnelModel`): the live tunnel, or
a replay at the same steps-per-frame budget.
"""
from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING

import numpy as np
from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QMessageBox

from feelflow.app.model import readouts
from feelflow.app.model.tracers import Tracers
from feelflow.solver.backend import SolverDiverged

if TYPE_CHECKING:
    from feelflow.app.gui.main_window import MainWindow
    from feelflow.app.gui.viewport import Viewport
    from feelflow.app.model.simulation import Simulation

#: the frame's length: as short as 1/60 s (aim just above 60 fps), as long as keeps at least
#: MIN_SOLVER_SHARE of it for the solver's steps, never longer than 1/30 s (just above 30 fps)
FASTEST_FRAME_S = 1.0 / 61.5
SLOWEST_FRAME_S = 1.0 / 31.5
MIN_SOLVER_SHARE = 0.5
MAX_STEPS_PER_FRAME = 200
MIN_STEPS_PER_FRAME = 2   # the flow keeps moving even where drawing alone takes 1/30 s
N_TRACERS = 900
READOUT_MS = 500
#: the live tunnel's physical-range check (SessionSolver.check_physical) runs once this many
#: solver steps have passed, not after every frame: it reads the whole field back (on the gl
#: backend a read-back of all populations), about 1.5 ms on a 2-core machine without a GPU;
#: non-finite populations are still caught at every step by the backends themselves
PHYSICAL_CHECK_STEPS = 64


class FrameLoop:
    """Owns the frame timer, pause, the display mode and the steps-per-frame budget."""

    def __init__(self, window: "MainWindow", viewport: "Viewport"):
        self.w = window
        self.viewport = viewport
        self.sim: "Simulation | None" = None   # the live tunnel, once it exists (events.liveCreated)
        self.paused = False
        self.display_mode = "speed"
        self.steps_per_frame = 4
        self.step_cost = 2e-3       # seconds per solver step (running estimate)
        self.other_cost = 5e-3      # seconds per frame outside stepping
        self._last_tick = None
        self._last_step_s = 0.0
        self._rate_window = [time.perf_counter(), 0, 0]   # start, steps, frames
        self.rates = {"steps_per_s": 0.0, "fps": 0.0, "mlups": 0.0}
        self.tracers = Tracers(N_TRACERS)
        self.timer = QTimer(window)
        self.timer.setInterval(0)
        self.timer.timeout.connect(self.tick)
        self.slow_timer = QTimer(window)
        self.slow_timer.setInterval(READOUT_MS)
        self.slow_timer.timeout.connect(self.refresh_readouts)
        window.events.liveCreated.connect(self._live_created)
        window.events.shownChanged.connect(self.show_model)
        window.events.replayStarted.connect(lambda: self.timer.setInterval(0))
        window.events.replayStopped.connect(self._replay_stopped)
        window.events.flowChanged.connect(self._flow_changed)

    def _live_created(self, sim):
        self.sim = sim

    def start(self):
        if self.sim is not None:
            self.sim.solver.check_every = PHYSICAL_CHECK_STEPS
        self.timer.start()
        self.slow_timer.start()

    def stop(self):
        self.timer.stop()
        self.slow_timer.stop()

    def show_model(self, model):
        """Point the viewport and the plot at `model` (the live tunnel or a replay) and draw it."""
        w = self.w
        vp = self.viewport
        vp.sim = w.plot.sim = model
        vp.locked = model is not self.sim
        vp.tracers = vp.arrow_forces = vp.torque_arc = None
        self.forget_last_frame()
        self.upload_field()
        w.plot.refresh(force=True)
        vp.update()

    def _flow_changed(self):
        """The live tunnel changed: its field, the readouts and a redraw."""
        self.upload_field()
        self.refresh_readouts()
        self.viewport.update()

    def _replay_stopped(self, paused: bool):
        """Back on the live tunnel: its own pace and pause."""
        self.w.actions.pause.setChecked(paused)
        self.timer.setInterval(30 if paused else 0)

    def forget_last_frame(self):
        """The next frame starts afresh (the model shown changed): no frame time to smooth."""
        self._last_tick = None

    # --- pause and display --------------------------------------------------------------------
    def toggle_pause(self, _=None):
        self.set_paused(not self.paused)

    def set_paused(self, paused: bool):
        w = self.w
        replay = w.replays.replay
        if replay is not None:   # Space pauses the replay; the live tunnel keeps its own state
            replay.paused = paused
            w.actions.pause.setChecked(paused or replay.done)
            w.replays.show_progress()
            return
        if self.sim is not None and paused != self.paused:
            self.sim.solver.pause() if paused else self.sim.solver.resume()
        self.paused = paused
        self.timer.setInterval(30 if paused else 0)   # paused: redraw at ~30 Hz, no busy loop
        w.inputs.pause(paused)
        w.actions.pause.setChecked(paused)
        w.statusBar().showMessage("Paused (space to run)" if paused else "Running", 2000)

    def set_display_mode(self, mode):
        w = self.w
        self.display_mode = mode
        self.viewport.mode = mode
        if mode != "tracers":
            self.viewport.tracers = None
        w.panel.show_params(w.params_now(), mode)
        if w.shown is not None:   # the field again (a gl texture computes the vorticity only where shown)
            w.make_current()
            self.upload_field()
        self.viewport.update()

    # --- the field ----------------------------------------------------------------------------
    def upload_field(self):
        """The shown model's field into the viewport: the flow's own texture where it has one
        (the gl backend, on the viewport's context; the vorticity, five nodes a texel, only where
        it is shown), else its (ny, nx, 4) array, which it returns."""
        w = self.w
        model = w.shown
        if model is None:
            return None
        texture = model.field_texture(vorticity=self.display_mode == "vorticity")
        if texture is not None:
            self.viewport.use_texture(texture)
            return None
        rgba = model.field_rgba()
        self.viewport.makeCurrent()
        self.viewport.upload_field(rgba)
        return rgba

    def _field_array(self) -> np.ndarray:
        """gl backend: the field texture `upload_field` computed this frame, read back (ny, nx,
        4) float32, instead of running the field pass again."""
        tex = self.viewport.field_texture
        return np.frombuffer(tex.read(), np.float32).reshape(tex.height, tex.width, 4)

    # --- one frame ------------------------------------------------------------------------------
    def tick(self):
        now = time.perf_counter()
        w = self.w
        sim = self.sim
        if sim is None:
            return
        if w.replays.replay is not None:
            self._tick_replay(now)
            return
        if self.paused:
            self.viewport.update()
            self._last_tick = None
            return
        n = self.steps_per_frame
        w.make_current()
        t0 = time.perf_counter()
        try:
            forces = sim.advance(n)
        except SolverDiverged:
            self._on_nan()
            return
        t1 = time.perf_counter()
        rgba = self.upload_field()
        # a blow-up in the field raises SolverDiverged from the solver's own check (both
        # backends, docs/science/algorithm.md 'Divergence'); the forces are checked here, cheaply
        if not all(math.isfinite(v) for f in forces.values() for v in f):
            self._on_nan()
            return
        if getattr(sim, "guard_changed", False):   # the local stability guard raised the viscosity
            sim.guard_changed = False
            w.flow.say_guard()
            w.panel.show_params(sim.params, self.display_mode)
            w.flow.after_rebuild()
        w.inputs.after_frame(forces)
        w.replays.watch_recording()
        self._frame_done(now, t0, t1, n, forces, rgba)

    def _tick_replay(self, now):
        """One frame of the replay, at the live tunnel's steps-per-frame budget."""
        from feelflow.app.sessions import SessionError

        w = self.w
        r = w.replays.replay
        w.inputs.watch_during_replay()
        if r.paused or r.done:
            self.viewport.update()
            self._last_tick = None
            return
        w.make_current()
        t0 = time.perf_counter()
        try:
            forces = r.advance(self.steps_per_frame)
        except SessionError as exc:   # the file asks for something impossible: one line
            w.replays.stop()
            QMessageBox.warning(w, "Could not replay the session", str(exc))
            return
        t1 = time.perf_counter()
        rgba = self.upload_field()
        self._frame_done(now, t0, t1, max(1, r.last_steps), forces, rgba)
        w.replays.show_progress()
        if r.done:
            w.actions.pause.setChecked(True)

    def _frame_done(self, now, t0, t1, n, forces, rgba):
        """After n steps took t1 - t0 s: tracers, arrows, redraw, and the next frame's budget."""
        vp = self.viewport
        if self.display_mode == "tracers":
            self._advance_tracers(rgba, n)
        if self.display_mode == "pressure" and vp.frames % 5 == 0:
            vp.rho_ref = self._free_stream_density(rgba)
        self.update_arrows(forces)
        self.w.probes.sample_frame(rgba if rgba is not None else self._field_array)   # app/gui/window/probes.py
        vp.update()
        # adaptive stepping: cost per step and the rest of the frame, smoothed
        self.step_cost = 0.8 * self.step_cost + 0.2 * (t1 - t0) / n
        if self._last_tick is not None:
            other = max(0.0, (now - self._last_tick) - self._last_step_s)
            self.other_cost = 0.8 * self.other_cost + 0.2 * min(other, 0.2)
        self._last_tick, self._last_step_s = now, t1 - t0
        budget = self.frame_seconds() - self.other_cost
        self.steps_per_frame = int(max(MIN_STEPS_PER_FRAME, min(MAX_STEPS_PER_FRAME, budget / max(self.step_cost, 1e-6))))
        rw = self._rate_window
        rw[1] += n
        rw[2] += 1
        if now - rw[0] >= 1.0:
            dt = now - rw[0]
            cfg = self.w.shown.config
            self.rates = {"steps_per_s": rw[1] / dt, "fps": rw[2] / dt, "mlups": rw[1] * cfg.nx * cfg.ny / dt / 1e6}
            self._rate_window = [now, 0, 0]

    def frame_seconds(self) -> float:
        """The frame length the steps per frame aim at: 1/60 s where the rest of the frame
        (drawing, Qt) takes at most half of it, longer as the rest takes more, so that the
        solver keeps half of each frame; never longer than 1/30 s: where the rest takes more
        than half of that, the solver gets what is left (at least MIN_STEPS_PER_FRAME steps)."""
        wanted = self.other_cost / (1.0 - MIN_SOLVER_SHARE)
        return min(SLOWEST_FRAME_S, max(FASTEST_FRAME_S, wanted))

    def _free_stream_density(self, rgba) -> float:
        """The pressure view's reference density (app/model/readouts.py)."""
        return readouts.free_stream_density(self._field_array() if rgba is None else rgba)

    def _on_nan(self):
        w = self.w
        self.set_paused(True)
        self.viewport.update()
        answer = QMessageBox.question(
            w, "The simulation became unstable",
            "The flow became unstable and stopped (the numbers grew without bound).\n"
            "This happens when the flow is too fast for the grid or the viscosity is too low.\n\n"
            "Reset the flow and continue?", QMessageBox.Reset | QMessageBox.Cancel, QMessageBox.Reset)
        if answer == QMessageBox.Reset:
            w.flow.reset()
            self.set_paused(False)

    def update_arrows(self, forces):
        """The viewport's drag and lift arrows for this frame's force (app/model/readouts.py)."""
        model = self.w.shown
        self.viewport.arrow_forces = readouts.arrows(forces.get(model.params.force_model), model.relative_wind(),
                                                     model.reference_length())
        self.viewport.torque_arc = readouts.torque_arc(model.last_torques.get(model.params.force_model),
                                                       model.params.size, model.config.max_speed)

    def _advance_tracers(self, rgba, n):
        """Move the viewport's tracers n steps through the field (app/model/tracers.py)."""
        model, vp = self.w.shown, self.viewport
        if rgba is None:
            rgba = self._field_array()
        vp.tracers = self.tracers.advance(rgba, n, model.shape, None if vp.tracers is None else vp.tracers[0])

    # --- readouts -----------------------------------------------------------------------------
    def refresh_readouts(self):
        """The panel's numbers, the plot and the status bar, from the model shown."""
        w = self.w
        model = w.shown
        if model is None:
            return
        p, panel = model.params, w.panel
        live = model is self.sim
        wind, nu = panel.flow_shown     # lattice units, whatever units the boxes show
        if live and (abs(wind - p.wind) > 5e-4   # a sweep, a lesson or the guard
                     or abs(nu - p.nu) > 5e-5):
            panel.show_params(p, self.display_mode)
        elif live and not panel.angle.hasFocus():   # the wheel or the handle turned the body
            panel.show_angle(p.angle_deg)
        panel.show_numbers(model.reynolds(), model.mach(), model.config.mach_limit)
        r = readouts.readout(model.history, p.force_model, model.reference_length())
        panel.show_forces(r.drag, r.lift) if r.has_forces else panel.show_forces(None, None)
        w.plot.refresh()
        r = self.rates
        w.status["steps"].setText(f"{r['steps_per_s']:.0f} steps/s")
        w.status["mlups"].setText(f"{r['mlups']:.1f} MLUPS")
        w.status["fps"].setText(f"{r['fps']:.0f} fps")
        w.status["re"].setText(f"Re {model.reynolds():.0f}")
        w.status["ma"].setText(f"Ma {model.mach():.3f}")
        w.status["operator"].setText(model.operator_line())   # the collision operator and why
