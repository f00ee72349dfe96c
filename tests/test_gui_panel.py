"""The side panel for a first-time user, in the real window (Xvfb, numpy solver, small grid):
every control explains itself in a tooltip, quantities carry their units, and the force readouts
are plain decimals."""
from __future__ import annotations


import pytest

# the `window` fixture comes from tests/gui_fixtures.py (conftest)

pytestmark = pytest.mark.gui


def test_every_panel_control_has_a_tooltip(window):
    from PySide6.QtWidgets import QAbstractButton, QAbstractSpinBox, QComboBox

    controls = [w for kind in (QAbstractButton, QAbstractSpinBox, QComboBox)
                for w in window.panel.widget().findChildren(kind)]
    assert len(controls) >= 15
    silent = [w.currentText() if isinstance(w, QComboBox) else w.text() for w in controls if not w.toolTip()]
    assert not silent, silent


def test_spin_boxes_show_their_units(window):
    from PySide6.QtWidgets import QDoubleSpinBox

    for box in window.panel.widget().findChildren(QDoubleSpinBox):
        assert box.suffix().strip(), box.toolTip()


def test_force_readouts_are_plain_decimals(window, qtbot):
    panel, sim = window.panel, window.sim
    qtbot.waitUntil(lambda: len(sim.history) > 30, timeout=20000)
    window.loop.readouts.refresh()
    for label in (panel.drag, panel.lift):
        number = label.text().split()[0]
        assert "e" not in number.lower(), label.text()
        float(number)
    decimals = {len(label.text().split()[0].partition(".")[2]) for label in (panel.drag, panel.lift)}
    assert len(decimals) == 1          # drag and lift to the same precision, side by side


def test_space_presses_a_tabbed_to_check_box_and_pauses_after_a_click(window, qtbot):
    from PySide6.QtCore import QPoint, Qt
    from PySide6.QtTest import QTest
    from PySide6.QtWidgets import QApplication

    panel = window.panel
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow, timeout=5000)
    panel.hold_still.setFocus(Qt.TabFocusReason)                # reached with Tab
    assert panel.hold_still.hasFocus()
    QTest.keyClick(panel.hold_still, Qt.Key_Space)
    assert panel.hold_still.isChecked() and window.sim.hold_still
    assert not window.loop.paused

    window.viewport.setFocus(Qt.MouseFocusReason)
    box = panel.hold_still
    QTest.mouseClick(box, Qt.LeftButton, pos=QPoint(8, box.height() // 2))   # its box, clicked with the mouse
    assert not panel.hold_still.isChecked()
    assert not panel.hold_still.hasFocus()
    QTest.keyClick(QApplication.focusWidget(), Qt.Key_Space)
    assert window.loop.paused                                   # Space is Pause / run again


def test_editing_the_polygon_says_how_in_the_status_bar(window):
    panel = window.panel
    panel.shape.setCurrentIndex(panel.shape.findData("polygon"))
    panel.edit.setChecked(True)
    message = window.statusBar().currentMessage()
    assert message.startswith("Editing the polygon") and "double-click an edge" in message
    panel.edit.setChecked(False)
    assert window.statusBar().currentMessage() == ""
