"""Files the window writes and reads besides sessions: the forces as CSV, the plot as PNG, a
screenshot of the whole window, and shape files (shapes/io.py). Every write is atomic
(app/files.py, or the plot's own exporter); a failure is one dialog line."""
from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtCore import QPoint
from PySide6.QtGui import QImage, QPainter
from PySide6.QtWidgets import QFileDialog, QMessageBox

from feelflow.app.gui.window.dialogs import attempt
from feelflow.shapes.base import ShapeError

if TYPE_CHECKING:
    from PySide6.QtWidgets import QWidget

    from feelflow.app.gui.force_plot import ForcePlot
    from feelflow.app.gui.viewport import Viewport
    from feelflow.app.gui.window.bodies import BodyController
    from feelflow.app.gui.window.events import WindowEvents
    from feelflow.app.gui.window.replay_controller import ReplayController
    from feelflow.app.model.simulation import Simulation


class ExportController:
    """The File menu's exports and shape files."""

    def __init__(self, events: "WindowEvents", viewport: "Viewport", plot: "ForcePlot", replays: "ReplayController",
                 bodies: "BodyController", window: "QWidget"):
        """`window`: the whole window, as a screenshot shows it and as the dialogs' parent."""
        self.viewport, self.plot, self.replays, self.bodies, self.window = viewport, plot, replays, bodies, window
        self.sim: "Simulation | None" = None   # the live tunnel, once it exists (events.liveCreated)
        events.liveCreated.connect(self._live_created)

    def _live_created(self, sim):
        self.sim = sim

    # --- forces, plot, screenshot -----------------------------------------------------------------
    def export_csv_dialog(self, _=None):
        path, _ = QFileDialog.getSaveFileName(self.window, "Export forces", "forces.csv", "CSV (*.csv)")
        if path:
            attempt(self.window, lambda: self.plot.export_csv(path), "Could not export the forces")

    def export_png_dialog(self, _=None):
        path, _ = QFileDialog.getSaveFileName(self.window, "Export plot", "forces.png", "PNG (*.png)")
        if path:
            attempt(self.window, lambda: self.plot.export_png(path), "Could not export the plot")

    def screenshot_dialog(self, _=None):
        path, _ = QFileDialog.getSaveFileName(self.window, "Save screenshot", "feelflow.png", "PNG (*.png)")
        if path:
            attempt(self.window, lambda: self.save_screenshot(path), "Could not save the screenshot")

    def window_image(self) -> QImage:
        """The whole window as shown: QWidget.grab() misses the QPainter overlay of the GL view,
        so the viewport's own rendering is painted over its place."""
        w = self.window
        image = w.grab().toImage()
        painter = QPainter(image)
        painter.drawImage(self.viewport.mapTo(w, QPoint(0, 0)), self.viewport.grabFramebuffer())
        painter.end()
        return image

    def save_screenshot(self, path):
        from feelflow.app.files import atomic_path

        image = self.window_image()
        with atomic_path(path, suffix=".png") as tmp:
            if not image.save(str(tmp), "PNG"):
                raise OSError(f"cannot write {path}")

    # --- shape files ------------------------------------------------------------------------------
    def save_shape_dialog(self, _=None):
        path, _ = QFileDialog.getSaveFileName(self.window, "Save shape", "shape.json", "Shapes (*.json)")
        if path:
            self.save_shape(path)

    def save_shape(self, path):
        from feelflow.app import shape_files as shape_io

        try:
            shape_io.save_shape(path, self.sim.shape)
        except (OSError, ShapeError, ValueError) as exc:
            QMessageBox.warning(self.window, "Could not save the shape", str(exc))

    def load_shape_dialog(self, _=None):
        path, _ = QFileDialog.getOpenFileName(self.window, "Load shape", "", "Shapes (*.json)")
        if path:
            self.load_shape(path)

    def load_shape(self, path):
        """Read a shape file and make it the body (a polygon as an undoable edit)."""
        from feelflow.app import shape_files as shape_io

        if self.replays.refuse("the body follows the recording"):
            return False
        try:
            shape = shape_io.load_shape(path)
        except (OSError, ShapeError, ValueError) as exc:
            QMessageBox.warning(self.window, "Could not load the shape", f"{exc}\nThe previous shape is kept.")
            return False
        return self.bodies.install_loaded_shape(shape)
