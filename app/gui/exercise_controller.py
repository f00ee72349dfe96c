"""Exercise mode in the window: opening and closing an exercise, and the wiring between its
parts, each in a module of its own:

    ExerciseMenu      exercise_menu.py         the Exercises menu and its file dialog
    ExercisePanel     exercise_panel.py        the panel's widgets (goal, parameters, score, attempts)
    ShapeFields       exercise_shape_fields.py the panel's built-in body fields (kind, sizes, angle)
    thumbnail         exercise_thumbnail.py    an attempt's outline as the list's picture
    ExerciseDock      exercise_dock.py         where the panel sits (scrolling); the tunnel fitted to the viewport
    StudentShape      exercise_shape.py        the student's shape and how it reaches the tunnel
    ConstraintWatch   exercise_constraints.py  what the shape breaks, named, the body outlined
    ScoringRunner     exercise_scoring.py      Score it in a worker thread, on the command line's solver
    ExerciseAttempts  exercise_attempts.py     the work folder and the attempts file

The physics and the words stay Qt-free in app/exercises/ (the file, the constraints, scoring,
the attempts file, the panel's words and the result's text, the parameter fields' values).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtCore import QObject, QTimer
from PySide6.QtWidgets import QMessageBox

from feelflow.app.errors import UserError
from feelflow.app.exercises import score_text
from feelflow.app.gui.exercise_attempts import ExerciseAttempts
from feelflow.app.gui.exercise_constraints import ConstraintWatch
from feelflow.app.gui.exercise_dock import ExerciseDock
from feelflow.app.gui.exercise_menu import ExerciseMenu
from feelflow.app.gui.exercise_panel import ExercisePanel
from feelflow.app.gui.exercise_scoring import ScoringRunner
from feelflow.app.gui.exercise_shape import StudentShape
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

#: how often the constraints and the panel's live line are refreshed while an exercise is open
CHECK_INTERVAL_MS = 250


class ExerciseController(QObject):
    """The open exercise (`exercise`, None when none is) and the wiring of its parts: `menu`,
    `panel`, `dock` (made when the first exercise opens), `shape`, `constraints`, `scoring`,
    `attempts`."""

    def __init__(self, events: "WindowEvents", viewport: "Viewport", loop: "FrameLoop", side_panel: "SidePanel",
                 plot: "ForcePlot", undo: "QUndoStack", replays: "ReplayController", flow: "FlowController",
                 bodies: "BodyController", settings: "QSettings", status: "QStatusBar",
                 make_current: "Callable[[], None]", window: "QMainWindow"):
        """`window`: the main window, as the holder of the exercise's dock (beside the side
        panel's) and the dialogs' parent."""
        super().__init__(window)
        self.window = window
        self.viewport, self.loop, self.side_panel, self.plot, self.undo = viewport, loop, side_panel, plot, undo
        self.replays, self.flow, self.bodies = replays, flow, bodies
        self.status, self.make_current = status, make_current
        self.sim: "Simulation | None" = None   # the live tunnel, once it exists (events.liveCreated)
        events.liveCreated.connect(self._live_created)
        self.exercise = None
        self.dock: ExerciseDock | None = None
        self.panel = ExercisePanel()
        self.attempts = ExerciseAttempts(settings, self.panel, window)
        self.menu = ExerciseMenu(window, self.open, self.attempts.choose_work_folder, self.close)
        self.shape = StudentShape(events, self.panel, side_panel, viewport, loop, make_current, self)
        self.constraints = ConstraintWatch(self.panel, viewport)
        self.scoring = ScoringRunner(self)
        self._connect()
        self.timer = QTimer(self)
        self.timer.setInterval(CHECK_INTERVAL_MS)
        self.timer.timeout.connect(self.refresh_constraints)
        self.timer.timeout.connect(self.refresh_live)

    def _connect(self):
        p = self.panel
        p.scoreRequested.connect(self.score)
        p.cancelRequested.connect(self.scoring.cancel)
        p.attemptChosen.connect(self.load_attempt)
        p.parametersChanged.connect(self.shape.parameters_changed)
        p.editToggled.connect(self.bodies.set_editing)
        self.side_panel.edit.toggled.connect(p.show_editing)   # both Edit vertices buttons show the same
        self.shape.changed.connect(self.refresh_constraints)
        self.shape.unbuildable.connect(lambda reason: self.constraints.name([reason]))
        s = self.scoring
        s.progressed.connect(p.set_progress)
        s.chosen.connect(self._backend_chosen)
        s.scored.connect(self._scored)
        s.failed.connect(self._failed)
        s.finished.connect(lambda: p.set_running(False, not self.constraints.problems))

    def _live_created(self, sim):
        self.sim = sim

    def build_menu(self, bar, presets_menu=None):
        return self.menu.build(bar, presets_menu)

    # --- opening and closing ---------------------------------------------------------------------
    def open(self, path) -> bool:
        """Load the exercise, set the tunnel up as it is scored, install its starting shape and
        show its panel; a dialog (one line) for a bad file."""
        from feelflow.app.exercises.format import load_exercise
        from feelflow.app.model.scene import scene_from_dict
        from feelflow.app.shape_files import load_shape

        if self.sim is None or self.replays.refuse("exercises run in the live tunnel"):
            return False
        if self.scoring.running:
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
        if self.dock is None:
            self.dock = ExerciseDock(self.panel, self.side_panel.parentWidget(), self.window)
        self.panel.show_exercise(exercise)
        self.dock.bring_forward()
        self.shape.install(start)
        self.attempts.load(exercise)
        self.menu.set_open(True)
        self.side_panel.show_params(self.sim.params, self.loop.display.mode)
        self.flow.after_rebuild()
        self.loop.set_paused(False)
        self.timer.start()
        self.refresh_constraints()
        self.status.showMessage(f"Exercise: {exercise.title}", 10000)
        QTimer.singleShot(0, self.fit_tunnel)   # once the docks have their new sizes
        return True

    def fit_tunnel(self):
        """The tunnel fills the viewport: the forces plot below takes the height it leaves."""
        if self.exercise is None or self.sim is None or self.dock is None:
            return
        self.dock.fit_tunnel(self.viewport, self.plot.parentWidget(), self.sim.config.nx, self.sim.config.ny)

    def close(self, _=False):
        if self.scoring.running:
            self.scoring.cancel()
        self.timer.stop()
        self.exercise = None
        self.attempts.close()
        if self.sim is not None:
            self.sim.reference_override = None
        self.constraints.clear()
        if self.dock is not None:
            self.dock.hide()
        self.menu.set_open(False)

    # --- the shape and its checks --------------------------------------------------------------
    def current_shape(self):
        """The shape the student has now (StudentShape.current)."""
        return self.shape.current(self.exercise)

    def refresh_constraints(self):
        """Check the shape now against the exercise; show what is broken, outline the body."""
        if self.exercise is not None:
            self.constraints.check(self.exercise, self.current_shape())

    def refresh_live(self):
        """The panel's line of the live tunnel's coefficients, as the plot shows them."""
        sim = self.sim
        if self.exercise is None or sim is None:
            return
        self.panel.show_live(readouts.readout(sim.history, sim.params.force_model, sim.reference_length()))

    def load_attempt(self, index: int) -> bool:
        if self.scoring.running:
            return False
        shape = self.attempts.shape(index)
        return shape is not None and self.shape.install(shape)

    # --- scoring -------------------------------------------------------------------------------
    def score(self, _=False) -> bool:
        """Score the current shape in a worker thread; refused (with the reasons) while a
        constraint is broken."""
        if self.exercise is None or self.scoring.running:
            return False
        self.refresh_constraints()
        if self.constraints.problems:
            QMessageBox.warning(self.window, "This shape cannot be scored yet",
                                "It breaks the exercise's constraints:\n- " + "\n- ".join(self.constraints.problems))
            return False
        self.panel.set_running(True)
        self.panel.show_result(score_text.CHOOSING)
        return self.scoring.start(self.exercise, self.current_shape())

    def cancel(self, _=False):
        self.scoring.cancel()

    def _backend_chosen(self, backend, why):
        self.panel.show_result(score_text.running_text(backend))
        if why:
            self.status.showMessage(f"Exercise: {why}", 10000)

    def _failed(self, message):
        self.panel.show_result(score_text.failed_text(message))
        self.panel.set_progress(0.0)

    def _scored(self, shape, result):
        self.panel.show_result(score_text.result_html(self.exercise, result, self.scoring.backend))
        self.attempts.add(shape, result)

    def shutdown(self):
        """Stop a running scoring and wait for its thread (the window is closing)."""
        self.scoring.shutdown()
