"""Shape dictionaries and JSON shape files: round trip, and one-line errors on malformed input."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from feelflow.app.shape_files import load_shape, save_shape
from feelflow.shapes import Cylinder, FlatPlate, HalfAirfoil, Polygon, ShapeError, Wedge, from_dict, rasterise

SHAPES = [
    Cylinder(12.5, x=40.25, y=30.0, angle=0.1),
    Polygon([[0, 0], [10, 0], [10, 4], [4, 4], [4, 10], [0, 10]], x=30.0, y=20.0, angle=0.7),
    FlatPlate(16.0, 0.2, x=40.0, y=40.0, angle=0.4),
    Wedge(20.0, math.radians(40), "downstream", x=40.0, y=40.0, angle=-0.2),
    HalfAirfoil(40.0, 6.0, x=40.0, y=40.0, angle=0.1),
]


@pytest.mark.parametrize("shape", SHAPES, ids=lambda s: s.kind)
def test_dict_and_file_round_trip(shape, tmp_path):
    d = shape.to_dict()
    assert json.loads(json.dumps(d)) == d              # JSON-ready
    assert from_dict(d) == shape
    path = tmp_path / "body.json"
    save_shape(path, shape)
    back = load_shape(path)
    assert back == shape and type(back) is type(shape)
    a, b = rasterise(shape, 96, 80), rasterise(back, 96, 80)
    assert np.array_equal(a.q, b.q) and np.array_equal(a.solid, b.solid)
    assert [p.name for p in tmp_path.iterdir()] == ["body.json"]   # no temp file left behind


def test_optional_keys_default():
    assert from_dict({"kind": "cylinder", "diameter": 8}) == Cylinder(8)
    assert from_dict({"kind": "wedge", "length": 8, "apex_angle": 1.0}).pointing == "upstream"


@pytest.mark.parametrize("d,words", [
    ({"kind": "sphere", "diameter": 3}, ["kind must be one of", "'sphere'"]),
    ({"diameter": 3}, ["no 'kind'"]),
    ({"kind": "cylinder"}, ["missing 'diameter'"]),
    ({"kind": "plate", "length": 5}, ["missing 'thickness'"]),
    ({"kind": "cylinder", "diameter": 8, "radius": 4}, ["unknown key 'radius'"]),
    ({"kind": "cylinder", "diameter": "big"}, ["diameter must be a number"]),
    ({"kind": "polygon", "vertices": [[0, 0], [1]]}, ["vertices must be a list of (x, y)"]),
    ({"kind": "polygon", "vertices": [[0, 0], [4, 4], [4, 0], [0, 4]]}, ["self-intersecting"]),
    ([1, 2], ["must be a table/object"]),
])
def test_from_dict_errors(d, words):
    with pytest.raises(ShapeError) as err:
        from_dict(d)
    for w in words:
        assert w in str(err.value)


@pytest.mark.parametrize("content,words", [
    ("{not json", ["not valid JSON", "line 1"]),
    ('{"shape": {"kind": "cylinder", "diameter": 4}}', ["not a FeelFlow shape file"]),
    ('{"format": "feelflow-shape", "version": 9, "shape": {}}', ["unsupported shape file version 9"]),
    ('{"format": "feelflow-shape", "version": 1}', ['no "shape"']),
    ('{"format": "feelflow-shape", "version": 1, "shape": {"kind": "cylinder", "diameter": -1}}',
     ["diameter must be positive"]),
    ('{"format": "feelflow-shape", "version": 1, "shape": {"kind": "cylinder", "diameter": NaN}}',
     ["NaN is not allowed"]),
])
def test_malformed_files(tmp_path, content, words):
    path = tmp_path / "bad.json"
    path.write_text(content)
    with pytest.raises(ShapeError) as err:
        load_shape(path)
    msg = str(err.value)
    assert msg.startswith(str(path)) and "\n" not in msg
    for w in words:
        assert w in msg, msg


def test_missing_and_binary_files(tmp_path):
    with pytest.raises(ShapeError, match="no such shape file"):
        load_shape(tmp_path / "nope.json")
    (tmp_path / "bin.json").write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(ShapeError, match="not UTF-8 text"):
        load_shape(tmp_path / "bin.json")


def test_save_replaces_existing_file(tmp_path):
    path = tmp_path / "body.json"
    save_shape(path, Cylinder(8))
    save_shape(path, FlatPlate(10, 1))
    assert load_shape(path) == FlatPlate(10, 1)


def test_examples_in_docs_parse():
    """Every JSON example in docs/reference/shapes.md is a valid shape or shape file."""
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "docs" / "reference" / "shapes.md").read_text()
    blocks = [b.split("```", 1)[0] for b in text.split("```json\n")[1:]]
    one_line = [ln for ln in blocks[0].splitlines() if ln.strip()]
    assert len(one_line) == 6
    assert {from_dict(json.loads(ln)).kind for ln in one_line} == {
        "cylinder", "plate", "wedge", "half_airfoil", "polygon", "naca"}
    doc = json.loads(blocks[1])
    assert doc["format"] == "feelflow-shape" and from_dict(doc["shape"]).kind == "half_airfoil"


def test_save_into_missing_folder_is_a_shape_error(tmp_path):
    with pytest.raises(ShapeError, match="cannot write shape file"):
        save_shape(tmp_path / "no" / "such" / "body.json", Cylinder(8))
