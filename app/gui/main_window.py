"""The FeelFlow window: the wind-tunnel viewport in the middle, the side panel, the live force
plot below, presets, status bar, keyboard shortcuts, remembered settings, and the frame loop
with adaptive stepping (as many solver steps per frame as keep the window at >= 30 fps).

A recorded session replays in the window (File > Replay session): an
`feelflow.app.model.replay_simulation.ReplaySimulation` takes the live simulation's place in the viewport and
the plot at the same steps-per-frame budget, the live one waits untouched, and Stop replay (Esc)
brings it back as it was.
"""
from __future__ import annotations

import json
import math
import time

import numpy as np
from PySide6.QtCore import QEvent, QPoint, QSettings, Qt, QTimer, Signal
from PySide6.QtGui import QAction, QKeySequence, QPainter, QUndoStack
from PySide6.QtWidgets import (QAbstractButton, QApplication, QDockWidget, QFileDialog, QLabel, QMainWindow,
                               QMessageBox, QToolBar)

from feelflow.app.gui.qt_runtime import make_none_immortal

make_none_immortal()  # before any Qt object: see app/qt_runtime.py

from feelflow.app.gui.exercise_controller import ExerciseController  # noqa: E402
from feelflow.app.gui.force_plot import ForcePlot  # noqa: E402
from feelflow.app.model.presets import PRESETS
from feelflow.app.model.bodies import default_polygon
from feelflow.app.gui.shape_editor import SetPolygon
from feelflow.app.gui.side_panel import SidePanel
from feelflow.app.model.simulation import Params, Simulation, wrap_degrees
from feelflow.app.gui.turn_handle import TurnBody
from feelflow.app.gui.viewport import DISPLAY_MODES, MOUSE_HINT, Viewport
from feelflow.shapes.base import ShapeError
from feelflow.solver.backend import SolverDiverged  # noqa: E402
from feelflow.solver.config import ConfigError

TARGET_FRAME_S = 1.0 / 31.5    # aim just above 30 fps: every spare millisecond goes to the solver
MAX_STEPS_PER_FRAME = 200
MIN_STEPS_PER_FRAME = 2   # the flow keeps moving even where drawing alone takes 1/30 s
N_TRACERS = 900


class MainWindow(QMainWindow):
    simulationReady = Signal()

    def __init__(self, backend: str = "gl", settings: QSettings | None = None, params: Params | None = None):
        super().__init__()
        self.setWindowTitle("FeelFlow \u2013 a wind tunnel you can touch")
        self.backend = backend
        self.settings = settings or QSettings("FeelFlow", "FeelFlow")
        self.sim: Simulation | None = None
        self.paused = False
        self.steps_per_frame = 4
        self._step_cost = 2e-3       # seconds per solver step (running estimate)
        self._other_cost = 5e-3      # seconds per frame outside stepping
        self._last_tick = None
        self._rate_window = [time.perf_counter(), 0, 0]   # start, steps, frames
        self.rates = {"steps_per_s": 0.0, "fps": 0.0, "mlups": 0.0}
        self.tracer_rng = np.random.default_rng(1)
        self.undo = QUndoStack(self)
        self.input_device = None
        self.replay = None           # the ReplaySimulation while a session replays
        self._device_seen = None     # the device's target when the replay began

        self.viewport = Viewport()
        self.setCentralWidget(self.viewport)
        self.panel = SidePanel()
        self.plot = ForcePlot()
        for button in self.panel.findChildren(QAbstractButton) + self.plot.findChildren(QAbstractButton):
            button.setFocusPolicy(Qt.TabFocus)   # a click leaves the focus (and Space = pause) where it was
        dock = QDockWidget("Controls", self)
        dock.setWidget(self.panel)
        dock.setFeatures(QDockWidget.DockWidgetMovable)
        self.addDockWidget(Qt.RightDockWidgetArea, dock)
        pdock = QDockWidget("Forces", self)
        pdock.setWidget(self.plot)
        pdock.setFeatures(QDockWidget.DockWidgetMovable)
        self.addDockWidget(Qt.BottomDockWidgetArea, pdock)
        self.resizeDocks([pdock], [230], Qt.Vertical)

        self.status = {k: QLabel() for k in ("steps", "mlups", "fps", "re", "ma", "renderer")}
        for label in self.status.values():
            self.statusBar().addPermanentWidget(label)
        self.replay_label = QLabel()   # "Replaying <name>: step N / M" (hidden by passing messages)
        self.statusBar().addWidget(self.replay_label, 1)
        self.replay_label.hide()
        self.exercises = ExerciseController(self)   # the Exercises menu and panel
        self._build_menus()

        self.params = params or self._params_from_settings()
        self.display_mode = self.settings.value("display_mode", "speed")
        if self.display_mode not in DISPLAY_MODES:
            self.display_mode = "speed"
        self.panel.show_params(self.params, self.display_mode)
        self._connect_panel()
        self.viewport.contextReady.connect(self._on_context)
        self.viewport.contextFailed.connect(self._cannot_start)
        self.startup_error = None
        self.viewport.polygonEdited.connect(self.edit_polygon)
        self.viewport.inputRefused.connect(lambda: self._refuse_in_replay("the mouse does not move the body"))
        self.viewport.turnRequested.connect(self.turn_body)
        self.viewport.turnFinished.connect(self._turn_done)
        self.viewport.wheelTurned.connect(self.turn_by_wheel)
        self.viewport.turnRefused.connect(self._turn_refused)
        geometry = self.settings.value("geometry")
        if geometry is not None:
            self.restoreGeometry(geometry)
        else:
            self.resize(1280, 820)
        self.timer = QTimer(self)
        self.timer.setInterval(0)
        self.timer.timeout.connect(self.tick)
        self.slow_timer = QTimer(self)
        self.slow_timer.setInterval(500)
        self.slow_timer.timeout.connect(self.refresh_readouts)

    # --- settings ---------------------------------------------------------------------------
    def _params_from_settings(self) -> Params:
        d = Params()
        s = self.settings

        def get(key, default, kind):
            try:
                return kind(s.value(key, default))
            except (TypeError, ValueError):
                return default
        grid = str(s.value("grid", f"{d.grid[0]}x{d.grid[1]}"))
        try:
            grid = tuple(int(v) for v in grid.split("x"))
        except ValueError:
            grid = d.grid
        return Params(grid=grid if len(grid) == 2 else d.grid, shape=get("shape", d.shape, str),
                      size=get("size", d.size, float), angle_deg=get("angle_deg", d.angle_deg, float),
                      wind=get("wind", d.wind, float), nu=get("nu", d.nu, float), wall=get("wall", d.wall, str),
                      force_model=get("force_model", d.force_model, str),
                      compare_all=str(s.value("compare_all", "false")).lower() == "true")

    def _polygon_from_settings(self):
        try:
            verts = json.loads(str(self.settings.value("polygon", "null")))
            return [(float(x), float(y)) for x, y in verts] if verts else None
        except (TypeError, ValueError):
            return None

    def save_settings(self):
        s, p = self.settings, self.params_now()
        s.setValue("grid", f"{p.grid[0]}x{p.grid[1]}")
        for key in ("shape", "size", "angle_deg", "wind", "nu", "wall", "force_model"):
            s.setValue(key, getattr(p, key))
        s.setValue("compare_all", "true" if p.compare_all else "false")
        if self.sim is not None and self.sim.polygon is not None:
            s.setValue("polygon", json.dumps([list(v) for v in self.sim.polygon]))
        s.setValue("display_mode", self.display_mode)
        s.setValue("geometry", self.saveGeometry())
        s.sync()

    def params_now(self) -> Params:
        return self.sim.params if self.sim is not None else self.params

    def event(self, ev):
        """Space is Pause / run everywhere except on a button or check box reached with Tab:
        there it presses the button, as on any desktop (the panel's buttons take no focus from
        a mouse click, so Space still pauses after clicking one)."""
        if (ev.type() == QEvent.ShortcutOverride and ev.key() == Qt.Key_Space
                and ev.modifiers() == Qt.NoModifier
                and isinstance(QApplication.focusWidget(), QAbstractButton)):
            ev.accept()
            return True
        return super().event(ev)

    def closeEvent(self, ev):
        self.save_settings()
        self.timer.stop()
        self.slow_timer.stop()
        self.exercises.shutdown()
        if self.replay is not None:
            self._make_current()
            self.replay.close()
        if self.input_device is not None:
            self._close_device()
        super().closeEvent(ev)

    # --- start ------------------------------------------------------------------------------
    def _cannot_start(self, message):
        """No GL or no backend: one plain dialog, then the window closes (exit code 2)."""
        self.startup_error = message
        hint = "" if self.backend == "numpy" else "\nThe numpy solver may work: feelflow gui --backend numpy"
        QTimer.singleShot(0, lambda: (QMessageBox.critical(self, "FeelFlow cannot start", message + hint),
                                      self.close()))

    def _on_context(self, ctx):
        from feelflow.solver.backend import BackendError

        try:
            self._create_simulation(ctx)
        except (BackendError, RuntimeError) as exc:
            self._cannot_start(f"The {self.backend} solver cannot run here: {str(exc).splitlines()[0]}")
            return
        self._simulation_started()

    def _create_simulation(self, ctx):
        try:
            self.sim = Simulation(self.params, backend=self.backend, ctx=ctx)
            polygon = self._polygon_from_settings()
            if polygon is not None and self.sim.params.shape == "polygon":
                self.sim.set_shape(polygon=polygon)
        except (ConfigError, ShapeError, ValueError) as exc:   # remembered settings that no longer work
            self.statusBar().showMessage(f"Remembered settings ignored ({exc}); using the defaults.", 8000)
            self.sim = Simulation(Params(), backend=self.backend, ctx=ctx)
        if self.sim.params.shape == "polygon" and self.sim.polygon is None:
            self._install_default_polygon()

    def _simulation_started(self):
        self.viewport.sim = self.sim
        self.plot.sim = self.sim
        self.viewport.mode = self.display_mode
        self.panel.show_params(self.sim.params, self.display_mode)
        self.status["renderer"].setText(f"{self.viewport.renderer().split(' (')[0]}, {self.backend} solver")
        self.status["renderer"].setToolTip(self.viewport.renderer())
        self._upload_field()
        self.refresh_devices()
        self._say_guard()
        self.timer.start()
        self.slow_timer.start()
        self.refresh_readouts()
        if not self.statusBar().currentMessage():   # a note about ignored settings comes first
            self.statusBar().showMessage(MOUSE_HINT, 20000)
        self.simulationReady.emit()

    # --- menus and keys ---------------------------------------------------------------------
    def _action(self, menu, text, slot, shortcut=None, checkable=False):
        act = QAction(text, self)
        if shortcut:
            act.setShortcut(QKeySequence(shortcut))
            act.setShortcutContext(Qt.ApplicationShortcut)
        act.setCheckable(checkable)
        act.triggered.connect(slot)
        menu.addAction(act)
        return act

    def _build_menus(self):
        bar = self.menuBar()
        f = bar.addMenu("&File")
        self._action(f, "Load shape\u2026", self.load_shape_dialog)
        self._action(f, "Save shape\u2026", self.save_shape_dialog)
        f.addSeparator()
        self._action(f, "Export forces as CSV\u2026", self.export_csv_dialog)
        self._action(f, "Export plot as PNG\u2026", self.export_png_dialog)
        self._action(f, "Save screenshot\u2026", self.screenshot_dialog)
        f.addSeparator()
        self.record_action = self._action(f, "Record session", self.toggle_recording, checkable=True)
        self.replay_action = self._action(f, "Replay session\u2026", self.replay_session_dialog)
        self.stop_replay_action = self._action(f, "Stop replay", self.stop_replay)
        self.stop_replay_action.setToolTip("Stop the replay and return to the live tunnel (Esc)")
        self.stop_replay_action.setEnabled(False)
        f.addSeparator()
        self._action(f, "Quit", self.close, "Ctrl+Q")
        e = bar.addMenu("&Edit")
        self.undo_action = undo = self.undo.createUndoAction(self, "Undo")
        undo.setShortcut(QKeySequence("Ctrl+Z"))
        self.redo_action = redo = self.undo.createRedoAction(self, "Redo")
        redo.setShortcuts([QKeySequence("Ctrl+Shift+Z"), QKeySequence("Ctrl+Y")])
        e.addAction(undo)
        e.addAction(redo)
        r = bar.addMenu("&Run")
        self.pause_action = self._action(r, "Pause / run", self.toggle_pause, "Space", checkable=True)
        self._action(r, "Reset flow", self.reset_flow, "R")
        self._action(r, "Stop device force / replay", self.escape, "Esc")
        v = bar.addMenu("&View")
        self._action(v, "Full screen", self.toggle_fullscreen, "F11")
        v.addSeparator()
        for key, mode in DISPLAY_MODES.items():
            self._action(v, mode.label, lambda _=False, k=key: self.set_display_mode(k))
        p = bar.addMenu("&Presets")
        for key, preset in PRESETS.items():
            self._action(p, preset.title, lambda _=False, k=key: self.apply_preset(k))
        self.exercises.build_menu(bar, p)
        self.replay_toolbar = QToolBar("Replay", self)   # shown only while a session replays
        self.replay_toolbar.setMovable(False)
        self.replay_toolbar.addAction(self.pause_action)
        self.replay_toolbar.addAction(self.stop_replay_action)
        self.addToolBar(Qt.TopToolBarArea, self.replay_toolbar)
        self.replay_toolbar.hide()

    def toggle_pause(self, _=None):
        self.set_paused(not self.paused)

    def toggle_recording(self, _=None):
        if self.sim is None:
            return
        solver = self.sim.solver
        if self._refuse_in_replay("recording is for the live tunnel"):
            self.record_action.setChecked(solver.recorder is not None)
            return
        if solver.recorder is None:
            solver.start_recording(renderer=self.viewport.renderer())
            self.record_action.setChecked(True)
            self.statusBar().showMessage("Recording a session: inputs, parameter changes and forces.", 5000)
            return
        self.record_action.setChecked(False)
        recorder = solver.stop_recording()
        path, _ = QFileDialog.getSaveFileName(self, "Save session", "lesson.ffsession", "Sessions (*.ffsession)")
        if path:
            self._try(lambda: recorder.save(path), "Could not save the session")

    # --- replaying a session -------------------------------------------------------------------
    @property
    def shown(self):
        """What the viewport and the plot show: the replay while one runs, else the live tunnel."""
        return self.replay if self.replay is not None else self.sim

    def replay_session_dialog(self, _=None):
        if self.sim is None:
            return
        path, _ = QFileDialog.getOpenFileName(self, "Replay session", "", "Sessions (*.ffsession)")
        if path:
            self.start_replay(path)

    def start_replay(self, path) -> bool:
        """Replay the session file at `path` in the window; a bad file is a one-line dialog and
        changes nothing. The live tunnel waits, untouched, until `stop_replay`."""
        if self.sim is None:
            return False
        if self.sim.solver.recorder is not None:
            QMessageBox.warning(self, "Could not replay the session",
                                "A session is being recorded: stop the recording (File > Record session) first.")
            return False
        replay = self._try(lambda: self._open_replay(path), "Could not replay the session")
        if replay is None:
            return False
        if self.replay is not None:
            self.stop_replay()
        self.set_editing(False)
        self.viewport._grab = None
        self.sim.target = None
        self.replay = replay
        if self.input_device is not None:   # its force fades out; its moves are refused
            self.input_device.pause(True)
            self._device_seen = self.input_device.target()
        self.undo_action.setEnabled(False)
        self.redo_action.setEnabled(False)
        self._show(replay)
        self.pause_action.setChecked(False)
        self.stop_replay_action.setEnabled(True)
        self.replay_toolbar.show()
        self.statusBar().clearMessage()   # a passing message (the mouse hint) would be drawn over the label
        self.replay_label.show()
        self.timer.setInterval(0)
        self._show_replay_progress()
        return True

    def _open_replay(self, path):
        """A ReplaySimulation of the file on the window's backend; SessionError (one line)."""
        from feelflow.app.model.replay_simulation import ReplaySimulation
        from feelflow.app.sessions import load_session

        session = load_session(path)
        self._make_current()
        return ReplaySimulation(session, self.backend, ctx=self.viewport.ctx if self.backend == "gl" else None)

    def stop_replay(self, _=None):
        """Back to the live tunnel exactly as it was when the replay began."""
        replay, self.replay = self.replay, None
        if replay is None:
            return
        self._make_current()
        self._show(self.sim)
        replay.close()
        self.viewport.banner = None
        self.replay_label.hide()
        self.replay_toolbar.hide()
        self.stop_replay_action.setEnabled(False)
        self.undo_action.setEnabled(self.undo.canUndo())
        self.redo_action.setEnabled(self.undo.canRedo())
        self.pause_action.setChecked(self.paused)
        self.timer.setInterval(30 if self.paused else 0)
        if self.input_device is not None:
            self.input_device.pause(self.paused)
        self.panel.show_params(self.sim.params, self.display_mode)
        self._after_rebuild()
        self.statusBar().showMessage("Replay stopped: back to the live tunnel.", 4000)

    def _show(self, sim):
        """Point the viewport and the plot at `sim` (live or replay) and draw it."""
        self.viewport.sim = self.plot.sim = sim
        self.viewport.locked = sim is self.replay
        self.viewport.tracers = self.viewport.arrow_forces = None
        self._last_tick = None
        self._upload_field()
        self.plot.refresh(force=True)
        self.viewport.update()

    def _show_replay_progress(self):
        r = self.replay
        if r is None:
            return
        where = f"step {r.step} / {r.total_steps}"
        if r.done:
            text = f"Replay of {r.name} finished at {where}: Stop replay (Esc) returns to the live tunnel."
            self.viewport.banner = f"replay finished ({where})"
        else:
            text = f"Replaying {r.name}: {where}" + (" (paused: space to run)" if r.paused else "")
            self.viewport.banner = f"replay: {where}" + (", paused" if r.paused else "")
        if r.player.diverged_at is not None:
            text += f"; the flow diverged at step {r.player.diverged_at}"
        self.replay_label.setText(text)

    def _refuse_in_replay(self, why: str) -> bool:
        """During a replay: say in the status bar why a request is refused, put the controls back
        as they were and return True; otherwise False."""
        r = self.replay
        if r is None:
            return False
        self.statusBar().showMessage(f"Replaying {r.name}: {why}. Stop replay (Esc) to return to the live tunnel.",
                                     6000)
        p = self.panel
        if self.sim is not None:
            p.show_params(self.sim.params, self.display_mode)
            for box, on in ((p.hold_still, self.sim.hold_still), (p.edit, self.viewport.editing)):
                box.blockSignals(True)
                box.setChecked(on)
                box.blockSignals(False)
        box = p.input
        box.blockSignals(True)
        box.setCurrentIndex(max(0, box.findData(self.input_device.url if self.input_device is not None else "mouse")))
        box.blockSignals(False)
        return True

    def _watch_device(self):
        """A device moved during a replay: say that it does not move the body now."""
        dev = self.input_device
        target = dev.target() if dev is not None else None
        if target is None:
            return
        if self._device_seen is not None and math.dist(target, self._device_seen) > 3.0:
            self._refuse_in_replay("the device does not move the body")
        self._device_seen = target

    def escape(self, _=None):
        """Esc: the device's force to zero at once (haptics safety: the stop key), and the
        replay, if one runs, stopped."""
        self.stop_device_force()
        self.stop_replay()

    def set_paused(self, paused: bool):
        if self.replay is not None:   # Space pauses the replay; the live tunnel keeps its own state
            self.replay.paused = paused
            self.pause_action.setChecked(paused or self.replay.done)
            self._show_replay_progress()
            return
        if self.sim is not None and paused != self.paused:
            self.sim.solver.pause() if paused else self.sim.solver.resume()
        self.paused = paused
        self.timer.setInterval(30 if paused else 0)   # paused: redraw at ~30 Hz, no busy loop
        if self.input_device is not None:
            self.input_device.pause(paused)
        self.pause_action.setChecked(paused)
        self.statusBar().showMessage("Paused (space to run)" if paused else "Running", 2000)

    def toggle_fullscreen(self):
        self.showNormal() if self.isFullScreen() else self.showFullScreen()

    def reset_flow(self):
        if self.sim is None or self._refuse_in_replay("the flow follows the recording"):
            return
        self._make_current()
        self.sim.reset_flow()
        self.viewport.tracers = None
        self._upload_field()
        self.refresh_readouts()

    # --- panel ------------------------------------------------------------------------------
    def _connect_panel(self):
        p = self.panel
        p.shapeChanged.connect(self.set_shape_kind)
        p.sizeChanged.connect(lambda v: self._apply_shape(size=v))
        p.angleChanged.connect(self.set_angle)
        p.holdStillToggled.connect(self.set_hold_still)
        p.editToggled.connect(self.set_editing)
        p.save_shape.clicked.connect(self.save_shape_dialog)
        p.load_shape.clicked.connect(self.load_shape_dialog)
        p.windChanged.connect(lambda v: self._apply_flow(wind=v))
        p.viscosityChanged.connect(lambda v: self._apply_flow(nu=v))
        p.wallChanged.connect(lambda v: self._apply_flow(wall=v))
        p.gridChanged.connect(self.set_grid)
        p.forceModelChanged.connect(lambda m: self._with_sim(lambda s: s.set_force_models(selected=m)))
        p.compareAllToggled.connect(lambda on: self._with_sim(lambda s: s.set_force_models(compare_all=on)))
        p.displayModeChanged.connect(self.set_display_mode)
        p.arrowsToggled.connect(lambda on: setattr(self.viewport, "show_arrows", on))
        p.inputChanged.connect(self.set_input)

    def _with_sim(self, fn):
        if self.sim is not None and not self._refuse_in_replay("the scene cannot be changed"):
            self._make_current()
            fn(self.sim)
            self.refresh_readouts()
            self.plot.refresh(force=True)

    def _refuse(self, title, exc):
        QMessageBox.warning(self, title, str(exc))
        self.panel.show_params(self.sim.params, self.display_mode)

    def _apply_shape(self, **changes):
        if self.sim is None or self._refuse_in_replay("the body follows the recording"):
            return False
        self._make_current()
        try:
            self.sim.set_shape(**changes)
        except (ShapeError, ConfigError, ValueError) as exc:
            self._refuse("This shape cannot be used", exc)
            return False
        self.panel.show_params(self.sim.params, self.display_mode)
        if self._say_guard():
            self._after_rebuild()
        self.viewport.update()
        return True

    def set_shape_kind(self, kind):
        if self.sim is None or self._refuse_in_replay("the body follows the recording"):
            return
        if kind == "polygon" and self.sim.polygon is None:
            self._install_default_polygon()
            return
        self._apply_shape(kind=kind)
        if kind != "polygon":
            self.set_editing(False)

    def _install_default_polygon(self):
        verts = default_polygon(self.sim.params.size)
        self._make_current()
        try:
            self.sim.set_shape(kind="polygon", polygon=verts)
        except (ShapeError, ValueError) as exc:
            self._refuse("This shape cannot be used", exc)
        self.panel.show_params(self.sim.params, self.display_mode)

    def _apply_flow(self, **changes):
        if self.sim is None or self._refuse_in_replay("the flow follows the recording"):
            return
        self._make_current()
        try:
            self.sim.set_flow(**changes)
        except ConfigError as exc:
            self._refuse("This flow setting cannot be used", exc)
            return
        if self._say_guard():
            self.panel.show_params(self.sim.params, self.display_mode)
        self._after_rebuild()

    def _say_guard(self) -> bool:
        """Show in the status bar what the stability guard changed (app.simulation.stable_params)."""
        note = self.sim.guard_note if self.sim is not None else None
        if note:
            self.statusBar().showMessage(note, 10000)
        return bool(note)

    def set_grid(self, grid):
        if self.sim is None or self._refuse_in_replay("the grid is the recording's"):
            return
        self._make_current()
        try:
            self.sim.set_grid(grid)
        except (ConfigError, ShapeError) as exc:
            self._refuse("This grid cannot be used", exc)
            return
        self.viewport.tracers = None
        self._after_rebuild()

    def _after_rebuild(self):
        if self.input_device is not None:
            self.input_device.loop.set_tunnel((0.0, 0.0, self.sim.config.nx - 1.0, self.sim.config.ny - 1.0))
        self._upload_field()
        self.refresh_readouts()
        self.viewport.update()

    def set_hold_still(self, on):
        if self._refuse_in_replay("the body follows the recording"):
            return
        if self.sim is not None:
            self.sim.hold_still = bool(on)
        self.panel.hold_still.setChecked(bool(on))

    # --- turning the body (the viewport's rotation handle) ----------------------------------------
    def turn_body(self, degrees: float) -> bool:
        """Turn the body to `degrees` (any number of turns). While the flow runs it swings there
        through the angle spring, as with the wheel; paused or held still it turns at once, as
        with the panel's angle box. The panel shows the angle asked for."""
        sim = self.sim
        if sim is None or self._refuse_in_replay("the body follows the recording"):
            return False
        if self.paused or sim.hold_still:
            if sim.angle != math.radians(wrap_degrees(degrees)):
                self._make_current()
                try:
                    sim.set_shape(angle_deg=wrap_degrees(degrees))
                except (ShapeError, ConfigError, ValueError) as exc:   # no dialog in the middle of a drag
                    self.statusBar().showMessage(f"The body cannot turn there: {exc}", 4000)
                    return False
        else:
            sim.turn_to(degrees)
        self.panel.show_angle(sim.params.angle_deg)
        self.viewport.update()
        return True

    def _turn_done(self, before: float, after: float):
        """One drag of the handle: one undo step (the body is already at `after`)."""
        if self.sim is not None and self.replay is None:
            self.undo.push(TurnBody(self.turn_body, before, after))

    def _script_refuses_turn(self, how: str) -> bool:
        """A motion script drives the pose (it ignores the angle until it ends, when the body would
        swing to the last asked angle): refuse the turn with a status message."""
        if getattr(self.sim, "runner", None) is None:
            return False
        self._turn_refused("A motion script", how)
        return True

    def turn_by_wheel(self, degrees: float) -> bool:
        """The mouse wheel turns the body like the handle does; a burst of notches is one undo step."""
        sim = self.sim
        if sim is None or self._script_refuses_turn("the mouse wheel"):
            return False
        before = sim.target_degrees()
        if not self.turn_body(before + degrees):
            return False
        self.undo.push(TurnBody(self.turn_body, before, before + degrees, "turn the body (wheel)", burst="wheel"))
        return True

    def set_angle(self, degrees: float) -> bool:
        """The panel's angle box turns the body at once; a burst of edits (typed digits, arrow
        steps) is one undo step, whose undo puts the body back at once too."""
        sim = self.sim
        if sim is None:
            return False
        if self._script_refuses_turn("the Angle box"):
            self.panel.show_angle(sim.params.angle_deg)   # the box goes back to the angle the body keeps
            return False
        before = sim.target_degrees()
        if not self._turn_at_once(degrees):
            return False
        self.undo.push(TurnBody(self._turn_at_once, before, degrees, "set the angle", burst="angle box"))
        return True

    def _turn_at_once(self, degrees: float) -> bool:
        return self._apply_shape(angle_deg=wrap_degrees(degrees))

    def _turn_refused(self, driver: str, what: str = "the handle"):
        """`driver` (viewport.turn_blocker's words) drives the body, so `what` may not turn it."""
        how = "choose Mouse under Input" if self.input_device is not None else "wait for it to end or reset the flow (R)"
        self.statusBar().showMessage(f"{driver} drives the body: {what} cannot rotate it now ({how}).", 6000)

    def set_display_mode(self, mode):
        self.display_mode = mode
        self.viewport.mode = mode
        if mode != "tracers":
            self.viewport.tracers = None
        self.panel.show_params(self.params_now(), mode)
        self.viewport.update()

    # --- polygon editor ---------------------------------------------------------------------
    def set_editing(self, on):
        if on and self._refuse_in_replay("the body follows the recording"):
            return
        self.viewport.editing = bool(on) and self.sim is not None and self.sim.params.shape == "polygon"
        self.panel.edit.setChecked(self.viewport.editing)
        if self.viewport.editing:
            self.set_hold_still(True)
            self.statusBar().showMessage(f"Editing the polygon (the body holds still): {self.panel.edit.toolTip()}; "
                                         "Ctrl+Z undoes an edit.", 20000)
        elif on is False and self.statusBar().currentMessage().startswith("Editing the polygon"):
            self.statusBar().clearMessage()
        self.viewport.update()

    def check_polygon(self, verts):
        """Build and validate the polygon without installing it; raises ShapeError."""
        sim = self.sim
        shape = sim.make_shape(sim.params.__class__(**{**sim.params.__dict__, "shape": "polygon"}), verts,
                               *sim.pos, sim.angle)
        return shape.validate(sim.config.nx, sim.config.ny)

    def edit_polygon(self, verts, text="edit polygon"):
        """Push an undoable polygon edit, or refuse it with a dialog (the previous shape stays)."""
        if self._refuse_in_replay("the body follows the recording"):
            return False
        try:
            self.check_polygon(verts)
        except (ShapeError, ValueError) as exc:
            QMessageBox.warning(self, "This polygon cannot be used", f"{exc}\nThe previous shape is kept.")
            self.viewport.update()
            return False
        self.undo.push(SetPolygon(self._install_polygon, self.sim.polygon, verts, text))
        return True

    def _install_polygon(self, verts):
        self._make_current()
        self.sim.set_shape(kind="polygon", polygon=[tuple(v) for v in verts])
        self.panel.show_params(self.sim.params, self.display_mode)
        self.viewport.update()

    # --- files --------------------------------------------------------------------------------
    def save_shape_dialog(self):
        path, _ = QFileDialog.getSaveFileName(self, "Save shape", "shape.json", "Shapes (*.json)")
        if path:
            self.save_shape(path)

    def save_shape(self, path):
        from feelflow.shapes import io as shape_io

        try:
            shape_io.save_shape(path, self.sim.shape)
        except (OSError, ShapeError, ValueError) as exc:
            QMessageBox.warning(self, "Could not save the shape", str(exc))

    def load_shape_dialog(self):
        path, _ = QFileDialog.getOpenFileName(self, "Load shape", "", "Shapes (*.json)")
        if path:
            self.load_shape(path)

    def load_shape(self, path):
        from feelflow.shapes import io as shape_io

        if self._refuse_in_replay("the body follows the recording"):
            return False
        try:
            shape = shape_io.load_shape(path)
        except (OSError, ShapeError, ValueError) as exc:
            QMessageBox.warning(self, "Could not load the shape", f"{exc}\nThe previous shape is kept.")
            return False
        return self.install_loaded_shape(shape)

    def install_loaded_shape(self, shape):
        from feelflow.app.model.bodies import params_for_shape

        kind, size, verts = params_for_shape(shape)
        if kind == "polygon":
            if self.sim.params.shape != "polygon":
                self._make_current()
                self.sim.params = self.sim.params.__class__(**{**self.sim.params.__dict__, "shape": "polygon"})
            return self.edit_polygon(verts, "load shape")
        return self._apply_shape(kind=kind, size=size)

    def export_csv_dialog(self):
        path, _ = QFileDialog.getSaveFileName(self, "Export forces", "forces.csv", "CSV (*.csv)")
        if path:
            self._try(lambda: self.plot.export_csv(path), "Could not export the forces")

    def export_png_dialog(self):
        path, _ = QFileDialog.getSaveFileName(self, "Export plot", "forces.png", "PNG (*.png)")
        if path:
            self._try(lambda: self.plot.export_png(path), "Could not export the plot")

    def screenshot_dialog(self):
        path, _ = QFileDialog.getSaveFileName(self, "Save screenshot", "feelflow.png", "PNG (*.png)")
        if path:
            self._try(lambda: self.save_screenshot(path), "Could not save the screenshot")

    def window_image(self):
        """The whole window as shown: QWidget.grab() misses the QPainter overlay of the GL view,
        so the viewport's own rendering is painted over its place."""
        image = self.grab().toImage()
        painter = QPainter(image)
        painter.drawImage(self.viewport.mapTo(self, QPoint(0, 0)), self.viewport.grabFramebuffer())
        painter.end()
        return image

    def save_screenshot(self, path):
        from feelflow.app.files import atomic_path

        image = self.window_image()
        with atomic_path(path, suffix=".png") as tmp:
            if not image.save(str(tmp), "PNG"):
                raise OSError(f"cannot write {path}")

    def _try(self, fn, title):
        """fn()'s result, or None after a one-line dialog when it raised OSError or ValueError."""
        try:
            return fn()
        except (OSError, ValueError) as exc:   # ValueError: ShapeError, SessionError (one line each)
            QMessageBox.warning(self, title, str(exc))
            return None

    # --- presets ------------------------------------------------------------------------------
    def apply_preset(self, key):
        """Load the lesson's scene file and set the window up as the lesson needs."""
        from feelflow.app.errors import UserError
        from feelflow.app.model.scene import load_scene

        lesson = PRESETS[key]
        if self.sim is None or self._refuse_in_replay("lessons run in the live tunnel"):
            return False
        try:
            scene = load_scene(lesson.path)
            self._make_current()
            self.sim.load_scene(scene)
        except (UserError, ConfigError, ShapeError, ValueError) as exc:
            self._refuse("This lesson cannot run here", exc)
            return False
        self.undo.clear()   # the lesson replaces the body and its pose: earlier edits and turns do not apply
        self.set_hold_still(lesson.hold_still and self.sim.runner is None)
        if lesson.wind_sweep:
            self.sim.start_sweep(lesson.wind_sweep, lesson.hold_steps)
        self.set_display_mode(lesson.display)
        self.plot.view.setCurrentIndex(self.plot.view.findData(lesson.plot_view))
        self.viewport.tracers = None
        self.panel.show_params(self.sim.params, self.display_mode)
        self._after_rebuild()
        self.set_paused(False)
        self.statusBar().showMessage(f"{lesson.title}: {lesson.note}", 20000)
        return True

    # --- input devices ------------------------------------------------------------------------
    def refresh_devices(self):
        """Fill the input selector: the mouse, then every device the haptics layer can drive."""
        from feelflow.haptics import list_devices

        box = self.panel.input
        box.blockSignals(True)
        current = box.currentData()
        box.clear()
        box.addItem("Mouse", "mouse")
        try:
            devices = list_devices()
        except Exception as exc:   # enumeration trouble must not stop the window
            devices = []
            self.panel.input_note.setText(f"Could not list devices: {exc}")
        for info in devices:
            if info.driver:
                box.addItem(info.name, info.url)
        i = box.findData(current)
        box.setCurrentIndex(max(0, i))
        box.blockSignals(False)

    def set_input(self, url):
        from feelflow.haptics import BadDeviceURL, DeviceError

        from feelflow.app.gui.device_input import DeviceInput

        if self._refuse_in_replay("the input cannot be changed"):
            return
        self._close_device()
        if url == "mouse" or self.sim is None:
            self.panel.input_note.setText("")
            return
        try:
            self.input_device = DeviceInput(url, (self.sim.config.nx, self.sim.config.ny),
                                            DeviceInput.expected_peak(self.sim), self)
        except (DeviceError, BadDeviceURL, OSError, ValueError) as exc:
            QMessageBox.warning(self, "The device cannot be used", f"{exc}\nBack to the mouse.")
            self._back_to_mouse("")
            return
        self.input_device.disconnected.connect(self._device_lost)
        self.viewport.driver = "The haptic device"
        self.set_hold_still(False)
        self.panel.input_note.setText("The device moves the body; you feel the selected force model.")

    def stop_device_force(self, _=None):
        """Esc: the haptic device's force goes to zero at once (haptics safety: the stop key)."""
        if self.input_device is not None:
            self.input_device.emergency_stop()
            self.statusBar().showMessage("Device force stopped (Esc). Choose the device again to feel the flow.", 10000)

    def _device_lost(self, reason):
        self._close_device()
        self._back_to_mouse(f"The device disconnected ({reason}); the mouse moves the body again.")

    def _back_to_mouse(self, message):
        box = self.panel.input
        box.blockSignals(True)
        box.setCurrentIndex(box.findData("mouse"))
        box.blockSignals(False)
        self.panel.input_note.setText(message)
        if message:
            self.statusBar().showMessage(message, 10000)
        if self.sim is not None:
            self.sim.target = None

    def _close_device(self):
        device, self.input_device = self.input_device, None
        self.viewport.driver = None
        if device is not None:
            device.close()

    # --- frame loop ---------------------------------------------------------------------------
    def _make_current(self):
        if self.backend == "gl":
            self.viewport.makeCurrent()

    def _upload_field(self):
        sim = self.shown
        if sim is None:
            return None
        if self.backend == "gl":
            self.viewport.use_texture(sim.solver.field_texture())
            return None
        rgba = sim.field_rgba()
        self.viewport.makeCurrent()
        self.viewport.upload_field(rgba)
        return rgba

    def _field_array(self) -> np.ndarray:
        """gl backend: the field texture `_upload_field` computed this frame, read back (ny, nx,
        4) float32, instead of running the field pass again."""
        tex = self.viewport.field_texture
        return np.frombuffer(tex.read(), np.float32).reshape(tex.height, tex.width, 4)

    def tick(self):
        now = time.perf_counter()
        if self.sim is None:
            return
        if self.replay is not None:
            self._tick_replay(now)
            return
        if self.paused:
            self.viewport.update()
            self._last_tick = None
            return
        n = self.steps_per_frame
        self._make_current()
        t0 = time.perf_counter()
        try:
            forces = self.sim.advance(n)
        except SolverDiverged:
            self._on_nan()
            return
        t1 = time.perf_counter()
        rgba = self._upload_field()
        # a blow-up in the field raises SolverDiverged from the solver's own check (both
        # backends, docs/algorithm.md 'Divergence'); the forces are checked here, cheaply
        if not all(math.isfinite(v) for f in forces.values() for v in f):
            self._on_nan()
            return
        if self.input_device is not None:
            target = self.input_device.target()
            if target is not None:
                self.sim.target = target
            f = forces.get(self.sim.params.force_model)
            if f is not None:
                self.input_device.submit(f, self.sim.solver.time)
        self._frame_done(now, t0, t1, n, forces, rgba)

    def _tick_replay(self, now):
        """One frame of the replay, at the live tunnel's steps-per-frame budget."""
        from feelflow.app.sessions import SessionError

        r = self.replay
        self._watch_device()
        if r.paused or r.done:
            self.viewport.update()
            self._last_tick = None
            return
        self._make_current()
        t0 = time.perf_counter()
        try:
            forces = r.advance(self.steps_per_frame)
        except SessionError as exc:   # the file asks for something impossible: one line
            self.stop_replay()
            QMessageBox.warning(self, "Could not replay the session", str(exc))
            return
        t1 = time.perf_counter()
        rgba = self._upload_field()
        self._frame_done(now, t0, t1, max(1, r.last_steps), forces, rgba)
        self._show_replay_progress()
        if r.done:
            self.pause_action.setChecked(True)

    def _frame_done(self, now, t0, t1, n, forces, rgba):
        """After n steps took t1 - t0 s: tracers, arrows, redraw, and the next frame's budget."""
        if self.display_mode == "tracers":
            self._advance_tracers(rgba, n)
        if self.display_mode == "pressure" and self.viewport.frames % 5 == 0:
            self.viewport.rho_ref = self._free_stream_density(rgba)
        self._arrows(forces)
        self.viewport.update()
        # adaptive stepping: cost per step and the rest of the frame, smoothed
        self._step_cost = 0.8 * self._step_cost + 0.2 * (t1 - t0) / n
        if self._last_tick is not None:
            other = max(0.0, (now - self._last_tick) - self._last_step_s)
            self._other_cost = 0.8 * self._other_cost + 0.2 * min(other, 0.2)
        self._last_tick, self._last_step_s = now, t1 - t0
        budget = TARGET_FRAME_S - self._other_cost
        self.steps_per_frame = int(max(MIN_STEPS_PER_FRAME, min(MAX_STEPS_PER_FRAME, budget / max(self._step_cost, 1e-6))))
        w = self._rate_window
        w[1] += n
        w[2] += 1
        if now - w[0] >= 1.0:
            dt = now - w[0]
            nodes = self.shown.config.nx * self.shown.config.ny
            self.rates = {"steps_per_s": w[1] / dt, "fps": w[2] / dt, "mlups": w[1] * nodes / dt / 1e6}
            self._rate_window = [now, 0, 0]

    def _free_stream_density(self, rgba) -> float:
        """Median density of the fluid: the reference of the pressure coefficient (the lattice's
        mean density drifts by a fraction of a percent, which alone is Cp ~ 1 at U = 0.05)."""
        if rgba is None:
            rgba = self._field_array()
        rho = rgba[::2, ::2, 0]
        rho = rho[np.isfinite(rho)]
        return float(np.median(rho)) if rho.size else 1.0

    def _on_nan(self):
        self.set_paused(True)
        self.viewport.update()
        answer = QMessageBox.question(
            self, "The simulation became unstable",
            "The flow became unstable and stopped (the numbers grew without bound).\n"
            "This happens when the flow is too fast for the grid or the viscosity is too low.\n\n"
            "Reset the flow and continue?", QMessageBox.Reset | QMessageBox.Cancel, QMessageBox.Reset)
        if answer == QMessageBox.Reset:
            self.reset_flow()
            self.set_paused(False)

    def _arrows(self, forces):
        sim = self.shown
        f = forces.get(sim.params.force_model)
        if f is None or not all(math.isfinite(v) for v in f):
            self.viewport.arrow_forces = None
            return
        w = sim.relative_wind()
        s = math.hypot(*w)
        ax, ay = (w[0] / s, w[1] / s) if s > 1e-9 else (1.0, 0.0)
        drag = f[0] * ax + f[1] * ay
        lift = -f[0] * ay + f[1] * ax
        self.viewport.arrow_forces = {"drag": (drag * ax, drag * ay), "lift": (-lift * ay, lift * ax)}

    def _advance_tracers(self, rgba, n):
        sim = self.shown
        nx, ny = sim.config.nx, sim.config.ny
        if rgba is None:
            rgba = self._field_array()
        rng = self.tracer_rng
        if self.viewport.tracers is None or len(self.viewport.tracers[0]) != N_TRACERS:
            pts = np.c_[rng.uniform(0, nx - 1, N_TRACERS), rng.uniform(0, ny - 1, N_TRACERS)]
        else:
            pts = self.viewport.tracers[0]
        ix = np.clip(np.rint(pts[:, 0]).astype(int), 0, nx - 1)
        iy = np.clip(np.rint(pts[:, 1]).astype(int), 0, ny - 1)
        u = rgba[iy, ix, 1:3].astype(float)
        pts = pts + u * n
        bad = (pts[:, 0] < 0) | (pts[:, 0] > nx - 1) | (pts[:, 1] < 0) | (pts[:, 1] > ny - 1) \
            | ~np.isfinite(pts).all(axis=1)
        if sim.shape is not None:
            bad |= sim.shape.contains(pts[:, 0], pts[:, 1])
        k = int(bad.sum())
        if k:
            pts[bad] = np.c_[rng.uniform(0, 3, k), rng.uniform(0, ny - 1, k)]
        tail = pts - u * 30   # a short streak: where the particle was 30 steps ago
        self.viewport.tracers = (pts, tail)

    def refresh_readouts(self):
        sim = self.shown
        if sim is None:
            return
        p = sim.params
        if sim is self.sim and (abs(self.panel.wind.value() - p.wind) > 5e-4   # a sweep, a lesson or the guard
                                or abs(self.panel.viscosity.value() - p.nu) > 5e-5):
            self.panel.show_params(p, self.display_mode)
        elif sim is self.sim and not self.panel.angle.hasFocus():   # the wheel or the handle turned the body
            self.panel.show_angle(p.angle_deg)
        self.panel.show_numbers(sim.reynolds(), sim.mach(), sim.config.mach_limit)
        t, drag, lift = sim.history.drag_lift(p.force_model)
        if len(t) and p.force_model in sim.history.forces:
            self.panel.show_forces(float(np.nanmean(drag[-30:])), float(np.nanmean(lift[-30:])))
        else:
            self.panel.show_forces(None, None)
        self.plot.refresh()
        r = self.rates
        self.status["steps"].setText(f"{r['steps_per_s']:.0f} steps/s")
        self.status["mlups"].setText(f"{r['mlups']:.1f} MLUPS")
        self.status["fps"].setText(f"{r['fps']:.0f} fps")
        self.status["re"].setText(f"Re {sim.reynolds():.0f}")
        self.status["ma"].setText(f"Ma {sim.mach():.3f}")
