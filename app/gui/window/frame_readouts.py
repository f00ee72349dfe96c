"""The readouts, refreshed twice a second by the frame loop and after each change of the flow:
the panel's numbers (Reynolds and Mach numbers, drag and lift, app/model/readouts.py), the force
plot and the status bar's numbers (steps/s, MLUPS, fps, Re, Ma, the collision operator).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from feelflow.app.model import readouts

if TYPE_CHECKING:
    from PySide6.QtWidgets import QLabel

    from feelflow.app.gui.force_plot import ForcePlot
    from feelflow.app.gui.side_panel import SidePanel
    from feelflow.app.gui.window.events import WindowEvents
    from feelflow.app.gui.window.field_display import FieldDisplay
    from feelflow.app.gui.window.frame_rates import FrameRates
    from feelflow.app.model.simulation import Simulation


class FrameReadouts:
    """Refreshes the panel's numbers, the plot and the status bar from the model shown."""

    def __init__(self, events: "WindowEvents", panel: "SidePanel", plot: "ForcePlot", labels: "dict[str, QLabel]",
                 display: "FieldDisplay", rates: "FrameRates"):
        """`labels`: the status bar's numbers by name; `display`: the model shown and its display
        mode; `rates`: the frame loop's measured rates."""
        self.panel, self.plot, self.labels, self.display, self.rates = panel, plot, labels, display, rates
        self.sim: "Simulation | None" = None   # the live tunnel, once it exists (events.liveCreated)
        events.liveCreated.connect(self._live_created)

    def _live_created(self, sim):
        self.sim = sim

    def refresh(self):
        """The panel's numbers, the plot and the status bar, from the model shown."""
        model = self.display.shown
        if model is None:
            return
        p, panel = model.params, self.panel
        live = model is self.sim
        wind, nu = panel.flow_units.shown     # lattice units, whatever units the boxes show
        if live and (abs(wind - p.wind) > 5e-4   # a sweep, a lesson or the guard
                     or abs(nu - p.nu) > 5e-5):
            panel.show_params(p, self.display.mode)
        elif live and not panel.angle.hasFocus():   # the wheel or the handle turned the body
            panel.show_angle(p.angle_deg)
        panel.show_numbers(model.reynolds(), model.mach(), model.config.mach_limit)
        r = readouts.readout(model.history, p.force_model, model.reference_length())
        panel.show_forces(r.drag, r.lift) if r.has_forces else panel.show_forces(None, None)
        self.plot.refresh()
        r = self.rates.now
        self.labels["steps"].setText(f"{r['steps_per_s']:.0f} steps/s")
        self.labels["mlups"].setText(f"{r['mlups']:.1f} MLUPS")
        self.labels["fps"].setText(f"{r['fps']:.0f} fps")
        self.labels["re"].setText(f"Re {model.reynolds():.0f}")
        self.labels["ma"].setText(f"Ma {model.mach():.3f}")
        self.labels["operator"].setText(model.operator_line())   # the collision operator and why
