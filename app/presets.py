"""Lessons from the Presets menu: each sets the scene and, where the lesson needs it, runs a
script (a wind-speed sweep, the seed's stop/with/against protocol)."""
from __future__ import annotations

from dataclasses import dataclass, field

from app.simulation import Params


@dataclass(frozen=True)
class Preset:
    title: str
    params: Params
    display: str = "speed"
    note: str = ""
    wind_sweep: tuple = ()     # wind speeds held `hold_steps` each (body held still)
    protocol: bool = False     # the seed's stop / with / against protocol
    hold_still: bool = True
    plot_view: str = "time"
    hold_steps: int = 1500
    offset_y: float = 0.0      # cells off the centre line (breaks symmetry for shedding)
    extra: dict = field(default_factory=dict)


PRESETS = {
    "drag_speed": Preset("Drag grows with speed",
                         Params(shape="cylinder", size=20, wind=0.02, nu=0.005),
                         note="The wind steps up from 0.02 to 0.09; watch the log-log slope.",
                         wind_sweep=(0.02, 0.03, 0.045, 0.065, 0.09), plot_view="speed"),
    "shape_matters": Preset("Shape matters: plate, wedges, cylinder",
                            Params(shape="plate", size=24, wind=0.05, nu=0.01),
                            note="Switch Shape between plate, wedge and cylinder and compare C_D."),
    "lift": Preset("Lift on the half airfoil",
                   Params(shape="half_airfoil", size=40, wind=0.05, nu=0.01),
                   note="The flat side faces down: the lift arrow points up."),
    "vortex_street": Preset("Vortex street behind a cylinder",
                            Params(shape="cylinder", size=20, wind=0.06, nu=0.006),
                            display="vorticity", offset_y=1.0,
                            note="Re about 200: the wake starts to swing after a few thousand steps."),
    "protocol": Preset("The seed's experiment: stopped, with, against the stream",
                       Params(shape="cylinder", size=24, wind=0.04, nu=0.02, compare_all=True),
                       protocol=True, hold_still=False,
                       note="Four phases of 3000 steps: stopped, with the stream, stopped, against it."),
    "models": Preset("Force models compared",
                     Params(shape="cylinder", size=24, wind=0.05, nu=0.01, compare_all=True),
                     note="All three force models on one plot."),
}
