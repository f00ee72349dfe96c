"""Shape files (`*.json`, `{"format": "feelflow-shape", "version": 1, "shape": {...}}`) through
the one door for files: read by app/inputs.py (a regular file of at most 1 MiB, strict bounded
JSON), written by app/files.py (atomic). Format: docs/reference/shapes.md; the dictionary inside
is shapes/io.py's `from_dict` / `to_dict`. Problems are a `ShapeError`, one line naming the file.
"""
from __future__ import annotations

import json
from pathlib import Path

from feelflow.app.errors import UserError, shown, shown_path
from feelflow.shapes.base import Shape, ShapeError
from feelflow.shapes.io import FILE_FORMAT, FILE_VERSION, from_dict

#: largest shape file read, bytes (a polygon of MAX_VERTICES vertices takes about 50 KB)
MAX_FILE_BYTES = 1 << 20


def load_shape(path) -> Shape:
    """Read a JSON shape file; ShapeError with one line naming the file and the problem."""
    from feelflow.app.inputs import load_json

    src = shown_path(path)
    try:
        doc = load_json(path, "shape file", MAX_FILE_BYTES)
    except UserError as exc:
        raise ShapeError(str(exc)) from None
    if not isinstance(doc, dict) or doc.get("format") != FILE_FORMAT:
        raise ShapeError(f"{src}: not a FeelFlow shape file (expected \"format\": \"{FILE_FORMAT}\")")
    version = doc.get("version")
    if isinstance(version, bool) or version != FILE_VERSION:
        raise ShapeError(f"{src}: unsupported shape file version {shown(version, 20)} "
                         f"(this FeelFlow reads {FILE_VERSION})")
    if "shape" not in doc:
        raise ShapeError(f"{src}: has no \"shape\" entry")
    try:
        return from_dict(doc["shape"])
    except ShapeError as exc:
        raise ShapeError(f"{src}: {exc}") from None


def shape_text(shape: Shape) -> str:
    """A shape file's text."""
    return json.dumps({"format": FILE_FORMAT, "version": FILE_VERSION, "shape": shape.to_dict()}, indent=2) + "\n"


def save_shape(path, shape: Shape) -> Path:
    """Write `shape` as a JSON shape file, atomically (app/files.py); ShapeError naming the file
    if it cannot (the old file is left as it was)."""
    from feelflow.app.files import write_text_atomic

    try:
        write_text_atomic(path, shape_text(shape))
    except OSError as exc:
        raise ShapeError(f"{shown_path(path)}: cannot write shape file ({exc.strerror or exc})") from None
    return Path(path)
