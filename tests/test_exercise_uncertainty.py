"""Scores with error bars: the digits a grid uncertainty supports, ties, the ranking check of
`feelflow exercise check --convergence` (same order at twice the resolution, declared ties
allowed, the declared uncertainty covering the measured change), the exercise file's key, and
every shipped exercise stating one. All fast: no flow is run here (the runs behind the shipped
numbers are `feelflow exercise check --convergence`, quoted in docs/guide/exercises.md)."""
from __future__ import annotations

import argparse
import csv
import io
import pathlib
import tomllib

import pytest

from feelflow.app.errors import UserError
from feelflow.app.exercises import grading, scoring
from feelflow.app.exercises.format import exercise_from_dict, load_exercise
from feelflow.app.exercises.uncertainty import (decimals, declared, fmt, largest_change, order_changes,
                                                rank_labels, tied_ranks)

ROOT = pathlib.Path(__file__).resolve().parents[1]
TINY = ROOT / "tests" / "data" / "exercises" / "tiny.toml"
SHIPPED = sorted((ROOT / "exercises").glob("*.toml"))


def tiny(uncertainty=None):
    with open(TINY, "rb") as fh:
        d = tomllib.load(fh)
    if uncertainty is not None:
        d["objective"]["grid_uncertainty"] = uncertainty
    return exercise_from_dict(d, "ex.toml", TINY)


def test_digits_follow_the_uncertainty():
    assert [decimals(u) for u in (0.1, 0.05, 0.02, 0.3, 1.0, 0.004)] == [2, 2, 3, 1, 1, 3]
    assert decimals(None) == 4
    assert fmt(2.23794, 0.1, with_uncertainty=True) == "2.24 \u00b1 0.10"
    assert fmt(0.78123, 0.05) == "0.78" and fmt(0.79104, 0.02, True) == "0.791 \u00b1 0.020"
    assert fmt(None, 0.1) == "-"


def test_declared_uncertainty_is_the_change_rounded_up_at_the_printed_digit():
    assert declared(0.0978) == 0.1 and declared(0.0445) == 0.05 and declared(0.1076) == 0.11
    assert declared(0.0211) == 0.022 and declared(0.05) == 0.05
    for m in (0.0978, 0.0445, 0.1076, 0.0211, 0.2991, 0.00073):
        assert declared(m) >= m


def test_scores_closer_than_the_uncertainty_share_a_rank():
    scores = [2.2379, 2.4324, 2.4934, 2.6285, 2.8052]
    assert tied_ranks(scores, "lower", 0.1) == [1, 2, 2, 4, 5]
    assert tied_ranks(scores, "lower", None) == [1, 2, 3, 4, 5]
    assert tied_ranks([1.1, 0.78, 0.6, 0.0], "higher", 0.05) == [1, 2, 3, 4]
    assert rank_labels([1, 2, 2, 4, 5]) == ["1", "2=", "2=", "4", "5"]


def test_ranking_check_allows_declared_ties_and_catches_a_real_swap():
    coarse = {"a": 2.24, "b": 2.44, "c": 2.46, "d": 2.59}
    fine = {"a": 2.29, "b": 2.43, "c": 2.57, "d": 2.61}
    assert order_changes(coarse, fine, "lower", 0.11) == []          # b and c tie at 1x
    assert order_changes(coarse, fine, "lower", None) == []
    swapped = dict(fine, b=2.65)        # b, ahead of d by 0.15 at 1x, now behind it
    assert order_changes(coarse, swapped, "lower", 0.11) == [("b", "d")]
    assert largest_change(coarse, fine) == pytest.approx(0.11)


def _rows(scores, scale):
    return {(f, scale): grading.Row(f, scoring.SCORED, s) for f, s in scores.items()}


def _convergence(exercise, coarse, fine):
    from feelflow.app.cli.commands.exercise import _convergence

    by = {**_rows(coarse, 1), **_rows(fine, 2)}
    out = io.StringIO()
    import contextlib

    with contextlib.redirect_stdout(out):
        failed = _convergence(exercise, list(coarse), by, markdown=False)
    return failed, out.getvalue()


def test_convergence_check_passes_with_ties_and_fails_past_the_declared_uncertainty():
    coarse = {"ref.json": 2.81, "cyl.json": 2.96, "down.json": 3.07, "sq.json": 3.34}
    fine = {"ref.json": 2.78, "cyl.json": 2.97, "down.json": 3.07, "sq.json": 3.51}
    failed, text = _convergence(tiny(0.2), coarse, fine)
    assert not failed and "largest change is 0.1700, within the declared 0.2" in text
    assert "the same" in text and "1=" in text
    failed, text = _convergence(tiny(0.1), coarse, fine)          # declared too small
    assert failed and "MORE than the declared 0.1 (declare 0.17)" in text
    failed, text = _convergence(tiny(0.2), coarse, dict(fine, **{"ref.json": 3.3}))   # ref falls behind
    assert failed and "DIFFERENT" in text and "order changes" in text
    failed, text = _convergence(tiny(), coarse, fine)                # none declared: says what to declare
    assert not failed and "grid_uncertainty = 0.17" in text


def test_the_csv_shares_ranks_of_ties_and_keeps_every_digit():
    ex = tiny(0.2)
    rows = grading.ranked(ex, [grading.Row("a.json", scoring.SCORED, 2.81234567),
                               grading.Row("b.json", scoring.SCORED, 2.9),
                               grading.Row("c.json", scoring.SCORED, 3.3),
                               grading.Row("bad.json", grading.INVALID)])
    table = list(csv.DictReader(io.StringIO("\n".join(",".join(map(str, r))
                                                      for r in [grading.CSV_HEADER, *grading.csv_rows(rows, ex)]))))
    assert [t["rank"] for t in table] == ["1", "1", "3", ""]
    assert [t["tied"] for t in table] == ["yes", "yes", "", ""]
    assert table[0]["score"] == repr(2.81234567) and table[0]["grid_uncertainty"] == "0.2"


def test_the_key_is_checked_and_every_shipped_exercise_states_its_uncertainty():
    assert tiny(0.05).objective.uncertainty == 0.05 and tiny().objective.uncertainty is None
    with pytest.raises(UserError, match="objective.grid_uncertainty: must be a positive number"):
        tiny(-0.1)
    for path in SHIPPED:
        ex = load_exercise(path)
        assert ex.objective.uncertainty is not None, path.name
        if ex.objective.tolerance is not None:   # a hit is never claimed more finely than the grid allows
            assert ex.objective.tolerance >= ex.objective.uncertainty, path.name


def test_score_table_prints_the_supported_digits(tmp_path, monkeypatch, capsys):
    """`feelflow exercise score` with a stated uncertainty: ties share a rank, two decimals."""
    from feelflow.app.cli.commands import exercise as cmd

    ex = tiny(0.1)
    fake = [grading.Row("one.json", scoring.SCORED, 2.81234, cd=2.81234, cl=0.0),
            grading.Row("two.json", scoring.SCORED, 2.85, cd=2.85, cl=0.0)]
    monkeypatch.setattr(grading, "grade", lambda *a, **k: (fake, 1.0))
    monkeypatch.setattr(grading, "shape_files", lambda paths: [pathlib.Path(p) for p in paths])
    args = argparse.Namespace(shapes=["one.json", "two.json"], out=str(tmp_path / "s.csv"), force=False,
                              workers="1", scale=None, backend="numpy")
    assert cmd._score(ex, args) == 0
    out = capsys.readouterr().out
    assert "grid uncertainty of a score: 0.1" in out
    assert "  1=       2.81" in out and "  1=       2.85" in out and "2.8123" not in out


@pytest.mark.slow
def test_the_cpu_backend_scores_numpys_digits():
    """`exercise check --backend cpu` (used for the convergence tables) gives numpy's scores."""
    from feelflow.app.shape_files import load_shape

    ex = load_exercise(TINY)
    shape = load_shape(ex.references[0].path)
    a = scoring.score_shape(ex, shape, backend="numpy")
    b = scoring.score_shape(ex, shape, backend="cpu")
    assert a.ok and b.ok
    assert b.score == pytest.approx(a.score, rel=1e-12) and round(a.score, 4) == round(b.score, 4)


def test_standing_against_a_reference():
    """The exercise panel's words for a score against a reference's (uncertainty.standing)."""
    from feelflow.app.exercises.uncertainty import standing

    assert standing(1.00, 1.02, "lower", 0.05) == "tied (within the grid uncertainty) with"
    assert standing(1.00, 1.20, "lower", 0.05) == "better than"
    assert standing(1.20, 1.00, "lower", 0.05) == "behind"
    assert standing(1.20, 1.00, "higher", 0.05) == "better than"
    assert standing(1.00002, 1.00001, "lower", None) == "the same as"
    assert standing(1.001, 1.002, "lower", None) == "better than"
