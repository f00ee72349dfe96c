"""Shapes as plain dictionaries and JSON files (the shape editor's and scene files' format).

Format: docs/reference/shapes.md. A dictionary is `{"kind": ..., <parameters>, "x", "y", "angle"}` as
written by `Shape.to_dict()`; a shape file wraps one as `{"format": "feelflow-shape",
"version": 1, "shape": {...}}`. Shape files are read and written by app/shape_files.py, through
the app's one door for files.
"""
from __future__ import annotations

from feelflow.shapes.base import Shape, ShapeError
from feelflow.shapes.cylinder import Cylinder
from feelflow.shapes.naca import NacaAirfoil
from feelflow.shapes.polygon import FlatPlate, HalfAirfoil, Polygon, Wedge

#: kind -> (class, required parameter keys, optional keys with defaults)
KINDS: dict[str, tuple[type, tuple[str, ...], dict]] = {
    "cylinder": (Cylinder, ("diameter",), {}),
    "polygon": (Polygon, ("vertices",), {}),
    "plate": (FlatPlate, ("length", "thickness"), {}),
    "wedge": (Wedge, ("length", "apex_angle"), {"pointing": "upstream"}),
    "half_airfoil": (HalfAirfoil, ("chord", "thickness"), {}),
    "naca": (NacaAirfoil, ("chord", "thickness"), {"camber": 0.0, "camber_position": 0.4}),
}
POSE = {"x": 0.0, "y": 0.0, "angle": 0.0}
FILE_FORMAT = "feelflow-shape"
FILE_VERSION = 1


def from_dict(d) -> Shape:
    """The shape a `to_dict()` dictionary describes; ShapeError naming a bad or missing key."""
    if not isinstance(d, dict):
        raise ShapeError(f"a shape must be a table/object with a 'kind', got {type(d).__name__}")
    kind = d.get("kind")
    if not isinstance(kind, str) or kind not in KINDS:
        known = ", ".join(KINDS)
        raise ShapeError(f"shape kind must be one of {known}; got {repr(kind)[:40]}" if "kind" in d
                         else f"shape has no 'kind' (one of {known})")
    cls, required, optional = KINDS[kind]
    missing = [k for k in required if k not in d]
    if missing:
        raise ShapeError(f"{kind} shape is missing {', '.join(repr(k) for k in missing)}")
    allowed = {"kind", *required, *optional, *POSE}
    unknown = sorted(set(d) - allowed)
    if unknown:
        raise ShapeError(f"{kind} shape has unknown key {unknown[0]!r} "
                         f"(allowed: {', '.join(sorted(allowed - {'kind'}))})")
    kwargs = {k: d[k] for k in required}
    kwargs.update({k: d.get(k, v) for k, v in optional.items()})
    kwargs.update({k: d.get(k, v) for k, v in POSE.items()})
    return cls(**kwargs).validate()


def to_dict(shape: Shape) -> dict:
    """Same as `shape.to_dict()` (symmetry with `from_dict`)."""
    return shape.to_dict()
