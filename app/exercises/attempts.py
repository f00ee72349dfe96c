"""A student's attempts at one exercise: a local JSON file next to their work.

`<folder>/<exercise file stem>.attempts.json` = {"format": "feelflow-attempts", "version": 1,
"exercise": title, "attempts": [...]}, each attempt {"number", "time" (UTC, ISO 8601), "shape"
(the shape's dictionary, shapes/io.py), "status", "score", "cd", "cl", "steps", "seconds",
"reason"}. Written atomically (app/files.py) after every attempt; any attempt's shape can be
loaded back; `best()` is the best scored attempt for the exercise's objective.
"""
from __future__ import annotations

import os
from dataclasses import asdict, dataclass
from datetime import datetime, timezone
from pathlib import Path

from feelflow.app.errors import UserError, shown, shown_path
from feelflow.app.files import write_json_atomic

FORMAT = "feelflow-attempts"
VERSION = 1


@dataclass
class Attempt:
    number: int
    time: str
    shape: dict
    status: str
    score: float | None = None
    cd: float | None = None
    cl: float | None = None
    steps: int = 0
    seconds: float = 0.0
    reason: str = ""

    def load_shape(self):
        from feelflow.shapes.io import from_dict

        return from_dict(self.shape)


def _finite(v):
    """A number kept in the file, or None for no number (NaN and inf are not JSON)."""
    import math

    return None if v is None or not math.isfinite(v) else float(v)


def attempts_path(exercise, folder) -> Path:
    stem = exercise.path.stem if exercise.path else "exercise"
    return Path(folder) / f"{stem}.attempts.json"


class Attempts:
    """The attempts file of one exercise in one folder."""

    def __init__(self, exercise, folder):
        self.exercise = exercise
        self.path = attempts_path(exercise, folder)
        self.items: list[Attempt] = []
        if os.path.lexists(self.path):   # a link that cannot be followed is read (and refused)
            self.items = _read(self.path)

    def add(self, shape, result) -> Attempt:
        """Record a scoring result (scoring.Result) for `shape` and save the file."""
        attempt = Attempt(number=len(self.items) + 1,
                          time=datetime.now(timezone.utc).isoformat(timespec="seconds"),
                          shape=shape.to_dict(), status=result.status, score=_finite(result.score),
                          cd=_finite(result.cd), cl=_finite(result.cl), steps=result.steps, seconds=round(result.seconds, 2), reason=result.reason)
        self.items.append(attempt)
        self.save()
        return attempt

    def save(self) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        write_json_atomic(self.path, {"format": FORMAT, "version": VERSION, "exercise": self.exercise.title,
                                      "attempts": [asdict(a) for a in self.items]})

    def best(self) -> Attempt | None:
        scored = [a for a in self.items if a.status == "scored" and a.score is not None]
        if not scored:
            return None
        lower = self.exercise.objective.better == "lower"
        return min(scored, key=lambda a: (a.score if lower else -a.score, a.number))


#: most attempts one file may hold (a student scoring every minute for a week of lessons)
MAX_ATTEMPTS = 10_000
#: largest attempts file read, bytes (an attempt with a 48-vertex polygon is about 2 KB)
MAX_FILE_BYTES = 32 << 20
_FIELDS = {"number": int, "time": str, "shape": dict, "status": str, "score": (float, type(None)),
           "cd": (float, type(None)), "cl": (float, type(None)), "steps": int, "seconds": float, "reason": str}


def _attempt(item, where: str) -> Attempt:
    """One attempt record with every field of its type (numbers finite, the shape a valid
    shape dictionary); UserError naming the field otherwise."""
    import math

    from feelflow.shapes.base import ShapeError
    from feelflow.shapes.io import from_dict

    if not isinstance(item, dict) or set(item) != set(_FIELDS):
        raise UserError(f"{where} is not an attempt record (fields: {', '.join(_FIELDS)})")
    values = {}
    for key, kind in _FIELDS.items():
        v = item[key]
        if kind in (float, (float, type(None))) and isinstance(v, int) and not isinstance(v, bool):
            v = float(v)
        if isinstance(v, bool) or not isinstance(v, kind) or (isinstance(v, float) and not math.isfinite(v)):
            raise UserError(f"{where}.{key} has the wrong type or is not finite: {shown(v)}")
        if isinstance(v, str) and len(v) > 1000:
            raise UserError(f"{where}.{key} is longer than 1000 characters")
        values[key] = v
    if values["number"] < 1 or values["steps"] < 0 or values["seconds"] < 0:
        raise UserError(f"{where}: number, steps and seconds must not be negative")
    try:
        from_dict(values["shape"])
    except ShapeError as exc:
        raise UserError(f"{where}.shape: {exc}") from None
    return Attempt(**values)


def _read(path: Path) -> list[Attempt]:
    """The attempts of a file, through the one reader (app/inputs.py: a regular file, bounded,
    strict JSON); UserError (one line) naming what is wrong."""
    from feelflow.app.inputs import load_json

    src = shown_path(path)
    doc = load_json(path, "attempts file", MAX_FILE_BYTES)
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise UserError(f"{src}: not a FeelFlow attempts file (expected \"format\": \"{FORMAT}\")")
    if isinstance(doc.get("version"), bool) or doc.get("version") != VERSION:
        raise UserError(f"{src}: unsupported attempts file version {shown(doc.get('version'))}")
    items = doc.get("attempts")
    if not isinstance(items, list):
        raise UserError(f"{src}: \"attempts\" must be a list")
    if len(items) > MAX_ATTEMPTS:
        raise UserError(f"{src}: {len(items)} attempts, more than a file may hold ({MAX_ATTEMPTS})")
    return [_attempt(item, f"{src}: attempts[{i}]") for i, item in enumerate(items)]
