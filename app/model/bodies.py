"""The shapes a student picks in the side panel, built from (kind, size) at a pose.

`size` is the characteristic length in cells: cylinder diameter, plate length, wedge length
along its axis, airfoil chord (half airfoil and NACA sections), and the scale of the default
custom polygon. The geometry itself (and its validation) is `shapes/`.
"""
from __future__ import annotations

import math

from feelflow.shapes import Cylinder, FlatPlate, HalfAirfoil, NacaAirfoil, Polygon, Wedge

#: kind -> label in the side panel
SHAPE_LABELS = {
    "cylinder": "Cylinder",
    "plate": "Flat plate |",
    "wedge": "Wedge < (point upstream)",
    "wedge_downstream": "Wedge > (point downstream)",
    "half_airfoil": "Half airfoil",
    "naca0012": "NACA 0012 airfoil",
    "naca2412": "NACA 2412 airfoil",
    "naca4412": "NACA 4412 airfoil",
    "polygon": "Custom polygon",
}

#: the NACA 4-digit sections in the panel's list (shapes/naca.py); size = chord
NACA_KINDS = tuple(k for k in SHAPE_LABELS if k.startswith("naca"))

#: the polygon a student starts from, in units of the body size: an arrow-like pentagon
DEFAULT_POLYGON = ((-0.5, -0.3), (0.2, -0.3), (0.5, 0.0), (0.2, 0.3), (-0.5, 0.3))

PLATE_THICKNESS = 0.1      # x size (at least 2 cells)
WEDGE_APEX_DEG = 60.0
AIRFOIL_THICKNESS = 0.2    # x chord


def make_shape(params, polygon, x, y, angle):
    """A shapes.Shape for params.shape / params.size at pose (x, y, angle) (not yet validated)."""
    size, kind = params.size, params.shape
    if kind == "cylinder":
        return Cylinder(size, x, y, angle)
    if kind == "plate":
        return FlatPlate(size, max(2.0, PLATE_THICKNESS * size), x, y, angle)
    if kind in ("wedge", "wedge_downstream"):
        return Wedge(size, math.radians(WEDGE_APEX_DEG), "upstream" if kind == "wedge" else "downstream", x, y, angle)
    if kind == "half_airfoil":
        return HalfAirfoil(size, AIRFOIL_THICKNESS * size, x, y, angle)
    if kind in NACA_KINDS:
        return NacaAirfoil.from_digits(kind[4:], size, x, y, angle)
    if kind == "polygon":
        if polygon is None:
            polygon = default_polygon(size)
        return Polygon(polygon, x, y, angle)
    raise ValueError(f"unknown shape {kind!r}")


def default_polygon(size: float):
    return [(px * size, py * size) for px, py in DEFAULT_POLYGON]


def params_for_shape(shape):
    """(kind, size, polygon vertices in the body frame or None) of a loaded shapes.Shape."""
    if isinstance(shape, Cylinder):
        return "cylinder", shape.diameter, None
    if isinstance(shape, FlatPlate):
        return "plate", shape.length, None
    if isinstance(shape, Wedge):
        return ("wedge" if shape.pointing == "upstream" else "wedge_downstream"), shape.length, None
    if isinstance(shape, HalfAirfoil):
        return "half_airfoil", shape.chord, None
    if isinstance(shape, NacaAirfoil):
        kind = f"naca{shape.digits}"
        if kind not in NACA_KINDS:
            raise ValueError(f"the NACA section {shape.digits or 'with these parameters'} cannot be edited here "
                             f"(the panel offers {', '.join(k[4:] for k in NACA_KINDS)})")
        return kind, shape.chord, None
    if isinstance(shape, Polygon):
        return "polygon", None, [tuple(v) for v in shape.vertices]
    raise ValueError(f"shapes of kind {shape.kind!r} cannot be edited here")
