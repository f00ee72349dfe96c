"""The Exercises menu: the shipped exercises by title, Open exercise file (a file dialog), Work
folder for attempts, Close exercise; and the Presets menu's entry that opens the shipped
exercises' first one. Each entry calls the slot it is given.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtGui import QAction
from PySide6.QtWidgets import QFileDialog

from feelflow import EXERCISE_DIR
from feelflow.app.errors import UserError

if TYPE_CHECKING:
    from collections.abc import Callable

    from PySide6.QtWidgets import QMainWindow


class ExerciseMenu:
    """`open_exercise(path)`, `choose_work_folder()` and `close_exercise()` are what the entries
    call; `parent` owns the actions and the file dialog."""

    def __init__(self, parent: "QMainWindow", open_exercise: "Callable", choose_work_folder: "Callable",
                 close_exercise: "Callable"):
        self.parent = parent
        self.open_exercise, self.choose_work_folder, self.close_exercise = (open_exercise, choose_work_folder,
                                                                            close_exercise)
        self.close_action: QAction | None = None

    def build(self, bar, presets_menu=None):
        from feelflow.app.exercises.format import load_exercise
        from feelflow.app.model.presets import EXERCISES_ENTRY

        menu = bar.addMenu("E&xercises")
        for path in sorted(EXERCISE_DIR.glob("*.toml")):
            try:
                title = load_exercise(path).title
            except UserError:
                continue
            self._action(menu, title, lambda _=False, p=path: self.open_exercise(p))
        menu.addSeparator()
        self._action(menu, "Open exercise file\u2026", self.open_dialog)
        self._action(menu, "Work folder for attempts\u2026", self.choose_work_folder)
        self.close_action = self._action(menu, "Close exercise", self.close_exercise)
        self.close_action.setEnabled(False)
        if presets_menu is not None:
            presets_menu.addSeparator()
            title, name = EXERCISES_ENTRY
            self._action(presets_menu, title, lambda _=False: self.open_exercise(EXERCISE_DIR / name))
        return menu

    def _action(self, menu, text, slot):
        act = QAction(text, self.parent)
        act.triggered.connect(slot)
        menu.addAction(act)
        return act

    def open_dialog(self, _=False):
        path, _ = QFileDialog.getOpenFileName(self.parent, "Open exercise", str(EXERCISE_DIR), "Exercises (*.toml)")
        if path:
            self.open_exercise(path)

    def set_open(self, is_open: bool):
        """Close exercise is offered while one is open."""
        if self.close_action is not None:
            self.close_action.setEnabled(is_open)
