"""The lesson chooser: the Presets menu's lessons with their notes, one click to start one
(app/model/presets.py holds them; the window's LessonController sets one up)."""
from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QDialog, QDialogButtonBox, QLabel, QListWidget, QListWidgetItem, QVBoxLayout

from feelflow.app.model.presets import PRESETS


class LessonsDialog(QDialog):
    def __init__(self, window):
        super().__init__(window)
        self.window_ = window
        self.setObjectName("lessons-dialog")
        self.setWindowTitle("FeelFlow \u2013 choose a lesson")
        layout = QVBoxLayout(self)
        layout.addWidget(QLabel("Welcome to the wind tunnel. Start with a lesson, or explore the tunnel on "
                                "your own:\ndrag the body with the mouse and watch the forces below. "
                                "The lessons stay in the Presets menu."))
        self.list = QListWidget()
        for key, lesson in PRESETS.items():
            item = QListWidgetItem(f"{lesson.title}\n    {lesson.note}" if lesson.note else lesson.title)
            item.setData(Qt.UserRole, key)
            self.list.addItem(item)
        self.list.setWordWrap(True)
        self.list.setCurrentRow(0)
        self.list.itemDoubleClicked.connect(lambda _item: self.accept())
        layout.addWidget(self.list)
        buttons = QDialogButtonBox()
        self.start_button = buttons.addButton("Start this lesson", QDialogButtonBox.AcceptRole)
        self.explore_button = buttons.addButton("Explore the tunnel", QDialogButtonBox.RejectRole)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        layout.addWidget(buttons)
        self.resize(640, 420)

    def chosen(self) -> str | None:
        item = self.list.currentItem()
        return item.data(Qt.UserRole) if item is not None else None

    def accept(self):
        key = self.chosen()
        super().accept()
        if key is not None:
            self.window_.lessons.apply(key)
