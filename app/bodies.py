"""The shapes a student picks in the side panel, built from (kind, size) at a pose.

`size` is the characteristic length in cells: cylinder diameter, plate length, wedge and
airfoil chord. The geometry itself lives in `shapes/`.
"""
from __future__ import annotations

#: kind -> label in the side panel
SHAPE_LABELS = {
    "cylinder": "Cylinder",
    "flat_plate": "Flat plate",
    "wedge": "Wedge",
    "half_airfoil": "Half airfoil",
    "polygon": "Custom polygon",
}


def make_shape(params, polygon, x, y, angle):
    """A shapes.Shape for params.shape / params.size at pose (x, y, angle) (not yet validated)."""
    from app.standin import StandInCircle  # TEMPORARY until shapes/ lands

    return StandInCircle(x, y, angle, params.size)


def params_for_shape(shape):
    """(kind, size, polygon vertices in the body frame or None) of a loaded shapes.Shape."""
    raise NotImplementedError  # TEMPORARY until shapes/ lands
