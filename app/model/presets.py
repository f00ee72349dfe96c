"""Lessons from the Presets menu. The physics of each is a scene file in scenes/presets/
(app/model/scene.py format: grid, flow, body, motion script, force models); this table adds only how
the window presents it: title, display mode, plot view, a note, and a wind-speed sweep where the
lesson needs one (scene files have no time-varying wind)."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from feelflow import SCENE_DIR

PRESET_DIR = SCENE_DIR / "presets"


@dataclass(frozen=True)
class Lesson:
    title: str
    scene: str                 # file name in scenes/presets/
    display: str = "speed"
    plot_view: str = "time"
    note: str = ""
    wind_sweep: tuple = ()     # wind speeds held `hold_steps` each (body held still)
    hold_steps: int = 2000
    hold_still: bool = True
    angle_sweep: tuple = ()    # angles of attack (degrees), each held until the forces settle (a polar)

    @property
    def path(self) -> Path:
        return PRESET_DIR / self.scene


PRESETS = {
    "drag_speed": Lesson("Drag grows with speed", "drag_speed.toml", plot_view="speed",
                         wind_sweep=(0.02, 0.03, 0.045, 0.065, 0.09),
                         note="The wind steps up from 0.02 to 0.09, 2000 steps each; the log-log plot fits drag ~ U^n "
                              "to the steady samples."),
    "shape_matters": Lesson("Shape matters: plate, wedges, cylinder", "shape_matters.toml", display="pressure",
                            note="Switch Shape between plate, wedges and cylinder and compare C_D."),
    "lift": Lesson("Lift on the half airfoil", "lift.toml", display="pressure",
                   note="Flat side down: the blue lift arrow points up."),
    "vortex_street": Lesson("Vortex street behind a cylinder", "vortex_street.toml", display="vorticity",
                            note="Re 90 (the most this grid keeps stable here): the wake starts to swing after several thousand steps."),
    "wake_re40_400": Lesson("The wake from Re 40 to 400", "wake_re40_400.toml", display="vorticity",
                            wind_sweep=(0.009, 0.0225, 0.045, 0.09), hold_steps=6000,
                            note="The wind steps through Re 40, 100, 200 and 400, 6000 steps each: still twin "
                                 "vortices, then a street that sheds faster. A 2D flow: a real wake turns "
                                 "three-dimensional above Re 190; at Re 200 this narrow tunnel reads St 12 % and "
                                 "C_D 22 % above an open 2D flow."),
    "plate_re1000": Lesson("A plate at Re 1000", "plate_re1000.toml", display="vorticity",
                           note="Re 1000 on the plate's length: the regularised collision operator keeps it stable. "
                                "A 2D flow: a real wake at Re 1000 is three-dimensional and its drag lower (a "
                                "cylinder: C_D 1.5 in 2D here, about 1.0 measured)."),
    "airfoil_stall": Lesson("Stall: the half airfoil at 15 degrees, Re 1000", "airfoil_stall_re1000.toml",
                            display="vorticity",
                            note="The flow leaves the upper side; watch the lift swing as vortices shed. A 2D "
                                 "flow: a real stalled wing sheds three-dimensional vortices and its lift swings "
                                 "less."),
    "polar": Lesson("Polar: a NACA 0012 from 0 to 24 degrees, Re 1000", "polar_naca0012.toml", display="pressure",
                    plot_view="polar", angle_sweep=(0, 2, 4, 6, 8, 10, 12, 16, 20, 24),
                    note="Each angle is held until C_L and C_D settle, then the nose turns up; the polar builds "
                         "up point by point beside the thin-airfoil line 2 pi alpha."),
    "seed_protocol": Lesson("The seed's experiment: stopped, with, against the stream", "seed_protocol.toml",
                            hold_still=False,
                            note="Four phases of 2500 steps: stopped, with the stream, stopped, against it."),
    "models": Lesson("Force models compared", "models_compared.toml",
                     note="All three force models on one plot: dashed lines are lift."),
}

#: the Presets menu's Exercises entry: (title, the shipped exercise it opens; app/exercises,
#: exercises/*.toml). Exercises are scored, not run as a lesson, so the entry is not in PRESETS
#: (which `feelflow report lessons` runs).
EXERCISES_ENTRY = ("Exercises: design a body and score it", "least_drag.toml")

