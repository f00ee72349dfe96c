"""The FeelFlow window: the wind-tunnel viewport in the middle, the side panel, the live force
plot below, the status bar; assembly only. What the window does lives in its controllers,
app/gui/window/, one module per concept, each an object given what it works on at construction
(the window itself only where it needs the menus' actions or the docks) and the live tunnel
through `events.liveCreated`:

    window.store    settings.py    WindowSettings: remembered parameters, polygon, mode, geometry
    window.actions  menus.py       the menus, shortcuts and replay toolbar (`build_menus`)
    window.loop     frame_loop.py  FrameLoop: the frame timer, adaptive stepping, pause; its parts:
      .display      field_display.py  FieldDisplay: the display mode, the field into the viewport
      .overlays     flow_overlays.py  FlowOverlays: tracers, force arrows, torque arc
      .readouts     frame_readouts.py FrameReadouts: panel numbers, plot, status bar (rates: frame_rates.py)
    window.replays  replay_controller.py  ReplayController: recording, and replaying a session
    window.inputs   input_controller.py   InputController: mouse or haptic device; body input to the model
    window.bodies   bodies.py      BodyController: shape, polygon editor (undo), turning the body
    window.flow     flow.py        FlowController: wind, viscosity, walls, grid, models, reset
    window.exports  exports.py     ExportController: CSV, plot PNG, screenshot, shape files
    window.lessons  lessons.py     LessonController: the Presets menu's lessons
    window.video    video.py       VideoController: a session rendered to MP4/GIF, the window recorded
    window.probes   probes.py      ProbeController: probes placed in the view, their plot beside the forces
    window.units    units.py       UnitsController: View > Units, lattice or SI for a chosen fluid
    window.backends backend_controller.py  BackendController: which solver backend runs, its menu
    window.exercises  app/gui/exercise_controller.py  ExerciseController: opening an exercise; its menu,
                      panel, shape, constraint checks, scoring and attempts (app/gui/exercise_*.py)

The model behind the view is a `TunnelModel` (app/model/tunnel.py): `window.shown` is the one
drawn (the live `window.sim`, or a replay), and every body input reaches it as a `BodyInput`
through `TunnelModel.drive`.

To add a menu entry: one `add_action(menu, text, slot, shortcut)` line in
app/gui/window/menus.py `build_menus`, with `slot` a controller's method. To add a controller:
a module in app/gui/window/ with a class taking what it works on; create it in `MainWindow.__init__`
under "controllers" (before `build_menus`, so menus can point at it), connect the widgets'
signals to it in `_connect`, and list it above.
"""
from __future__ import annotations

from PySide6.QtCore import QEvent, QSettings, Qt, QTimer, Signal
from PySide6.QtGui import QUndoStack
from PySide6.QtWidgets import QAbstractButton, QApplication, QDockWidget, QLabel, QMainWindow, QMessageBox

from feelflow.app.gui.qt_runtime import make_none_immortal

make_none_immortal()  # before any Qt object: see app/gui/qt_runtime.py

from feelflow.app.gui import first_start  # noqa: E402
from feelflow.app.gui.exercise_controller import ExerciseController  # noqa: E402
from feelflow.app.gui.force_plot import ForcePlot  # noqa: E402
from feelflow.app.gui.side_panel import SidePanel  # noqa: E402
from feelflow.app.gui.display_modes import DISPLAY_MODES  # noqa: E402
from feelflow.app.gui.view_mouse import MOUSE_HINT  # noqa: E402
from feelflow.app.gui.viewport import Viewport  # noqa: E402
from feelflow.app.gui.window.backend_controller import BackendController  # noqa: E402
from feelflow.app.gui.window.bodies import BodyController  # noqa: E402
from feelflow.app.gui.window.exports import ExportController  # noqa: E402
from feelflow.app.gui.window.flow import FlowController  # noqa: E402
from feelflow.app.gui.window.field_display import FieldDisplay  # noqa: E402
from feelflow.app.gui.window.flow_overlays import FlowOverlays  # noqa: E402
from feelflow.app.gui.window.frame_loop import FrameLoop  # noqa: E402
from feelflow.app.gui.window.frame_rates import FrameRates  # noqa: E402
from feelflow.app.gui.window.frame_readouts import FrameReadouts  # noqa: E402
from feelflow.app.gui.window.input_controller import InputController  # noqa: E402
from feelflow.app.gui.window.lessons import LessonController  # noqa: E402
from feelflow.app.gui.window.events import WindowEvents  # noqa: E402
from feelflow.app.gui.window.menus import build_menus  # noqa: E402
from feelflow.app.gui.window.replay_controller import ReplayController  # noqa: E402
from feelflow.app.gui.window.settings import WindowSettings  # noqa: E402
from feelflow.app.gui.window.probes import ProbeController  # noqa: E402
from feelflow.app.gui.window.units import UnitsController  # noqa: E402
from feelflow.app.gui.window.video import VideoController  # noqa: E402
from feelflow.app.model.simulation import Params, Simulation  # noqa: E402
from feelflow.app.model.tunnel import TunnelModel  # noqa: E402
from feelflow.shapes.base import ShapeError  # noqa: E402
from feelflow.solver.config import ConfigError  # noqa: E402


class MainWindow(QMainWindow):
    simulationReady = Signal()

    def __init__(self, backend: str = "gl", settings: QSettings | None = None, params: Params | None = None):
        super().__init__()
        self.setWindowTitle("FeelFlow \u2013 a wind tunnel you can touch")
        self.backend = backend
        self.settings = settings or QSettings("FeelFlow", "FeelFlow")
        self.store = WindowSettings(self.settings)
        self.sim: Simulation | None = None   # the live tunnel, once the GL context exists
        self.startup_error = None
        self.undo = QUndoStack(self)

        # widgets
        self.viewport = Viewport()
        self.setCentralWidget(self.viewport)
        self.panel = SidePanel()
        self.plot = ForcePlot()
        for button in self.panel.findChildren(QAbstractButton) + self.plot.findChildren(QAbstractButton):
            button.setFocusPolicy(Qt.TabFocus)   # a click leaves the focus (and Space = pause) where it was
        self._dock("Controls", self.panel, Qt.RightDockWidgetArea)
        plot_dock = self._dock("Forces", self.plot, Qt.BottomDockWidgetArea)
        self.resizeDocks([plot_dock], [230], Qt.Vertical)
        self.status = {k: QLabel() for k in ("steps", "mlups", "fps", "re", "ma", "operator", "renderer")}
        for label in self.status.values():
            self.statusBar().addPermanentWidget(label)

        # controllers, and the events they tell each other (window/events.py)
        self.events = WindowEvents(self)
        vp, events, panel, plot, status = self.viewport, self.events, self.panel, self.plot, self.statusBar()
        display = FieldDisplay(vp, panel, self.params_now, self.make_current)
        rates = FrameRates()
        readouts = FrameReadouts(events, panel, plot, self.status, display, rates)
        self.loop = loop = FrameLoop(events, vp, plot, display, FlowOverlays(vp, display), readouts, rates, status,
                                     self.make_current, self)
        self.probes = ProbeController(events, vp, plot, loop, status, self)
        self.plot.export.probes = self.probes.probes   # the forces CSV carries the probes' columns
        self.units = UnitsController(events, self.settings, panel, plot, self.probes, loop, status, self)
        self.replays = replays = ReplayController(events, vp, loop, panel, self.probes, self.units, status,
                                                  self.make_current, lambda: self.backend, self)
        self.flow = FlowController(events, vp, loop, panel, plot, replays, status, self.make_current, self)
        self.bodies = BodyController(events, vp, loop, panel, self.undo, replays, self.flow, status,
                                     self.make_current, self)
        self.inputs = InputController(events, vp, panel, replays, self.bodies, status, self)
        self.exports = ExportController(events, vp, plot, replays, self.bodies, self)
        self.lessons = LessonController(events, vp, loop, panel, plot, self.undo, replays, self.flow, self.bodies,
                                        status, self.make_current)
        self.video = VideoController(events, vp, loop, status, self)
        self.backends = BackendController(self.settings, vp, status, backend)   # "auto": measured once the context exists
        self.exercises = ExerciseController(events, vp, loop, panel, plot, self.undo, replays, self.flow,
                                            self.bodies, self.settings, status, self.make_current,
                                            self)   # the Exercises menu and panel
        self.actions = build_menus(self)

        self.params = params or self.store.params()
        self.loop.display.mode = self.store.display_mode(DISPLAY_MODES)
        self.panel.show_params(self.params, self.loop.display.mode)
        self._connect()
        self.store.restore_geometry(self)

    def _dock(self, title, widget, area) -> QDockWidget:
        dock = QDockWidget(title, self)
        dock.setWidget(widget)
        dock.setFeatures(QDockWidget.DockWidgetMovable)
        self.addDockWidget(area, dock)
        return dock

    def _connect(self):
        """The widgets' signals to the controllers."""
        p, vp = self.panel, self.viewport
        p.shapeChanged.connect(self.bodies.set_shape_kind)
        p.sizeChanged.connect(lambda v: self.bodies.apply_shape(size=v))
        p.angleChanged.connect(self.bodies.set_angle)
        p.holdStillToggled.connect(self.bodies.set_hold_still)
        p.editToggled.connect(self.bodies.set_editing)
        p.save_shape.clicked.connect(self.exports.save_shape_dialog)
        p.load_shape.clicked.connect(self.exports.load_shape_dialog)
        p.windChanged.connect(lambda v: self.flow.apply(wind=v))
        p.viscosityChanged.connect(lambda v: self.flow.apply(nu=v))
        p.wallChanged.connect(lambda v: self.flow.apply(wall=v))
        p.gridChanged.connect(self.flow.set_grid)
        p.forceModelChanged.connect(lambda m: self.flow.set_force_models(selected=m))
        p.compareAllToggled.connect(lambda on: self.flow.set_force_models(compare_all=on))
        p.displayModeChanged.connect(self.loop.display.set_mode)
        p.arrowsToggled.connect(lambda on: setattr(self.viewport, "show_arrows", on))
        p.inputChanged.connect(self.inputs.set_input)
        vp.contextReady.connect(self.on_context)
        first_start.watch_gl(self)   # no OpenGL 3.3: a dialog, then the numpy solver on the CPU
        vp.bodyPulled.connect(self.inputs.mouse_pulled)
        vp.polygonEdited.connect(self.bodies.edit_polygon)
        vp.inputRefused.connect(lambda: self.replays.refuse("the mouse does not move the body"))
        vp.turnRequested.connect(self.bodies.turn_body)
        vp.turnFinished.connect(self.bodies.turn_done)
        vp.wheelTurned.connect(self.bodies.turn_by_wheel)
        vp.turnRefused.connect(self.bodies.turn_refused)
        vp.probeClicked.connect(self.probes.clicked)

    # --- what the window shows ----------------------------------------------------------------
    @property
    def shown(self) -> TunnelModel | None:
        """What the viewport and the plot show: the replay while one runs, else the live tunnel."""
        return self.replays.shown

    def params_now(self) -> Params:
        return self.sim.params if self.sim is not None else self.params

    def make_current(self):
        """The viewport's GL context current (the gl solver draws into it)."""
        if self.backend == "gl":
            self.viewport.makeCurrent()

    # --- start ------------------------------------------------------------------------------
    def _cannot_start(self, message):
        """No GL or no backend: one plain dialog, then the window closes (exit code 2)."""
        self.startup_error = message
        hint = "" if self.backend == "numpy" else "\nThe numpy solver may work: feelflow gui --backend numpy"
        QTimer.singleShot(0, lambda: (QMessageBox.critical(self, "FeelFlow cannot start", message + hint),
                                      self.close()))

    def on_context(self, ctx):
        from feelflow.solver.backend import BackendError

        self.backend = self.backends.resolve(ctx, self.params.grid)
        try:
            self._create_simulation(ctx)
        except (BackendError, RuntimeError) as exc:
            self._cannot_start(f"The {self.backend} solver cannot run here: {str(exc).splitlines()[0]}")
            return
        self._simulation_started()

    def _create_simulation(self, ctx):
        try:
            self.sim = Simulation(self.params, backend=self.backend, ctx=ctx)
            polygon = self.store.polygon()
            if polygon is not None and self.sim.params.shape == "polygon":
                self.sim.set_shape(polygon=polygon)
        except (ConfigError, ShapeError, ValueError) as exc:   # remembered settings that no longer work
            self.statusBar().showMessage(f"Remembered settings ignored ({exc}); using the defaults.", 8000)
            self.sim = Simulation(Params(), backend=self.backend, ctx=ctx)
        self.events.liveCreated.emit(self.sim)   # every controller keeps the live tunnel
        if self.sim.params.shape == "polygon" and self.sim.polygon is None:
            self.bodies.install_default_polygon()

    def _simulation_started(self):
        self.viewport.mode = self.loop.display.mode
        self.events.shownChanged.emit(self.sim)   # the viewport and the plot show it, its field drawn
        self.panel.show_params(self.sim.params, self.loop.display.mode)
        self.status["renderer"].setText(self.backends.status_text(self.viewport.renderer().split(' (')[0], self.backend))
        self.status["renderer"].setToolTip(f"{self.viewport.renderer()}; {self.backends.description}")
        self.inputs.refresh_devices()
        self.flow.say_guard()
        self.loop.start()
        self.loop.readouts.refresh()
        self.units.start()
        if not self.statusBar().currentMessage():   # a note about ignored settings comes first
            self.statusBar().showMessage(MOUSE_HINT, 20000)
        self.simulationReady.emit()

    # --- keys and closing ---------------------------------------------------------------------
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

    def remember(self):
        """What the next start comes back to (app/gui/window/settings.py)."""
        self.store.remember(self.params_now(), self.sim.polygon if self.sim is not None else None,
                        self.loop.display.mode, self.saveGeometry())

    def closeEvent(self, ev):
        self.remember()
        self.loop.stop()
        self.exercises.shutdown()
        self.video.close()
        self.replays.close()
        self.inputs.close_device()
        super().closeEvent(ev)
