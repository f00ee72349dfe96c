"""A student's attempts at one exercise: a local JSON file next to their work.

`<folder>/<exercise file stem>.attempts.json` = {"format": "feelflow-attempts", "version": 1,
"exercise": title, "attempts": [...]}, each attempt {"number", "time" (UTC, ISO 8601), "shape"
(the shape's dictionary, shapes/io.py), "status", "score", "cd", "cl", "steps", "seconds",
"reason"}. Written atomically (app/files.py) after every attempt; any attempt's shape can be
loaded back; `best()` is the best scored attempt for the exercise's objective.
"""
from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from datetime import datetime, timezone
from pathlib import Path

from feelflow.app.errors import UserError
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


def attempts_path(exercise, folder) -> Path:
    stem = exercise.path.stem if exercise.path else "exercise"
    return Path(folder) / f"{stem}.attempts.json"


class Attempts:
    """The attempts file of one exercise in one folder."""

    def __init__(self, exercise, folder):
        self.exercise = exercise
        self.path = attempts_path(exercise, folder)
        self.items: list[Attempt] = []
        if self.path.exists():
            self.items = _read(self.path)

    def add(self, shape, result) -> Attempt:
        """Record a scoring result (scoring.Result) for `shape` and save the file."""
        attempt = Attempt(number=len(self.items) + 1,
                          time=datetime.now(timezone.utc).isoformat(timespec="seconds"),
                          shape=shape.to_dict(), status=result.status, score=result.score, cd=result.cd,
                          cl=result.cl, steps=result.steps, seconds=round(result.seconds, 2), reason=result.reason)
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


def _read(path: Path) -> list[Attempt]:
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise UserError(f"{path}: cannot read the attempts file ({getattr(exc, 'strerror', None) or exc})") from None
    except json.JSONDecodeError as exc:
        raise UserError(f"{path}: not valid JSON (line {exc.lineno}: {exc.msg})") from None
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise UserError(f"{path}: not a FeelFlow attempts file (expected \"format\": \"{FORMAT}\")")
    if doc.get("version") != VERSION:
        raise UserError(f"{path}: unsupported attempts file version {doc.get('version')!r}")
    items = doc.get("attempts")
    if not isinstance(items, list):
        raise UserError(f"{path}: \"attempts\" must be a list")
    out = []
    for i, item in enumerate(items):
        try:
            out.append(Attempt(**item))
        except TypeError:
            raise UserError(f"{path}: attempts[{i}] is not an attempt record") from None
    return out
