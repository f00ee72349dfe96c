"""Units in the real window (Xvfb): View > Units switches lattice units to SI for water, and
the side panel's drag and lift, the force plot's axes, the probes' plot and the forces CSV all
change together; the vortex-street lesson's drag the window shows in newtons is its lattice drag
converted by hand from water's density and viscosity (no hidden factor); back to lattice units
restores them."""
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
    assert "lattice units" in w.panel.drag.text()
    assert w.plot.plot.getAxis("left").labelText == "force (lattice units)"
    lattice_header = next(csv.reader(io.StringIO(w.plot.csv_text())))
    assert "time_s" not in lattice_header

    size_m, span_m = 0.01, 0.1
    w.loop.set_paused(True)       # hold the flow still while the numbers are compared
    w.units.set_choice(UnitsChoice("water", size_m, span_m))
    w.loop.refresh_readouts()
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
    curve = w.plot.curves[(p.force_model, "drag")]
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
    w.loop.refresh_readouts()
    assert "lattice units" in w.panel.drag.text() and not w.panel.physical.isVisible()
    assert w.plot.plot.getAxis("left").labelText == "force (lattice units)"
    assert "time_s" not in next(csv.reader(io.StringIO(w.plot.csv_text())))
    assert np.isfinite(r.drag)
