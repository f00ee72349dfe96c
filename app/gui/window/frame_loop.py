"""The frame loop: each frame runs as many solver steps as fit its length (adaptive stepping:
the cost of a step and of the rest of the frame, each smoothed; `FrameLoop.frame_seconds`:
60 frames per second where drawing takes at most half a frame, down to 30 as it takes more,
so that the solver keeps at least half of each frame), uploads
the field, moves the tracers, sets the force arrows and redraws; twice a second the readouts
follow. Pause, the display mode and the unstable-flow dialog live here too.

A frame advances the model shown (a `TunnelModel`, as `shownChanged` says): the live tunnel,
or a replay at the same steps-per-frame budget. What follows a frame elsewhere (the device, the
recording, the probes, the replay's progress, the guard's note) follows the loop's events
(app/gui/window/events.py).
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
    from collections.abc import Callable

    from PySide6.QtWidgets import QLabel, QStatusBar, QWidget

    from feelflow.app.gui.force_plot import ForcePlot
    from feelflow.app.gui.side_panel import SidePanel
    from feelflow.app.gui.viewport import Viewport
    from feelflow.app.gui.window.events import WindowEvents
    from feelflow.app.model.simulation import Params, Simulation
    from feelflow.app.model.tunnel import TunnelModel

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

    def __init__(self, events: "WindowEvents", viewport: "Viewport", panel: "SidePanel", plot: "ForcePlot",
                 status: "QStatusBar", labels: "dict[str, QLabel]", make_current: "Callable[[], None]",
                 params_now: "Callable[[], Params]", parent: "QWidget"):
        """`labels`: the status bar's numbers by name; `make_current`: the viewport's GL context
        current where the solver draws on it; `params_now`: the parameters the panel shows
        (the live tunnel's, or the remembered ones before it exists); `parent`: the dialogs'
        and the timers' parent."""
        self.events, self.viewport, self.panel, self.plot = events, viewport, panel, plot
        self.status, self.labels, self.make_current, self.params_now = status, labels, make_current, params_now
        self.parent = parent
        self.sim: "Simulation | None" = None   # the live tunnel, once it exists (events.liveCreated)
        self.shown: "TunnelModel | None" = None   # the model drawn (events.shownChanged)
        self.replay = None                         # the shown model while it is a replay, else None
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
        self.timer = QTimer(parent)
        self.timer.setInterval(0)
        self.timer.timeout.connect(self.tick)
        self.slow_timer = QTimer(parent)
        self.slow_timer.setInterval(READOUT_MS)
        self.slow_timer.timeout.connect(self.refresh_readouts)
        events.liveCreated.connect(self._live_created)
        events.shownChanged.connect(self.show_model)
        events.replayStarted.connect(lambda: self.timer.setInterval(0))
        events.replayStopped.connect(self._replay_stopped)
        events.flowChanged.connect(self._flow_changed)

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
        self.shown = model
        self.replay = model if model is not self.sim else None
        vp = self.viewport
        vp.sim = self.plot.sim = model
        vp.locked = model is not self.sim
        vp.tracers = vp.arrow_forces = vp.torque_arc = None
        self.forget_last_frame()
        self.upload_field()
        self.plot.refresh(force=True)
        vp.update()

    def _flow_changed(self):
        """The live tunnel changed: its field, the readouts and a redraw."""
        self.upload_field()
        self.refresh_readouts()
        self.viewport.update()

    def _replay_stopped(self, paused: bool):
        """Back on the live tunnel: its own pace and pause."""
        self.events.pauseShown.emit(paused)
        self.timer.setInterval(30 if paused else 0)

    def forget_last_frame(self):
        """The next frame starts afresh (the model shown changed): no frame time to smooth."""
        self._last_tick = None

    # --- pause and display --------------------------------------------------------------------
    def toggle_pause(self, _=None):
        self.set_paused(not self.paused)

    def set_paused(self, paused: bool):
        replay = self.replay
        if replay is not None:   # Space pauses the replay; the live tunnel keeps its own state
            replay.paused = paused
            self.events.pauseShown.emit(paused or replay.done)
            self.events.replayProgressed.emit()
            return
        if self.sim is not None and paused != self.paused:
            self.sim.solver.pause() if paused else self.sim.solver.resume()
        self.paused = paused
        self.timer.setInterval(30 if paused else 0)   # paused: redraw at ~30 Hz, no busy loop
        self.events.livePaused.emit(paused)
        self.events.pauseShown.emit(paused)
        self.status.showMessage("Paused (space to run)" if paused else "Running", 2000)

    def set_display_mode(self, mode):
        self.display_mode = mode
        self.viewport.mode = mode
        if mode != "tracers":
            self.viewport.tracers = None
        self.panel.show_params(self.params_now(), mode)
        if self.shown is not None:   # the field again (a gl texture computes the vorticity only where shown)
            self.make_current()
            self.upload_field()
        self.viewport.update()

    # --- the field ----------------------------------------------------------------------------
    def upload_field(self):
        """The shown model's field into the viewport: the flow's own texture where it has one
        (the gl backend, on the viewport's context; the vorticity, five nodes a texel, only where
        it is shown), else its (ny, nx, 4) array, which it returns."""
        model = self.shown
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
        sim = self.sim
        if sim is None:
            return
        if self.replay is not None:
            self._tick_replay(now)
            return
        if self.paused:
            self.viewport.update()
            self._last_tick = None
            return
        n = self.steps_per_frame
        self.make_current()
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
        if sim.take_guard_change():   # the local stability guard raised the viscosity
            self.events.guardActed.emit()
        self.events.liveFrame.emit(forces)
        self._frame_done(now, t0, t1, n, forces, rgba)

    def _tick_replay(self, now):
        """One frame of the replay, at the live tunnel's steps-per-frame budget."""
        from feelflow.app.sessions import SessionError

        r = self.replay
        self.events.replayTick.emit()
        if r.paused or r.done:
            self.viewport.update()
            self._last_tick = None
            return
        self.make_current()
        t0 = time.perf_counter()
        try:
            forces = r.advance(self.steps_per_frame)
        except SessionError as exc:   # the file asks for something impossible: one line
            self.events.replayFailed.emit(str(exc))
            return
        t1 = time.perf_counter()
        rgba = self.upload_field()
        self._frame_done(now, t0, t1, max(1, r.last_steps), forces, rgba)
        self.events.replayProgressed.emit()
        if r.done:
            self.events.pauseShown.emit(True)

    def _frame_done(self, now, t0, t1, n, forces, rgba):
        """After n steps took t1 - t0 s: tracers, arrows, redraw, and the next frame's budget."""
        vp = self.viewport
        if self.display_mode == "tracers":
            self._advance_tracers(rgba, n)
        if self.display_mode == "pressure" and vp.frames % 5 == 0:
            vp.rho_ref = self._free_stream_density(rgba)
        self.update_arrows(forces)
        self.events.fieldShown.emit(rgba if rgba is not None else self._field_array)   # the probes sample it
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
            cfg = self.shown.config
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
        self.set_paused(True)
        self.viewport.update()
        answer = QMessageBox.question(
            self.parent, "The simulation became unstable",
            "The flow became unstable and stopped (the numbers grew without bound).\n"
            "This happens when the flow is too fast for the grid or the viscosity is too low.\n\n"
            "Reset the flow and continue?", QMessageBox.Reset | QMessageBox.Cancel, QMessageBox.Reset)
        if answer == QMessageBox.Reset:
            self.events.resetAsked.emit()
            self.set_paused(False)

    def update_arrows(self, forces):
        """The viewport's drag and lift arrows for this frame's force (app/model/readouts.py)."""
        model = self.shown
        self.viewport.arrow_forces = readouts.arrows(forces.get(model.params.force_model), model.relative_wind(),
                                                     model.reference_length())
        self.viewport.torque_arc = readouts.torque_arc(model.last_torques.get(model.params.force_model),
                                                       model.params.size, model.config.max_speed)

    def _advance_tracers(self, rgba, n):
        """Move the viewport's tracers n steps through the field (app/model/tracers.py)."""
        model, vp = self.shown, self.viewport
        if rgba is None:
            rgba = self._field_array()
        vp.tracers = self.tracers.advance(rgba, n, model.shape, None if vp.tracers is None else vp.tracers[0])

    # --- readouts -----------------------------------------------------------------------------
    def refresh_readouts(self):
        """The panel's numbers, the plot and the status bar, from the model shown."""
        model = self.shown
        if model is None:
            return
        p, panel = model.params, self.panel
        live = model is self.sim
        wind, nu = panel.flow_units.shown     # lattice units, whatever units the boxes show
        if live and (abs(wind - p.wind) > 5e-4   # a sweep, a lesson or the guard
                     or abs(nu - p.nu) > 5e-5):
            panel.show_params(p, self.display_mode)
        elif live and not panel.angle.hasFocus():   # the wheel or the handle turned the body
            panel.show_angle(p.angle_deg)
        panel.show_numbers(model.reynolds(), model.mach(), model.config.mach_limit)
        r = readouts.readout(model.history, p.force_model, model.reference_length())
        panel.show_forces(r.drag, r.lift) if r.has_forces else panel.show_forces(None, None)
        self.plot.refresh()
        r = self.rates
        self.labels["steps"].setText(f"{r['steps_per_s']:.0f} steps/s")
        self.labels["mlups"].setText(f"{r['mlups']:.1f} MLUPS")
        self.labels["fps"].setText(f"{r['fps']:.0f} fps")
        self.labels["re"].setText(f"Re {model.reynolds():.0f}")
        self.labels["ma"].setText(f"Ma {model.mach():.3f}")
        self.labels["operator"].setText(model.operator_line())   # the collision operator and why
