"""Shape files for the exercise tests: a class of valid shapes for the tiny test exercise
(tests/data/exercises/tiny.toml) and a few broken files."""
from __future__ import annotations

import math

TINY = "tests/data/exercises/tiny.toml"


def make_class(folder, n: int = 30) -> list:
    """`n` distinct valid shapes for the tiny exercise (6-cell frontal height): wedges of
    several lengths both ways round, cylinders, and polygons with a blunt or pointed nose."""
    from feelflow.app.shape_files import save_shape
    from feelflow.shapes import Cylinder, Polygon, Wedge

    folder.mkdir(parents=True, exist_ok=True)
    shapes = []
    for k in range(n):
        kind = k % 3
        if kind == 0:
            length = 4.0 + 0.5 * k / 3
            shapes.append(Wedge(length, 2 * math.atan(3.0 / length), "upstream" if k % 2 else "downstream"))
        elif kind == 1:
            shapes.append(Cylinder(6.0 - 0.01 * (k // 3)))
        else:
            nose = 1.0 + 0.25 * (k // 3)
            shapes.append(Polygon([[-nose, 0], [0, -3], [4, -3], [5, 0], [4, 3], [0, 3]]))
    paths = []
    for k, shape in enumerate(shapes):
        p = folder / f"student{k:02d}.json"
        save_shape(p, shape)
        paths.append(p)
    return paths


def make_broken(folder) -> dict:
    """Broken files: name -> a fragment of the reason the grading must give."""
    from feelflow.app.shape_files import save_shape
    from feelflow.shapes import Cylinder, FlatPlate

    folder.mkdir(parents=True, exist_ok=True)
    (folder / "not_json.json").write_text("{ this is not json")
    (folder / "wrong_format.json").write_text('{"format": "something-else", "version": 1}')
    (folder / "bad_kind.json").write_text('{"format": "feelflow-shape", "version": 1, "shape": {"kind": "star"}}')
    save_shape(folder / "too_big.json", Cylinder(12.0))
    save_shape(folder / "plate_not_allowed.json", FlatPlate(6.0, 2.0))
    return {"not_json.json": "not valid JSON", "wrong_format.json": "not a FeelFlow shape file",
            "bad_kind.json": "shape kind must be one of", "too_big.json": "frontal height",
            "plate_not_allowed.json": "not a plate"}
