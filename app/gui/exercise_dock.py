"""Where the exercise panel sits in the window: a dock tabbed beside the Controls in the right
column (which takes the window's full height), in front while an exercise opens, the panel
scrolling inside it on a short screen (`ScrollingPanel`); and the
forces plot below the tunnel given the height a wide, low exercise tunnel leaves empty, so the
tunnel fills the viewport's width and height.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QDockWidget, QScrollArea

from feelflow.app.gui.display_modes import COLOUR_BAR_MARGIN

if TYPE_CHECKING:
    from PySide6.QtWidgets import QMainWindow, QWidget

    from feelflow.app.gui.exercise_panel import ExercisePanel
    from feelflow.app.gui.viewport import Viewport


#: the panel's width in the window (logical pixels): the goal, references and attempts lines wrap to it
PANEL_WIDTH = 340
#: the narrowest it gets (the window keeps 1280 pixels with the forces' toolbar below the flow)
PANEL_MIN_WIDTH = 290


class ScrollingPanel(QScrollArea):
    """The exercise panel in a vertical scroll area: on a short screen it scrolls instead of
    squeezing its wrapped lines over each other."""

    def __init__(self, panel: "ExercisePanel"):
        super().__init__()
        self.setObjectName("exercise_scroll")
        self.setWidget(panel)
        self.setWidgetResizable(True)
        self.setHorizontalScrollBarPolicy(Qt.ScrollBarAlwaysOff)
        self.setMinimumWidth(PANEL_MIN_WIDTH)


class ExerciseDock(QDockWidget):
    """The exercise panel's dock in `window`, placed as a tab beside `controls` (the side
    panel's dock) when that is docked, else on the right."""

    def __init__(self, panel: "ExercisePanel", controls: "QWidget | None", window: "QMainWindow"):
        super().__init__("Exercise", window)
        self.main_window = window
        self.setObjectName("exercise_dock")
        self.setWidget(ScrollingPanel(panel))
        self.setFeatures(QDockWidget.DockWidgetMovable | QDockWidget.DockWidgetClosable)
        # a tab beside the Controls (one column of panels: the tunnel keeps the window's width),
        # the column full height (the forces plot below grows when the tunnel is wide and low)
        w = window
        w.setCorner(Qt.BottomRightCorner, Qt.RightDockWidgetArea)
        w.setCorner(Qt.TopRightCorner, Qt.RightDockWidgetArea)
        if isinstance(controls, QDockWidget) and w.dockWidgetArea(controls) != Qt.NoDockWidgetArea:
            w.tabifyDockWidget(controls, self)
        else:
            w.addDockWidget(Qt.RightDockWidgetArea, self)
        w.resizeDocks([self], [PANEL_WIDTH], Qt.Horizontal)

    def bring_forward(self):
        self.show()
        self.raise_()

    def fit_tunnel(self, viewport: "Viewport", plot_dock, nx: int, ny: int):
        """Give the viewport an nx x ny tunnel's shape: the forces plot's dock (`plot_dock`)
        below takes the height a wide, low tunnel leaves empty."""
        if not isinstance(plot_dock, QDockWidget):
            return
        self.raise_()
        vp = viewport
        wanted = max(vp.minimumHeight(), int(math.ceil((vp.width() - COLOUR_BAR_MARGIN) * ny / nx)) + 8)
        spare = vp.height() - wanted
        if spare > 0:
            self.main_window.resizeDocks([plot_dock], [plot_dock.height() + spare], Qt.Vertical)
