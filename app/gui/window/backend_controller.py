"""Which solver backend the window runs, and the Run > Solver backend menu.

"Automatic" (the default) times the backends briefly on the window's grid once the OpenGL
context exists and keeps the fastest, remembered in QSettings per (GL renderer, grid)
(app/model/backend_choice.py: the same choice as `feelflow run --backend auto`). The status bar
says which backend runs and the steps per second it was measured at. A choice made in the menu
is remembered and takes effect at the next start: the window never switches backend while a
lesson runs.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtGui import QAction, QActionGroup
from PySide6.QtWidgets import QApplication

from feelflow.app.model.backend_choice import CANDIDATES, choose_backend
from feelflow.app.model.flow_choice import default_base_config

if TYPE_CHECKING:
    from PySide6.QtCore import QSettings
    from PySide6.QtWidgets import QStatusBar

    from feelflow.app.gui.viewport import Viewport

SETTINGS_KEY = "backend"
REMEASURE_KEY = "backend_remeasure"
CHOICES = ("auto",) + CANDIDATES
LABELS = {"auto": "Automatic (the fastest here)", "cpu": "cpu (compiled, on the processor)",
          "gl": "gl (OpenGL shaders)", "numpy": "numpy (the reference)"}


class QSettingsStore:
    """backend_choice's store interface on the window's QSettings."""

    def __init__(self, settings):
        self.settings = settings

    def get(self, key: str) -> str | None:
        value = self.settings.value(f"backend_choice/{key}", None)
        return str(value) if value is not None else None

    def set(self, key: str, value: str) -> None:
        self.settings.setValue(f"backend_choice/{key}", value)


class BackendController:
    """Resolves "auto" to a backend when the context is ready; owns the backend menu."""

    def __init__(self, settings: "QSettings", viewport: "Viewport", status: "QStatusBar", requested: str):
        self.settings, self.viewport, self.status = settings, viewport, status
        self.requested = requested
        self.description = ""   # why this backend runs, for the status bar's tooltip
        self.measured = None     # steps per second it was measured at on start, if it was

    def resolve(self, ctx, grid) -> str:
        """The backend to build the tunnel of `grid` (nx, ny) with; for "auto", measured (or
        remembered) now."""
        if self.requested != "auto":
            if self.requested == "gl" and ctx is None:   # no OpenGL 3.3 (first_start): the CPU
                self.description = "numpy solver (no OpenGL 3.3 here)"
                return "numpy"
            self.description = f"{self.requested} solver (chosen in the menu or with --backend)"
            return self.requested
        settings = self.settings
        remeasure = str(settings.value(REMEASURE_KEY, "false")).lower() == "true"
        candidates = CANDIDATES if ctx is not None else tuple(c for c in CANDIDATES if c != "gl")
        self.status.showMessage("Measuring the solver backends on this machine\u2026")
        QApplication.processEvents()

        def make_solver(name, config):
            from feelflow.solver.backend import create_solver

            return create_solver(name, config, ctx=ctx)

        config = default_base_config(grid)
        try:
            choice = choose_backend(config, make_solver, QSettingsStore(settings), renderer=self.viewport.renderer(),
                                    candidates=candidates, remeasure=remeasure)
        except RuntimeError:
            self.description = "numpy solver (no other backend runs here)"
            return "numpy"
        settings.setValue(REMEASURE_KEY, "false")
        if choice.remembered:
            self.description = f"{choice.backend} solver (the fastest here, measured before)"
        else:
            rates = ", ".join(t.describe() for t in choice.timings)
            self.measured = next(t.steps_per_s for t in choice.timings if t.backend == choice.backend)
            self.description = f"{choice.backend} solver (the fastest here: {rates})"
        self.status.clearMessage()
        return choice.backend

    def status_text(self, renderer: str, backend: str) -> str:
        """The status bar's renderer label: the renderer, the backend, its measured speed."""
        text = f"{renderer}, {backend} solver"
        return text + (f", {self.measured:.0f} steps/s measured" if self.measured else "")

    def build_menu(self, menu) -> None:
        """Run > Solver backend: Automatic / cpu / gl / numpy, and Measure again."""
        sub = menu.addMenu("Solver &backend")
        group = QActionGroup(sub)
        current = str(self.settings.value(SETTINGS_KEY, "auto"))
        for key in CHOICES:
            act = QAction(LABELS[key], sub, checkable=True)
            act.setChecked(key == current)
            act.triggered.connect(lambda _=False, k=key: self.set_requested(k))
            group.addAction(act)
            sub.addAction(act)
        sub.addSeparator()
        again = QAction("Measure again at the next start", sub)
        again.triggered.connect(self.remeasure)
        sub.addAction(again)

    def set_requested(self, key: str) -> None:
        self.settings.setValue(SETTINGS_KEY, key)
        self.status.showMessage(f"Solver backend: {LABELS[key]}, from the next start of FeelFlow "
                                       "(the running tunnel keeps its backend).", 8000)

    def remeasure(self) -> None:
        self.settings.setValue(REMEASURE_KEY, "true")
        self.settings.setValue(SETTINGS_KEY, "auto")
        self.status.showMessage("The backends will be measured again at the next start of FeelFlow.", 8000)


def requested_backend(option: str | None, settings) -> str:
    """The backend asked for: the command line's --backend, else the menu's remembered choice."""
    if option:
        return option
    value = str(settings.value(SETTINGS_KEY, "auto"))
    return value if value in CHOICES else "auto"
