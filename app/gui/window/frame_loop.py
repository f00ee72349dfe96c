"""The frame loop: each frame runs as many solver steps as fit its length (adaptive stepping:
the cost of a step and of the rest of the frame, each smoothed; `FrameLoop.frame_seconds`:
60 frames per second where drawing takes at most half a frame, down to 30 as it takes more,
so that the solver keeps at least half of each frame), then has the field uploaded
(field_display.py), the tracers and force arrows set (flow_overlays.py) and the viewport
redrawn; twice a second it has the readouts refreshed (frame_readouts.py). Pause lives here;
a flow that blows up pauses and asks the student (unstable_flow.py).

A frame advances the model shown (a `TunnelModel`, as `shownChanged` says): the live tunnel,
or a replay at the same steps-per-frame budget. What follows a frame elsewhere (the device, the
recording, the probes, the replay's progress, the guard's note) follows the loop's events
(app/gui/window/events.py).
"""
from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING

from PySide6.QtCore import QTimer

from feelflow.app.gui.window import unstable_flow
from feelflow.solver.backend import SolverDiverged

if TYPE_CHECKING:
    from collections.abc import Callable

    from PySide6.QtWidgets import QStatusBar, QWidget

    from feelflow.app.gui.force_plot import ForcePlot
    from feelflow.app.gui.viewport import Viewport
    from feelflow.app.gui.window.events import WindowEvents
    from feelflow.app.gui.window.field_display import FieldDisplay
    from feelflow.app.gui.window.flow_overlays import FlowOverlays
    from feelflow.app.gui.window.frame_rates import FrameRates
    from feelflow.app.gui.window.frame_readouts import FrameReadouts
    from feelflow.app.model.simulation import Simulation
    from feelflow.app.model.tunnel import TunnelModel

#: the frame's length: as short as 1/60 s (aim just above 60 fps), as long as keeps at least
#: MIN_SOLVER_SHARE of it for the solver's steps, never longer than 1/30 s (just above 30 fps)
FASTEST_FRAME_S = 1.0 / 61.5
SLOWEST_FRAME_S = 1.0 / 31.5
MIN_SOLVER_SHARE = 0.5
MAX_STEPS_PER_FRAME = 200
MIN_STEPS_PER_FRAME = 2   # the flow keeps moving even where drawing alone takes 1/30 s
READOUT_MS = 500
#: the live tunnel's physical-range check (SessionSolver.check_physical) runs once this many
#: solver steps have passed, not after every frame: it reads the whole field back (on the gl
#: backend a read-back of all populations), about 1.5 ms on a 2-core machine without a GPU;
#: non-finite populations are still caught at every step by the backends themselves
PHYSICAL_CHECK_STEPS = 64


class FrameLoop:
    """Owns the frame timer, pause and the steps-per-frame budget; each frame it has the field
    shown, the overlays set and, twice a second, the readouts refreshed."""

    def __init__(self, events: "WindowEvents", viewport: "Viewport", plot: "ForcePlot", display: "FieldDisplay",
                 overlays: "FlowOverlays", readouts: "FrameReadouts", rates: "FrameRates", status: "QStatusBar",
                 make_current: "Callable[[], None]", parent: "QWidget"):
        """`display`, `overlays`, `readouts`: what each frame updates; `rates`: where the frames
        and steps are counted; `make_current`: the viewport's GL context current where the
        solver draws on it; `parent`: the dialogs' and the timers' parent."""
        self.events, self.viewport, self.plot = events, viewport, plot
        self.display, self.overlays, self.readouts, self.rates = display, overlays, readouts, rates
        self.status, self.make_current, self.parent = status, make_current, parent
        self.sim: "Simulation | None" = None   # the live tunnel, once it exists (events.liveCreated)
        self.shown: "TunnelModel | None" = None   # the model drawn (events.shownChanged)
        self.replay = None                         # the shown model while it is a replay, else None
        self.paused = False
        self.steps_per_frame = 4
        self.step_cost = 2e-3       # seconds per solver step (running estimate)
        self.other_cost = 5e-3      # seconds per frame outside stepping
        self._last_tick = None
        self._last_step_s = 0.0
        self.timer = QTimer(parent)
        self.timer.setInterval(0)
        self.timer.timeout.connect(self.tick)
        self.slow_timer = QTimer(parent)
        self.slow_timer.setInterval(READOUT_MS)
        self.slow_timer.timeout.connect(readouts.refresh)
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
        self.display.show(model)
        vp.sim = self.plot.sim = model
        vp.locked = model is not self.sim
        self.overlays.clear()
        self.forget_last_frame()
        self.display.upload_field()
        self.plot.refresh(force=True)
        vp.update()

    def _flow_changed(self):
        """The live tunnel changed: its field, the readouts and a redraw."""
        self.display.upload_field()
        self.readouts.refresh()
        self.viewport.update()

    def _replay_stopped(self, paused: bool):
        """Back on the live tunnel: its own pace and pause."""
        self.events.pauseShown.emit(paused)
        self.timer.setInterval(30 if paused else 0)

    def forget_last_frame(self):
        """The next frame starts afresh (the model shown changed): no frame time to smooth."""
        self._last_tick = None

    # --- pause --------------------------------------------------------------------
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
        rgba = self.display.upload_field()
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
        rgba = self.display.upload_field()
        self._frame_done(now, t0, t1, max(1, r.last_steps), forces, rgba)
        self.events.replayProgressed.emit()
        if r.done:
            self.events.pauseShown.emit(True)

    def _frame_done(self, now, t0, t1, n, forces, rgba):
        """After n steps took t1 - t0 s: the field's followers, overlays, redraw, and the next
        frame's budget."""
        self.display.follow_field(rgba)
        self.overlays.after_frame(rgba, n, forces)
        self.events.fieldShown.emit(rgba if rgba is not None else self.display.field_array)   # the probes sample it
        self.viewport.update()
        # adaptive stepping: cost per step and the rest of the frame, smoothed
        self.step_cost = 0.8 * self.step_cost + 0.2 * (t1 - t0) / n
        if self._last_tick is not None:
            other = max(0.0, (now - self._last_tick) - self._last_step_s)
            self.other_cost = 0.8 * self.other_cost + 0.2 * min(other, 0.2)
        self._last_tick, self._last_step_s = now, t1 - t0
        budget = self.frame_seconds() - self.other_cost
        self.steps_per_frame = int(max(MIN_STEPS_PER_FRAME, min(MAX_STEPS_PER_FRAME, budget / max(self.step_cost, 1e-6))))
        cfg = self.shown.config
        self.rates.count(now, n, cfg.nx * cfg.ny)

    def frame_seconds(self) -> float:
        """The frame length the steps per frame aim at: 1/60 s where the rest of the frame
        (drawing, Qt) takes at most half of it, longer as the rest takes more, so that the
        solver keeps half of each frame; never longer than 1/30 s: where the rest takes more
        than half of that, the solver gets what is left (at least MIN_STEPS_PER_FRAME steps)."""
        wanted = self.other_cost / (1.0 - MIN_SOLVER_SHARE)
        return min(SLOWEST_FRAME_S, max(FASTEST_FRAME_S, wanted))

    def _on_nan(self):
        """The flow blew up: pause, and reset it where the student asks (unstable_flow.py)."""
        self.set_paused(True)
        self.viewport.update()
        if unstable_flow.ask_reset(self.parent):
            self.events.resetAsked.emit()
            self.set_paused(False)
