"""Units in the real window (Xvfb): View > Units switches lattice units to SI for water, and
the side panel's drag and lift, the force plot's axes, the probes' plot and the forces CSV all
change together; the vortex-street lesson's drag the window shows in newtons is its lattice drag
converted by hand from water's density and viscosity (no hidden factor); back to lattice units
restores them. In SI the side panel's wind box reads m/s and its viscosity box water's
viscosity (read-only), while the solver keeps its lattice values; a recorded session keeps the
units choice and its replay shows it."""
from __future__ import annotations

import csv
import io
import math

import numpy as np
import pytest

from gui_fixtures import window  # noqa: F401 - the fixture

pytestmark = pytest.mark.gui

RHO_WATER = 998.0             # kg/m^3, 20 C (White, Fluid Mechanics, Table 1.4)
NU_WATER = 1.00e-3 / 998.0    # m^2/s: mu / rho


def test_switch_units_and_convert_the_drag_by_hand(window, qtbot):  # noqa: F811
    from feelflow.app.model.display_units import UnitsChoice

    w = window
    assert w.lessons.apply("vortex_street")      # a lesson: the cylinder at Re 100 (Presets menu)
    w.probes.add(6.0, w.sim.pos[1])
    qtbot.waitUntil(lambda: len(w.sim.history.time) > 20 and len(w.probes.probes.items[0].time) > 5, timeout=30000)
    # the readouts refresh on their own slower timer: on a fast machine 20 rows come before it
    qtbot.waitUntil(lambda: "lattice units" in w.panel.drag.text(), timeout=10000)
    assert w.plot.plot.getAxis("left").labelText == "force (lattice units)"
    lattice_header = next(csv.reader(io.StringIO(w.plot.csv_text())))
    assert "time_s" not in lattice_header

    size_m, span_m = 0.01, 0.1
    w.loop.set_paused(True)       # hold the flow still while the numbers are compared
    w.units.set_choice(UnitsChoice("water", size_m, span_m))
    w.loop.readouts.refresh()
    w.plot.refresh(force=True)
    # readouts, plot axes and the probes' plot in SI
    assert w.panel.drag.text().endswith("(N)") and w.panel.lift.text().endswith("(N)")
    assert w.panel.physical.isVisible() and "water" in w.panel.physical.text()
    assert w.plot.plot.getAxis("left").labelText == "force (N)"
    assert w.plot.plot.getAxis("bottom").labelText == "time (s)"
    assert "m/s" in w.probes.plot.plot.getAxis("left").labelText
    assert w.probes.plot.plot.getAxis("bottom").labelText == "time (s)"

    # the drag by hand: the cell from the body's size, the speed from the Reynolds number
    p = w.sim.params
    L = w.sim.reference_length().cells          # the body's size in cells (the cylinder's diameter)
    re = p.wind * L / p.nu
    dx = size_m / L                              # m per cell
    u_water = re * NU_WATER / size_m             # m/s with the simulated Re
    dt = p.wind * dx / u_water                   # s per step
    newtons_per_lattice_force = RHO_WATER * dx ** 3 * span_m / dt ** 2
    r = w.plot.readout()
    drag_n = r.drag * newtons_per_lattice_force
    shown = float(w.panel.drag.text().split()[0])
    assert math.isclose(shown, drag_n, rel_tol=1e-3), (shown, drag_n)
    # the plot's last drag point and time are the same conversion
    curve = w.plot.time_views.curves[(p.force_model, "drag")]
    t, f = curve.getData()
    t_steps, drag, _ = w.sim.history.drag_lift(p.force_model)
    assert math.isclose(f[-1], drag[-1] * newtons_per_lattice_force, rel_tol=1e-9)
    assert math.isclose(t[-1], t_steps[-1] * dt, rel_tol=1e-9)

    # the CSV carries SI columns beside the lattice ones, consistent with the same factors
    rows = list(csv.DictReader(io.StringIO(w.plot.csv_text())))
    last = rows[-1]
    drag_col = f"{p.force_model}_drag"
    assert {"time_s", f"{drag_col}_N", "wind_x_m_s", "probe1_speed_m_s", "probe1_p_Pa"} <= set(last)
    assert math.isclose(float(last["time_s"]), float(last["step"]) * dt, rel_tol=1e-6)
    assert math.isclose(float(last[f"{drag_col}_N"]), float(last[drag_col]) * newtons_per_lattice_force, rel_tol=1e-6)
    assert math.isclose(float(last["wind_x_m_s"]), float(last["wind_x"]) * dx / dt, rel_tol=1e-6)

    # back to lattice units
    w.units.set_choice(UnitsChoice())
    w.loop.readouts.refresh()
    assert "lattice units" in w.panel.drag.text() and not w.panel.physical.isVisible()
    assert w.plot.plot.getAxis("left").labelText == "force (lattice units)"
    assert "time_s" not in next(csv.reader(io.StringIO(w.plot.csv_text())))
    assert np.isfinite(r.drag)


def test_wind_box_in_metres_per_second_for_water(window, qtbot):  # noqa: F811
    from feelflow.app.model.display_units import UnitsChoice

    w = window
    w.loop.set_paused(True)
    panel, p = w.panel, w.sim.params
    wind_lattice, nu_lattice, re_before = p.wind, p.nu, w.sim.reynolds()
    lattice_text = (panel.wind.value(), panel.wind.suffix(), panel.viscosity.value(), panel.viscosity.suffix())
    assert lattice_text[1] == " cells/step" and lattice_text[0] == pytest.approx(wind_lattice, abs=5e-4)

    size_m = 0.01
    w.units.set_choice(UnitsChoice("water", size_m, 0.1))
    # by hand: L cells across the body, Re = U L / nu, water with the same Re past a 1 cm body
    L = w.sim.reference_length().cells
    re = wind_lattice * L / nu_lattice
    dx = size_m / L                          # m per cell
    u_water = re * NU_WATER / size_m         # m/s with the simulated Re
    dt = wind_lattice * dx / u_water         # s per step
    u_si = wind_lattice * dx / dt            # U_SI = U_lattice * dx / dt (= u_water)
    assert panel.wind.suffix() == " m/s"
    assert panel.wind.value() == pytest.approx(u_si, rel=1e-3), (panel.wind.value(), u_si)
    # the viscosity box shows water's, read-only, and says why
    assert panel.viscosity.suffix() == " m\u00b2/s" and panel.viscosity.isReadOnly()
    assert panel.viscosity.value() == pytest.approx(NU_WATER, rel=1e-6)
    assert "fixes it" in panel.viscosity.toolTip()
    # the solver is untouched, so Re is unchanged by the switch
    assert (w.sim.params.wind, w.sim.params.nu) == (wind_lattice, nu_lattice)
    w.loop.readouts.refresh()
    assert w.sim.reynolds() == re_before and panel.reynolds.text() == f"Re = {re_before:.0f}"

    # back to lattice units: the boxes show the lattice values exactly as before
    w.units.set_choice(UnitsChoice())
    assert (panel.wind.value(), panel.wind.suffix(), panel.viscosity.value(), panel.viscosity.suffix()) == lattice_text
    assert not panel.viscosity.isReadOnly()
    assert (w.sim.params.wind, w.sim.params.nu) == (wind_lattice, nu_lattice)

    # a wind typed in m/s reaches the solver in lattice units: half the speed, half the lattice wind
    w.units.set_choice(UnitsChoice("water", size_m, 0.1))
    panel.wind.setValue(u_si / 2)
    assert w.sim.params.wind == pytest.approx(wind_lattice / 2, rel=1e-3) and w.sim.params.nu == nu_lattice
    assert panel.wind.suffix() == " m/s"


def test_a_session_keeps_the_units_choice(window, qtbot, tmp_path, monkeypatch):  # noqa: F811
    from PySide6.QtWidgets import QFileDialog

    from feelflow.app.model.display_units import UnitsChoice
    from feelflow.app.sessions import load_session
    from feelflow.app.sessions.replay import replay

    w = window
    path = tmp_path / "water.ffsession"
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a, **k: (str(path), ""))
    water = UnitsChoice("water", 0.02, 0.3)
    w.units.set_choice(water)
    w.actions.record.trigger()
    t0 = w.sim.solver.time
    qtbot.waitUntil(lambda: w.sim.solver.time > t0 + 40, timeout=20000)
    w.actions.record.trigger()
    session = load_session(path)
    assert session.units == {"fluid": "water", "size_m": 0.02, "span_m": 0.3}
    assert session.manifest["units"] == session.units
    # the units change only what is shown: the replay reproduces the forces bit for bit
    assert replay(session).max_deviation == 0.0

    # replayed in the window under lattice units: the recorded units show, Stop replay returns
    w.units.set_choice(UnitsChoice())
    assert w.replays.start(path)
    assert w.units.choice == water and w.panel.wind.suffix() == " m/s" and "water" in w.panel.physical.text()
    w.replays.stop()
    assert w.units.choice == UnitsChoice() and w.panel.wind.suffix() == " cells/step"
    assert str(w.settings.value("units/fluid")) == "lattice"   # a replay never changes the user's choice
