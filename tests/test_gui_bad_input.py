"""The window meets bad input as the command line does: a named pipe, a hostile shape file or a
hostile settings file is one line in a dialog (or a quiet fall-back to the defaults), never a
hang or a traceback; a save onto a pipe is refused with the old pipe left as it was."""
from __future__ import annotations

import json
import os

import pytest

pytestmark = pytest.mark.gui


def test_hostile_files_are_one_line_dialogs(window, tmp_path, monkeypatch):
    from PySide6.QtWidgets import QMessageBox

    warnings = []
    monkeypatch.setattr(QMessageBox, "warning", lambda *a, **k: warnings.append(a[2]))
    kind = window.sim.shape.kind
    fifo = tmp_path / "pipe.json"
    os.mkfifo(fifo)
    deep = tmp_path / "deep.json"
    deep.write_text('{"shape": ' + "[" * 50000 + "]" * 50000 + "}")
    text_number = tmp_path / "text.json"
    text_number.write_text(json.dumps({"format": "feelflow-shape", "version": 1,
                                       "shape": {"kind": "cylinder", "diameter": "32", "x": 40, "y": 30}}))
    for path in (fifo, deep, text_number):
        assert not window.exports.load_shape(str(path))
    assert len(warnings) == 3 and window.sim.shape.kind == kind
    assert "not a regular file" in warnings[0] and "must be a number" in warnings[2]
    window.exports.save_shape(str(fifo))                      # a pipe is never replaced by a file
    assert len(warnings) == 4 and "not a regular file" in warnings[3] and fifo.is_fifo()
    assert window.replays.start(str(fifo)) is False    # a pipe as a session: refused at once
    assert len(warnings) == 5 and "not a regular file" in warnings[4]


def test_a_hostile_settings_file_falls_back_to_the_defaults(qtbot, tmp_path):
    from PySide6.QtCore import QSettings

    from feelflow.app.gui.main_window import MainWindow
    from feelflow.app.model.simulation import Params

    path = str(tmp_path / "settings.ini")
    s = QSettings(path, QSettings.IniFormat)
    s.setValue("grid", "99999x99999")
    s.setValue("wind", "nan")
    s.setValue("polygon", "[" * 100000 + "]" * 100000)
    s.sync()
    w = MainWindow(backend="numpy", settings=QSettings(path, QSettings.IniFormat))
    qtbot.addWidget(w)
    d = Params()
    assert w.params.grid == d.grid and w.params.wind == d.wind
    assert w.store.polygon() is None
