"""The window's menus, keyboard shortcuts and the replay toolbar. Every entry calls a
controller's method; `Actions` names the entries other code checks or enables.

To add an entry: one `add_action(menu, text, slot, shortcut)` line in `build_menus`, with
`slot` a method of the controller that does the work; a new menu is one `bar.addMenu(...)`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import QMenu, QToolBar

from feelflow.app.gui.display_modes import DISPLAY_MODES
from feelflow.app.model.presets import PRESETS

if TYPE_CHECKING:
    from feelflow.app.gui.main_window import MainWindow


@dataclass
class Actions:
    """The entries whose state the controllers set (checked, enabled)."""

    record: QAction
    replay: QAction
    stop_replay: QAction
    pause: QAction
    undo: QAction
    redo: QAction
    replay_toolbar: QToolBar
    record_video: QAction | None = None
    place_probes: QAction | None = None


def add_action(window: "MainWindow", menu: QMenu, text: str, slot, shortcut: str | None = None,
               checkable: bool = False) -> QAction:
    """A menu entry calling `slot`; a shortcut works wherever the focus is in the window."""
    act = QAction(text, window)
    if shortcut:
        act.setShortcut(QKeySequence(shortcut))
        act.setShortcutContext(Qt.ApplicationShortcut)
    act.setCheckable(checkable)
    act.triggered.connect(slot)
    menu.addAction(act)
    return act


def build_menus(w: "MainWindow") -> Actions:
    """File, Edit, Run, View and Presets, and the toolbar a replay shows."""
    bar = w.menuBar()
    f = bar.addMenu("&File")
    add_action(w, f, "Load shape\u2026", w.exports.load_shape_dialog)
    add_action(w, f, "Save shape\u2026", w.exports.save_shape_dialog)
    f.addSeparator()
    add_action(w, f, "Export forces as CSV\u2026", w.exports.export_csv_dialog)
    add_action(w, f, "Export plot as PNG\u2026", w.exports.export_png_dialog)
    add_action(w, f, "Save screenshot\u2026", w.exports.screenshot_dialog)
    f.addSeparator()
    record = add_action(w, f, "Record session", w.replays.toggle_recording, checkable=True)
    w.events.recordShown.connect(record.setChecked)
    w.events.recordLabel.connect(record.setText)
    replay = add_action(w, f, "Replay session\u2026", w.replays.open_dialog)
    stop_replay = add_action(w, f, "Stop replay", w.replays.stop)
    stop_replay.setToolTip("Stop the replay and return to the live tunnel (Esc)")
    stop_replay.setEnabled(False)
    f.addSeparator()
    add_action(w, f, "Export video of a session\u2026", w.video.export_session_dialog)
    record_video = add_action(w, f, "Record video of the window", w.video.toggle_live, checkable=True)
    w.events.videoRecording.connect(record_video.setChecked)
    f.addSeparator()
    add_action(w, f, "Quit", w.close, "Ctrl+Q")
    e = bar.addMenu("&Edit")
    undo = w.undo.createUndoAction(w, "Undo")
    undo.setShortcut(QKeySequence("Ctrl+Z"))
    redo = w.undo.createRedoAction(w, "Redo")
    redo.setShortcuts([QKeySequence("Ctrl+Shift+Z"), QKeySequence("Ctrl+Y")])
    e.addAction(undo)
    e.addAction(redo)
    r = bar.addMenu("&Run")
    pause = add_action(w, r, "Pause / run", w.loop.toggle_pause, "Space", checkable=True)
    w.events.pauseShown.connect(pause.setChecked)   # the frame loop says when it pauses
    add_action(w, r, "Reset flow", w.flow.reset, "R")
    add_action(w, r, "Stop device force / replay", w.inputs.escape, "Esc")
    r.addSeparator()
    w.backends.build_menu(r)   # Solver backend: Automatic / cpu / gl / numpy
    v = bar.addMenu("&View")
    place_probes = add_action(w, v, "Place probes (click in the flow)", w.probes.set_placing, "P", checkable=True)
    w.events.probesPlacing.connect(place_probes.setChecked)
    add_action(w, v, "Remove all probes", w.probes.clear)
    add_action(w, v, "Units\u2026", w.units.dialog)
    v.addSeparator()
    add_action(w, v, "Full screen", lambda _=False: w.showNormal() if w.isFullScreen() else w.showFullScreen(), "F11")
    v.addSeparator()
    for key, mode in DISPLAY_MODES.items():
        add_action(w, v, mode.label, lambda _=False, k=key: w.loop.display.set_mode(k))
    p = bar.addMenu("&Presets")
    for key, preset in PRESETS.items():
        add_action(w, p, preset.title, lambda _=False, k=key: w.lessons.apply(k))
    w.exercises.build_menu(bar, p)   # the Exercises menu, and its entry in Presets
    toolbar = QToolBar("Replay", w)   # shown only while a session replays
    toolbar.setMovable(False)
    toolbar.addAction(pause)
    toolbar.addAction(stop_replay)
    w.addToolBar(Qt.TopToolBarArea, toolbar)
    toolbar.hide()

    def replay_shown(on: bool):
        """A replay shows (its toolbar, Stop replay; undo and redo off) or the live tunnel again."""
        if on:
            undo.setEnabled(False)
            redo.setEnabled(False)
            pause.setChecked(False)
            stop_replay.setEnabled(True)
            toolbar.show()
        else:
            toolbar.hide()
            stop_replay.setEnabled(False)
            undo.setEnabled(w.undo.canUndo())
            redo.setEnabled(w.undo.canRedo())

    w.events.replayShown.connect(replay_shown)
    return Actions(record=record, replay=replay, stop_replay=stop_replay, pause=pause, undo=undo, redo=redo,
                   replay_toolbar=toolbar, record_video=record_video, place_probes=place_probes)
