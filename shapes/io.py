"""Shapes as plain dictionaries and JSON files (the shape editor's and scene files' format).

Format: docs/reference/shapes.md. A dictionary is `{"kind": ..., <parameters>, "x", "y", "angle"}` as
written by `Shape.to_dict()`; a shape file wraps one as `{"format": "feelflow-shape",
"version": 1, "shape": {...}}`. Writes are atomic (temp file in the same folder + os.replace).
"""
from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

from feelflow.shapes.base import Shape, ShapeError
from feelflow.shapes.cylinder import Cylinder
from feelflow.shapes.polygon import FlatPlate, HalfAirfoil, Polygon, Wedge

#: kind -> (class, required parameter keys, optional keys with defaults)
KINDS: dict[str, tuple[type, tuple[str, ...], dict]] = {
    "cylinder": (Cylinder, ("diameter",), {}),
    "polygon": (Polygon, ("vertices",), {}),
    "plate": (FlatPlate, ("length", "thickness"), {}),
    "wedge": (Wedge, ("length", "apex_angle"), {"pointing": "upstream"}),
    "half_airfoil": (HalfAirfoil, ("chord", "thickness"), {}),
}
POSE = {"x": 0.0, "y": 0.0, "angle": 0.0}
FILE_FORMAT = "feelflow-shape"
FILE_VERSION = 1


def from_dict(d) -> Shape:
    """The shape a `to_dict()` dictionary describes; ShapeError naming a bad or missing key."""
    if not isinstance(d, dict):
        raise ShapeError(f"a shape must be a table/object with a 'kind', got {type(d).__name__}")
    kind = d.get("kind")
    if kind not in KINDS:
        known = ", ".join(KINDS)
        raise ShapeError(f"shape kind must be one of {known}; got {kind!r}" if "kind" in d
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


def save_shape(path, shape: Shape) -> None:
    """Write `shape` as a JSON shape file, atomically; ShapeError naming the file if it cannot."""
    path = Path(path)
    text = json.dumps({"format": FILE_FORMAT, "version": FILE_VERSION, "shape": shape.to_dict()}, indent=2)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as exc:
        raise ShapeError(f"{path}: cannot write shape file ({exc.strerror or exc})") from None
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text + "\n")
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException as exc:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        if isinstance(exc, OSError):
            raise ShapeError(f"{path}: cannot write shape file ({exc.strerror or exc})") from None
        raise


def load_shape(path) -> Shape:
    """Read a JSON shape file; ShapeError with one line naming the file and the problem."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else "not UTF-8 text"
        raise ShapeError(f"{path}: cannot read shape file ({reason})") from None
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ShapeError(f"{path}: not valid JSON (line {exc.lineno}, column {exc.colno}: {exc.msg})") from None
    if not isinstance(doc, dict) or doc.get("format") != FILE_FORMAT:
        raise ShapeError(f"{path}: not a FeelFlow shape file (expected \"format\": \"{FILE_FORMAT}\")")
    if doc.get("version") != FILE_VERSION:
        raise ShapeError(f"{path}: unsupported shape file version {doc.get('version')!r} (this FeelFlow reads {FILE_VERSION})")
    if "shape" not in doc:
        raise ShapeError(f"{path}: has no \"shape\" entry")
    try:
        return from_dict(doc["shape"])
    except ShapeError as exc:
        raise ShapeError(f"{path}: {exc}") from None
