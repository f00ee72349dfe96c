"""Shapes as plain dictionaries and JSON files (the shape editor's and scene files' format).

Format: docs/reference/shapes.md. A dictionary is `{"kind": ..., <parameters>, "x", "y", "angle"}` as
written by `Shape.to_dict()`; a shape file wraps one as `{"format": "feelflow-shape",
"version": 1, "shape": {...}}`. Writes are atomic (temp file in the same folder + os.replace).
"""
from __future__ import annotations

import json
import os
import stat
import tempfile
from pathlib import Path

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


def save_shape(path, shape: Shape) -> None:
    """Write `shape` as a JSON shape file, atomically; ShapeError naming the file if it cannot."""
    path = Path(path)
    text = json.dumps({"format": FILE_FORMAT, "version": FILE_VERSION, "shape": shape.to_dict()}, indent=2)
    if path.exists() and not path.is_file():
        raise ShapeError(f"{path}: not a regular file (a folder, pipe or device); refused")
    try:   # the temporary's name follows app/files.py, which removes those of a killed write
        fd, tmp = tempfile.mkstemp(prefix=f".feelflow-tmp-{os.getpid()}-", suffix=".tmp",
                                   dir=path.parent if str(path.parent) else ".")
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


#: largest shape file read, bytes (a polygon of MAX_VERTICES vertices takes about 50 KB)
MAX_FILE_BYTES = 1 << 20


def _bounded_int(text: str) -> int:
    if len(text.lstrip("+-")) > 16:
        raise ValueError(f"the integer {text[:12]}... is too large")
    return int(text)


def _read_shape_text(path: Path) -> str:
    """The file's text: a regular file (checked before opening, so a pipe never blocks) of at
    most MAX_FILE_BYTES, UTF-8; ShapeError naming the file otherwise."""
    try:
        st = os.stat(path)
    except OSError as exc:
        raise ShapeError(f"{path}: cannot read shape file ({exc.strerror or exc})") from None
    except ValueError:   # a NUL byte in the name
        raise ShapeError(f"{str(path)!r}: not a valid file name") from None
    if not stat.S_ISREG(st.st_mode):
        raise ShapeError(f"{path}: not a regular file (a folder, pipe or device); refused")
    if st.st_size > MAX_FILE_BYTES:
        raise ShapeError(f"{path}: {st.st_size} bytes, more than a shape file can be ({MAX_FILE_BYTES})")
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise ShapeError(f"{path}: cannot read shape file ({exc.strerror or exc})") from None
    if len(data) > MAX_FILE_BYTES:
        raise ShapeError(f"{path}: more than a shape file can be ({MAX_FILE_BYTES} bytes)")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        raise ShapeError(f"{path}: cannot read shape file (not UTF-8 text)") from None


def load_shape(path) -> Shape:
    """Read a JSON shape file; ShapeError with one line naming the file and the problem."""
    path = Path(path)
    text = _read_shape_text(path)
    try:
        doc = json.loads(text, parse_int=_bounded_int)  # NaN is refused by the shape's checks
    except json.JSONDecodeError as exc:
        raise ShapeError(f"{path}: not valid JSON (line {exc.lineno}, column {exc.colno}: {exc.msg})") from None
    except RecursionError:
        raise ShapeError(f"{path}: not valid JSON: nested too deeply") from None
    except ValueError as exc:
        raise ShapeError(f"{path}: not valid JSON: {str(exc).splitlines()[0]}") from None
    if not isinstance(doc, dict) or doc.get("format") != FILE_FORMAT:
        raise ShapeError(f"{path}: not a FeelFlow shape file (expected \"format\": \"{FILE_FORMAT}\")")
    version = doc.get("version")
    if isinstance(version, bool) or version != FILE_VERSION:
        raise ShapeError(f"{path}: unsupported shape file version {repr(version)[:20]} (this FeelFlow reads {FILE_VERSION})")
    if "shape" not in doc:
        raise ShapeError(f"{path}: has no \"shape\" entry")
    try:
        return from_dict(doc["shape"])
    except ShapeError as exc:
        raise ShapeError(f"{path}: {exc}") from None
