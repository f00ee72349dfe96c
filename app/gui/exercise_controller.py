"""Exercise mode in the window: the Exercises menu, the exercise panel beside the flow, live
constraint checks while the student edits (the body outlined in red while one is broken), Score
it in a worker thread (progress, Cancel) and the attempts file next to the student's work.

The score is `feelflow.app.exercises.scoring.score_shape` in float64 on the solver that
`feelflow exercise score` picks by default (`grading.resolve_backend`, `--backend auto`: the
faster of numpy and the compiled cpu backend, which give the same scores), so the window and
the command line give the same digits. The live flow in the viewport is the window's own (gl,
cpu or numpy, float32) and only shows the flow.
"""
from __future__ import annotations

import math
import multiprocessing
from pathlib import Path
from typing import TYPE_CHECKING

from PySide6.QtCore import QObject, QThread, QTimer, Qt, Signal
from PySide6.QtGui import QAction, QColor
from PySide6.QtWidgets import QDockWidget, QFileDialog, QMessageBox

from feelflow import EXERCISE_DIR
from feelflow.app.errors import UserError
from feelflow.app.exercises import grading, scoring
from feelflow.app.exercises.uncertainty import fmt, standing
from feelflow.app.gui.exercise_panel import PARAMETERS, PANEL_WIDTH, ExercisePanel, ScrollingPanel
from feelflow.app.model import readouts
from feelflow.app.model.readouts import EXERCISE_LENGTH, ReferenceLength
from feelflow.shapes.base import ShapeError

if TYPE_CHECKING:
    from collections.abc import Callable

    from PySide6.QtCore import QSettings
    from PySide6.QtGui import QUndoStack
    from PySide6.QtWidgets import QMainWindow, QStatusBar

    from feelflow.app.gui.force_plot import ForcePlot
    from feelflow.app.gui.side_panel import SidePanel
    from feelflow.app.gui.viewport import Viewport
    from feelflow.app.gui.window.bodies import BodyController
    from feelflow.app.gui.window.events import WindowEvents
    from feelflow.app.gui.window.flow import FlowController
    from feelflow.app.gui.window.frame_loop import FrameLoop
    from feelflow.app.gui.window.replay_controller import ReplayController
    from feelflow.app.model.simulation import Simulation

BROKEN_EDGE = QColor(230, 40, 40)
CHECK_INTERVAL_MS = 250


class ScoreWorker(QThread):
    """Runs one scoring in a thread: chooses the solver as `feelflow exercise score` does by
    default (`grading.resolve_backend` with AUTO: timed once per grid in a child process, then
    remembered in the same file the command line reads), then scores on it. The window keeps
    drawing (numpy releases the GIL in its array kernels, the cpu backend's kernels run
    without it)."""

    progressed = Signal(float)
    chosen = Signal(str, str)      # the backend, the line saying why (empty when named)
    scored = Signal(object)        # scoring.Result
    failed = Signal(str)

    def __init__(self, exercise, shape, parent=None):
        super().__init__(parent)
        self.exercise, self.shape = exercise, shape
        self.backend: str | None = None
        self._cancel = False

    def cancel(self):
        self._cancel = True

    def run(self):
        try:
            # a spawned child: this process may already run numba's OpenMP threads (the live
            # flow on the cpu backend), and a forked child of such a process aborts in them
            self.backend, why = grading.resolve_backend(grading.AUTO, self.exercise,
                                                        mp_context=multiprocessing.get_context("spawn"))
            self.chosen.emit(self.backend, why or "")
            if self._cancel:
                raise scoring.Cancelled()
            result = scoring.score_shape(self.exercise, self.shape, progress=self.progressed.emit,
                                         cancelled=lambda: self._cancel, backend=self.backend)
        except scoring.Cancelled:
            self.failed.emit("cancelled")
        except Exception as exc:  # noqa: BLE001 - shown in one line in the panel, not a traceback
            self.failed.emit(str(exc).splitlines()[0] if str(exc) else type(exc).__name__)
        else:
            self.scored.emit(result)


class ExerciseController(QObject):
    """Owns the open exercise, its panel (a dock) and its attempts; `window` is the MainWindow."""

    attemptAdded = Signal(object)   # attempts.Attempt

    def __init__(self, events: "WindowEvents", viewport: "Viewport", loop: "FrameLoop", side_panel: "SidePanel",
                 plot: "ForcePlot", undo: "QUndoStack", replays: "ReplayController", flow: "FlowController",
                 bodies: "BodyController", settings: "QSettings", status: "QStatusBar",
                 make_current: "Callable[[], None]", window: "QMainWindow"):
        """`window`: the main window, as the holder of the exercise's dock (beside the side
        panel's) and the dialogs' parent."""
        super().__init__(window)
        self.window = window
        self.viewport, self.loop, self.side_panel, self.plot, self.undo = viewport, loop, side_panel, plot, undo
        self.replays, self.flow, self.bodies, self.settings = replays, flow, bodies, settings
        self.status, self.make_current = status, make_current
        self.sim: "Simulation | None" = None   # the live tunnel, once it exists (events.liveCreated)
        events.liveCreated.connect(self._live_created)
        self.exercise = None
        self.attempts = None
        self.panel = None
        self.dock = None
        self.worker = None
        self.problems: list[str] = []
        self.param_shape = None      # the built-in body the parameter fields describe
        self.last_result = None
        self.scored_on = None        # the solver the last score ran on (numpy or cpu)
        self.timer = QTimer(self)
        self.timer.setInterval(CHECK_INTERVAL_MS)
        self.timer.timeout.connect(self.refresh_constraints)
        self.timer.timeout.connect(self.refresh_live)

    def _live_created(self, sim):
        self.sim = sim

    # --- menus -------------------------------------------------------------------------------
    def build_menu(self, bar, presets_menu=None):
        from feelflow.app.exercises.format import load_exercise
        from feelflow.app.model.presets import EXERCISES_ENTRY

        menu = bar.addMenu("E&xercises")
        for path in sorted(EXERCISE_DIR.glob("*.toml")):
            try:
                title = load_exercise(path).title
            except UserError:
                continue
            self._action(menu, title, lambda _=False, p=path: self.open(p))
        menu.addSeparator()
        self._action(menu, "Open exercise file\u2026", self.open_dialog)
        self._action(menu, "Work folder for attempts\u2026", self.work_folder_dialog)
        self.close_action = self._action(menu, "Close exercise", self.close)
        self.close_action.setEnabled(False)
        if presets_menu is not None:
            presets_menu.addSeparator()
            title, name = EXERCISES_ENTRY
            self._action(presets_menu, title, lambda _=False: self.open(EXERCISE_DIR / name))
        return menu

    def _action(self, menu, text, slot):
        act = QAction(text, self.window)
        act.triggered.connect(slot)
        menu.addAction(act)
        return act

    @property
    def work_folder(self) -> Path:
        default = Path.home() / "FeelFlow" / "exercises"
        return Path(self.settings.value("exercises/work_folder", str(default)))

    @work_folder.setter
    def work_folder(self, folder):
        self.settings.setValue("exercises/work_folder", str(folder))

    def work_folder_dialog(self, _=False):
        folder = QFileDialog.getExistingDirectory(self.window, "Work folder for attempts", str(self.work_folder))
        if folder:
            self.work_folder = folder
            if self.exercise is not None:
                self._load_attempts()

    def open_dialog(self, _=False):
        path, _ = QFileDialog.getOpenFileName(self.window, "Open exercise", str(EXERCISE_DIR), "Exercises (*.toml)")
        if path:
            self.open(path)

    # --- opening -----------------------------------------------------------------------------
    def open(self, path) -> bool:
        """Load the exercise, set the tunnel up as it is scored, install its starting shape and
        show its panel; a dialog (one line) for a bad file."""
        from feelflow.app.exercises.format import load_exercise
        from feelflow.app.model.scene import scene_from_dict
        from feelflow.app.shape_files import load_shape

        if self.sim is None or self.replays.refuse("exercises run in the live tunnel"):
            return False
        if self.worker is not None:
            QMessageBox.information(self.window, "Scoring is running", "Wait for the score or cancel it first.")
            return False
        try:
            exercise = load_exercise(path)
            start = load_shape(exercise.start)
            s = exercise.scene
            scene = scene_from_dict(s.live_scene(), exercise.source)   # the scored flow, in float32
            self.make_current()
            self.sim.load_scene(scene)
        except (UserError, ShapeError, ValueError) as exc:
            self.flow.refuse_dialog("This exercise cannot be opened", exc)
            return False
        self.exercise = exercise
        # the live readouts use the length the score uses (app/model/readouts.py)
        self.sim.reference_override = ReferenceLength(s.reference_length, EXERCISE_LENGTH)
        self.undo.clear()
        self.bodies.set_hold_still(True)
        self._ensure_panel()
        self.panel.show_exercise(exercise)
        self.dock.show()
        self.dock.raise_()
        self.install_shape(start)
        self._load_attempts()
        self.close_action.setEnabled(True)
        self.side_panel.show_params(self.sim.params, self.loop.display_mode)
        self.flow.after_rebuild()
        self.loop.set_paused(False)
        self.timer.start()
        self.refresh_constraints()
        self.status.showMessage(f"Exercise: {exercise.title}", 10000)
        QTimer.singleShot(0, self.fit_tunnel)   # once the docks have their new sizes
        return True

    def fit_tunnel(self):
        """Give the viewport the exercise tunnel's shape: the forces plot below takes the height
        a wide, low tunnel leaves empty, so the tunnel fills the viewport's width and height."""
        w = self.window
        vp, plot_dock = self.viewport, self.plot.parentWidget()
        if self.exercise is None or self.sim is None or not isinstance(plot_dock, QDockWidget):
            return
        self.dock.raise_()
        from feelflow.app.gui.display_modes import COLOUR_BAR_MARGIN

        nx, ny = self.sim.config.nx, self.sim.config.ny
        wanted = max(vp.minimumHeight(), int(math.ceil((vp.width() - COLOUR_BAR_MARGIN) * ny / nx)) + 8)
        spare = vp.height() - wanted
        if spare > 0:
            w.resizeDocks([plot_dock], [plot_dock.height() + spare], Qt.Vertical)

    def _ensure_panel(self):
        if self.panel is not None:
            return
        self.panel = ExercisePanel()
        self.panel.scoreRequested.connect(self.score)
        self.panel.cancelRequested.connect(self.cancel)
        self.panel.attemptChosen.connect(self.load_attempt)
        self.panel.parametersChanged.connect(self._parameters_changed)
        w = self.window
        self.panel.editToggled.connect(self.bodies.set_editing)
        self.side_panel.edit.toggled.connect(self._show_editing)
        self.dock = QDockWidget("Exercise", w)
        self.dock.setObjectName("exercise_dock")
        self.dock.setWidget(ScrollingPanel(self.panel))
        self.dock.setFeatures(QDockWidget.DockWidgetMovable | QDockWidget.DockWidgetClosable)
        # a tab beside the Controls (one column of panels: the tunnel keeps the window's width),
        # the column full height (the forces plot below grows when the tunnel is wide and low)
        w.setCorner(Qt.BottomRightCorner, Qt.RightDockWidgetArea)
        w.setCorner(Qt.TopRightCorner, Qt.RightDockWidgetArea)
        controls = self.side_panel.parentWidget()
        if isinstance(controls, QDockWidget) and w.dockWidgetArea(controls) != Qt.NoDockWidgetArea:
            w.tabifyDockWidget(controls, self.dock)
        else:
            w.addDockWidget(Qt.RightDockWidgetArea, self.dock)
        w.resizeDocks([self.dock], [PANEL_WIDTH], Qt.Horizontal)

    def _show_editing(self, on: bool):
        """The Controls panel's Edit vertices button and the exercise panel's show the same."""
        self.panel.edit.blockSignals(True)
        self.panel.edit.setChecked(on)
        self.panel.edit.blockSignals(False)

    def _load_attempts(self):
        from feelflow.app.exercises.attempts import Attempts

        try:
            self.attempts = Attempts(self.exercise, self.work_folder)
        except UserError as exc:
            QMessageBox.warning(self.window, "The attempts file cannot be read",
                                f"{exc}\nNew attempts are not saved until it is fixed or moved away.")
            self.attempts = None
        self._show_attempts()

    def _show_attempts(self):
        if self.attempts is None:
            self.panel.set_attempts([], None, "nowhere: the attempts file is unreadable")
        else:
            self.panel.set_attempts(self.attempts.items, self.attempts.best(), str(self.attempts.path),
                                    self.exercise.objective.uncertainty)

    def close(self, _=False):
        if self.worker is not None:
            self.cancel()
        self.timer.stop()
        self.exercise = None
        if self.sim is not None:
            self.sim.reference_override = None
        self.viewport.body_edge = None
        if self.dock is not None:
            self.dock.hide()
        self.close_action.setEnabled(False)

    # --- the shape -----------------------------------------------------------------------------
    def current_shape(self):
        """The shape the student has now: the edited polygon, or the parameter fields' body."""
        if self.exercise is None:
            return None
        if "polygon" in self.exercise.kinds and self.sim.params.shape == "polygon":
            return self.sim.shape
        return self.param_shape

    def install_shape(self, shape):
        """Put a shape (a start shape, a loaded attempt) into the editor and the tunnel."""
        if shape.kind in PARAMETERS:
            self.panel.set_parameters(shape)
            return self._parameters_changed()
        self.make_current()
        self.sim.set_shape(kind="polygon", polygon=[tuple(v) for v in shape.vertices],
                        angle_deg=math.degrees(shape.angle))
        self.param_shape = None
        self.side_panel.show_params(self.sim.params, self.loop.display_mode)
        self.viewport.update()
        self.refresh_constraints()
        return True

    def _parameters_changed(self):
        """Build the body from the parameter fields and show it in the tunnel (as a polygon with
        the body's exact vertices, or a cylinder)."""
        from feelflow.shapes.io import from_dict

        try:
            shape = from_dict(self.panel.parameters())
        except ShapeError as exc:
            self.problems = [str(exc).splitlines()[0]]
            self.panel.set_problems(self.problems)
            return False
        self.param_shape = shape
        try:
            self.make_current()
            if shape.kind == "cylinder":
                self.sim.set_shape(kind="cylinder", size=shape.diameter, angle_deg=math.degrees(shape.angle))
            else:
                self.sim.set_shape(kind="polygon", polygon=[tuple(v) for v in shape.local_vertices],
                                angle_deg=math.degrees(shape.angle))
        except (ShapeError, ValueError):
            pass    # too big for the tunnel: the constraints say so
        self.side_panel.show_params(self.sim.params, self.loop.display_mode)
        self.viewport.update()
        self.refresh_constraints()
        return True

    def refresh_constraints(self):
        """Check the shape now against the exercise; show what is broken, outline the body."""
        from feelflow.app.exercises.constraints import check_shape

        if self.exercise is None or self.panel is None:
            return
        shape = self.current_shape()
        try:
            problems = check_shape(self.exercise, shape) if shape is not None else ["no shape yet"]
        except (ShapeError, ValueError) as exc:
            problems = [str(exc).splitlines()[0]]
        if problems != self.problems or not self.panel.constraints.text():
            self.problems = problems
            self.panel.set_problems(problems)
        edge = BROKEN_EDGE if problems else None
        if self.viewport.body_edge != edge:
            self.viewport.body_edge = edge
            self.viewport.update()

    def refresh_live(self):
        """The panel's line of the live tunnel's coefficients, as the plot shows them."""
        sim = self.sim
        if self.exercise is None or self.panel is None or sim is None:
            return
        self.panel.show_live(readouts.readout(sim.history, sim.params.force_model, sim.reference_length()))

    # --- scoring -------------------------------------------------------------------------------
    def score(self, _=False) -> bool:
        """Score the current shape in a worker thread; refused (with the reasons) while a
        constraint is broken."""
        if self.exercise is None or self.worker is not None:
            return False
        self.refresh_constraints()
        if self.problems:
            QMessageBox.warning(self.window, "This shape cannot be scored yet",
                                "It breaks the exercise's constraints:\n- " + "\n- ".join(self.problems))
            return False
        shape = self.current_shape()
        self.worker = ScoreWorker(self.exercise, shape, self)
        self.worker.progressed.connect(self.panel.set_progress)
        self.worker.chosen.connect(self._backend_chosen)
        self.worker.scored.connect(lambda result, s=shape: self._scored(s, result))
        self.worker.failed.connect(self._failed)
        self.worker.finished.connect(self._worker_done)
        self.panel.set_running(True)
        self.panel.result.setText("Scoring: choosing the solver (numpy or the compiled cpu backend, float64: "
                                  "the same scores; timed once for this grid)\u2026")
        self.worker.start()
        return True

    def _backend_chosen(self, backend, why):
        self.scored_on = backend
        text = f"Scoring: the tunnel runs the exercise's scoring simulation ({backend}, float64)\u2026"
        if backend == "cpu":
            text += "<br><small>The first run on this machine compiles the solver (20 - 60 s).</small>"
        self.panel.result.setText(text)
        if why:
            self.status.showMessage(f"Exercise: {why}", 10000)

    def cancel(self, _=False):
        if self.worker is not None:
            self.worker.cancel()

    def _worker_done(self):
        self.worker.deleteLater()
        self.worker = None
        self.panel.set_running(False, not self.problems)

    def _failed(self, message):
        self.panel.result.setText("Scoring cancelled." if message == "cancelled" else f"Scoring failed: {message}")
        self.panel.set_progress(0.0)

    def _scored(self, shape, result):
        self.last_result = result
        ex = self.exercise
        if result.ok:
            o = ex.objective
            u = o.uncertainty
            s = ex.scene
            lines = [f"<b>Score {fmt(result.score, u, with_uncertainty=True)}</b> ({o.quantity}; "
                     f"C_D {fmt(result.cd, u)}, C_L {fmt(result.cl, u)} "
                     f"with L = {s.reference_length:g} cells ({EXERCISE_LENGTH}), U = {s.inflow_speed:.3f}; "
                     f"{result.steps} steps, {result.seconds:.1f} s on {self.scored_on})"]
            if result.hit is not None:
                lines.append("A hit: within the tolerance." if result.hit else "Not a hit yet: outside the tolerance.")
            for ref in ex.references:
                word = standing(result.score, ref.score, o.better, u)
                lines.append(f"{word} the reference \u201c{ref.label}\u201d ({fmt(ref.score, u)})")
            lines.append(f"<small>{result.averaging}</small>")
            self.panel.result.setText("<br>".join(lines))
        else:
            self.panel.result.setText(f"<b>Not settled</b>: {result.reason}. No score is given for this run.")
        if self.attempts is not None:
            try:
                attempt = self.attempts.add(shape, result)
            except OSError as exc:
                QMessageBox.warning(self.window, "The attempt could not be saved", str(exc))
            else:
                self.attemptAdded.emit(attempt)
        self._show_attempts()

    def load_attempt(self, index: int) -> bool:
        if self.attempts is None or not 0 <= index < len(self.attempts.items) or self.worker is not None:
            return False
        try:
            shape = self.attempts.items[index].load_shape()
        except ShapeError as exc:
            QMessageBox.warning(self.window, "This attempt cannot be loaded", str(exc))
            return False
        return self.install_shape(shape)

    def shutdown(self):
        """Stop a running scoring and wait for its thread (the window is closing)."""
        if self.worker is not None:
            self.worker.cancel()
            self.worker.wait()
