"""Probes in the real window (Xvfb): View > Place probes, a click in the flow places one, its
trace grows beside the forces and reads the wind ahead of the body, its columns are in the
forces CSV, a right click removes it."""
from __future__ import annotations

import csv
import io
import math

import numpy as np
import pytest

from gui_fixtures import window  # noqa: F401 - the fixture

pytestmark = pytest.mark.gui


def test_place_a_probe_see_its_trace_and_csv(window, qtbot):  # noqa: F811
    from PySide6.QtCore import Qt

    w = window
    w.probes.set_placing(True)
    assert w.viewport.probing and w.actions.place_probes.isChecked()
    x0, y0 = w.sim.pos
    ahead = (6.0, y0)                        # upstream of the body, in the oncoming wind
    qtbot.mouseClick(w.viewport, Qt.LeftButton, pos=w.viewport.to_widget(*ahead).toPoint())
    assert len(w.probes.probes) == 1 and w.probes.dock.isVisible()
    p = w.probes.probes.items[0]
    assert abs(p.x - ahead[0]) < 1.0 and abs(p.y - ahead[1]) < 1.0
    assert w.sim.pos == (x0, y0)             # the click placed a probe, it did not move the body
    # read it once the inlet's start-up ramp is over (a loaded machine may take a while to get there)
    settled = w.sim.config.inflow_ramp_steps + 2 * w.sim.config.nx
    qtbot.waitUntil(lambda: len(p.time) >= 10 and w.sim.solver.time > settled, timeout=120000)
    qtbot.wait(2 * 250)                      # the plot refreshes a few times a second
    t, v = w.probes.plot.traces()[0]
    assert len(t) >= 10 and np.all(np.isfinite(v[-5:]))
    wind = w.sim.params.wind
    assert abs(v[-1] - wind) < 0.25 * wind, (v[-1], wind)   # far upstream the probe reads about the wind
    assert "cells/step" in w.probes.plot.plot.getAxis("left").labelText
    # the forces CSV has the probe's columns, filled on the rows it sampled
    rows = list(csv.DictReader(io.StringIO(w.plot.csv_text())))
    assert {"probe1_ux", "probe1_uy", "probe1_speed", "probe1_p"} <= set(rows[0])
    filled = [r for r in rows if r["probe1_speed"]]
    assert len(filled) >= 5
    r = filled[-1]
    assert math.isclose(float(r["probe1_speed"]), math.hypot(float(r["probe1_ux"]), float(r["probe1_uy"])),
                        rel_tol=1e-6)
    # a second probe in the wake, then remove the first with a right click
    w.probes.add(x0 + 15.0, y0)
    assert len(w.viewport.probe_marks) == 2
    qtbot.mouseClick(w.viewport, Qt.RightButton, pos=w.viewport.to_widget(p.x, p.y).toPoint())
    assert len(w.probes.probes) == 1 and w.probes.probes.items[0].x > x0
    w.probes.set_placing(False)
    assert not w.viewport.probing


def test_probes_are_recorded_in_the_session_and_come_back_in_its_replay(window, qtbot, tmp_path, monkeypatch):  # noqa: F811
    from PySide6.QtWidgets import QFileDialog

    w = window
    path = tmp_path / "probed.ffsession"
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a, **k: (str(path), ""))
    w.probes.add(8.0, w.sim.pos[1])
    w.replays.toggle_recording()
    qtbot.waitUntil(lambda: len(w.probes.probes.items[0].time) > 5, timeout=20000)
    w.replays.toggle_recording()          # stop: saved with the probe
    assert path.exists()
    w.probes.clear()
    assert w.replays.start(path)
    assert len(w.probes.probes) == 1 and w.probes.probes.items[0].x == 8.0   # put back where it stood
    qtbot.waitUntil(lambda: len(w.probes.probes.items[0].time) >= 1, timeout=20000)   # sampling the replay
    w.replays.stop()
