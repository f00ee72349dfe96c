"""The built-in bodies an exercise lets a student set by number, Qt-free: each kind's
parameters with their labels and ranges (`PARAMETERS`), and the conversion between a shape
dictionary (shapes/io.py: lengths in cells, angles in radians) and the values the exercise
panel's fields show (angles in degrees). app/gui/exercise_shape_fields.py draws the fields."""
from __future__ import annotations

import math
from typing import NamedTuple

#: parametric kinds: parameter -> (label, minimum, maximum, step); angles in degrees
PARAMETERS = {
    "cylinder": {"diameter": ("Diameter (cells)", 2.0, 60.0, 0.5)},
    "plate": {"length": ("Length (cells)", 2.0, 60.0, 0.5), "thickness": ("Thickness (cells)", 0.5, 20.0, 0.5)},
    "wedge": {"length": ("Length (cells)", 2.0, 60.0, 0.5), "apex_angle": ("Apex angle (degrees)", 5.0, 170.0, 1.0)},
    "half_airfoil": {"chord": ("Chord (cells)", 4.0, 60.0, 0.5), "thickness": ("Thickness (cells)", 0.5, 20.0, 0.25)},
    "naca": {"chord": ("Chord (cells)", 8.0, 120.0, 1.0), "thickness": ("Thickness (x chord)", 0.04, 0.3, 0.01),
             "camber": ("Camber (x chord)", 0.0, 0.09, 0.01), "camber_position": ("Camber at (x chord)", 0.1, 0.9, 0.1)},
}

#: the parameters shown in degrees (radians in the shape dictionary)
DEGREES = frozenset({"apex_angle"})


class FieldValues(NamedTuple):
    """What the fields show for one body: its kind, {parameter: value shown}, a wedge's
    pointing (else None) and the angle in degrees."""

    kind: str
    values: dict[str, float]
    pointing: str | None
    angle_deg: float


def field_values(shape: dict) -> FieldValues:
    """The fields' values for a shape dictionary of a kind in `PARAMETERS`."""
    kind = shape["kind"]
    values = {name: math.degrees(shape[name]) if name in DEGREES else shape[name] for name in PARAMETERS[kind]}
    return FieldValues(kind, values, shape.get("pointing"), math.degrees(shape["angle"]))


def shape_dict(fields: FieldValues) -> dict:
    """The shape dictionary (shapes/io.py: radians) the fields describe, at (0, 0)."""
    kind = fields.kind
    d = {"kind": kind, "x": 0.0, "y": 0.0, "angle": math.radians(fields.angle_deg)}
    for name in PARAMETERS[kind]:
        value = fields.values[name]
        d[name] = math.radians(value) if name in DEGREES else value
    if kind == "wedge":
        d["pointing"] = fields.pointing
    return d
