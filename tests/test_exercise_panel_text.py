"""The exercise panel's words and its shape fields' values, Qt-free (app/exercises/panel_text.py,
app/exercises/shape_fields.py)."""
import dataclasses
import math
from pathlib import Path

import pytest

from feelflow.app.exercises import panel_text
from feelflow.app.exercises.attempts import Attempt
from feelflow.app.exercises.format import Objective, load_exercise
from feelflow.app.exercises.shape_fields import PARAMETERS, FieldValues, field_values, shape_dict
from feelflow.shapes.io import from_dict

TINY = Path(__file__).resolve().parent / "data" / "exercises" / "tiny.toml"


def test_reflow_joins_a_paragraph_and_keeps_blank_lines():
    text = "  First line\n  goes on here.\n\n\nSecond   \n paragraph.\n"
    assert panel_text.reflow(text) == "First line goes on here.\n\nSecond paragraph."


def test_breakable_path_writes_home_as_tilde_and_breaks_after_separators(monkeypatch):
    monkeypatch.setattr(Path, "home", classmethod(lambda cls: Path("/home/ann")))
    assert panel_text.breakable_path("/home/ann/work/a.json") == "~/\u200bwork/\u200ba.json"
    assert panel_text.breakable_path("/srv/x") == "/\u200bsrv/\u200bx"
    assert panel_text.breakable_path("C:\\u\\x") == "C:\\\u200bu\\\u200bx"


def test_goal_and_references_name_the_uncertainty():
    ex = load_exercise(TINY)
    assert panel_text.goal_text(ex) == "Goal: least cd; score = C_D, lower is better."
    assert panel_text.references_text(ex) == "Reference solution: wedge pointing upstream: 2.8101."
    ex = dataclasses.replace(ex, objective=Objective("target_cl", target=0.5, tolerance=0.05, uncertainty=0.01))
    assert panel_text.goal_text(ex) == ("Goal: target cl; score = |C_L - target|, lower is better (a hit is within "
                                        "0.05 of 0.5). Scores are good to \u00b10.01 (the grid uncertainty); closer "
                                        "than that is a tie.")
    assert panel_text.references_text(ex) == "Reference solution: wedge pointing upstream: 2.810."


def test_problems_and_attempt_lines():
    assert "Not ready to score" in panel_text.problems_text(["too thin"]) and "<li>too thin</li>" in \
        panel_text.problems_text(["too thin"])
    assert "All constraints met" in panel_text.problems_text([])
    shape = {"kind": "cylinder", "diameter": 10.0, "x": 0.0, "y": 0.0, "angle": 0.0}
    best = Attempt(1, "2026-01-02T03:04:05.123", shape, "scored", score=1.234, cd=1.234, cl=0.0, seconds=2.0)
    tie = Attempt(2, "2026-01-02T03:05:00", shape, "scored", score=1.240, cd=1.240, cl=0.0, seconds=2.5)
    failed = Attempt(3, "2026-01-02T03:06:00", shape, "failed", reason="the flow blew up")
    assert panel_text.attempt_line(best, best, 0.01) == "#1  1.234   2026-01-02 03:04:05, 2.0 s   \u2605 best"
    assert panel_text.attempt_line(tie, best, 0.01).endswith("= ties the best")
    assert not panel_text.attempt_line(tie, best, 0.001).endswith("the best")
    assert panel_text.attempt_line(failed, best, 0.01).startswith("#3  failed")
    assert panel_text.attempt_tip(tie) == "C_D 1.2400, C_L 0.0000"
    assert panel_text.attempt_tip(failed) == "the flow blew up"


@pytest.mark.parametrize("kind", sorted(PARAMETERS))
def test_shape_fields_round_trip_every_kind(kind):
    """The fields' values (degrees) back to the same shape dictionary (radians)."""
    values = {name: lo + 0.37 * (hi - lo) for name, (_, lo, hi, _) in PARAMETERS[kind].items()}
    fields = FieldValues(kind, values, "downstream" if kind == "wedge" else None, 12.5)
    d = shape_dict(fields)
    assert d["angle"] == pytest.approx(math.radians(12.5))
    if kind == "wedge":
        assert d["apex_angle"] == pytest.approx(math.radians(values["apex_angle"]))
    shape = from_dict(d)
    back = field_values(shape.to_dict())
    assert back.kind == kind and back.pointing == fields.pointing
    assert back.angle_deg == pytest.approx(12.5)
    assert back.values == pytest.approx(values)
