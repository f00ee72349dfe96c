"""Exercises: the file format's errors, every constraint, the averaging, determinism, the
attempts file, and `feelflow exercise` as a user meets it (real subprocesses)."""
from __future__ import annotations

import copy
import csv
import math
import pathlib
import subprocess
import sys
import tomllib

import numpy as np
import pytest

from feelflow.app.errors import UserError
from feelflow.app.exercises import scoring
from feelflow.app.exercises.constraints import check_shape, solid_pieces, thickness
from feelflow.app.exercises.format import exercise_from_dict, load_exercise
from feelflow.shapes import Cylinder, FlatPlate, Polygon, Wedge

from exercise_shapes import make_broken, make_class

ROOT = pathlib.Path(__file__).resolve().parents[1]
TINY = ROOT / "tests" / "data" / "exercises" / "tiny.toml"
SHIPPED = sorted((ROOT / "exercises").glob("*.toml"))


def feelflow(*args, cwd=None, timeout=600):
    return subprocess.run([sys.executable, "-m", "feelflow.app", *map(str, args)], cwd=cwd or ROOT,
                          capture_output=True, text=True, timeout=timeout)


def tiny_dict():
    with open(TINY, "rb") as fh:
        return tomllib.load(fh)


def load(d):
    return exercise_from_dict(d, "ex.toml", TINY)


@pytest.fixture(scope="module")
def tiny():
    return load_exercise(TINY)


# --- the file format ------------------------------------------------------------------------
def test_shipped_exercises_load_and_their_references_meet_the_constraints():
    assert len(SHIPPED) >= 5
    kinds = set()
    for path in SHIPPED:
        ex = load_exercise(path)
        kinds.add(ex.objective.kind)
        assert ex.instructions and ex.teacher_note and ex.scene.why and ex.references
        assert len(ex.check_shapes) + len(ex.references) >= 5   # reference + four others
    assert {"least_cd", "largest_cl", "largest_ld", "target_cd"} <= kinds


def _without(d, section, key):
    d = copy.deepcopy(d)
    if key is None:
        del d[section]
    elif section is None:
        del d[key]
    else:
        del d[section][key]
    return d


@pytest.mark.parametrize("section,key,where", [
    (None, "title", "title"), (None, "instructions", "instructions"), ("scene", None, "scene"),
    ("scene", "nx", "scene.nx"), ("scene", "reynolds", "scene.reynolds"), ("scene", "why", "scene.why"),
    ("scene", "body_position", "scene.body_position"), ("edit", "kinds", "edit.kinds"),
    ("objective", "kind", "objective.kind"), (None, "reference", "reference"),
])
def test_missing_key_names_it(section, key, where):
    with pytest.raises(UserError) as err:
        load(_without(tiny_dict(), section, key))
    assert f"ex.toml: {where}: " in str(err.value) and "\n" not in str(err.value)


@pytest.mark.parametrize("section,key,value,where,fragment", [
    ("scene", "nx", 10, "scene.nx", "integer in 32..2048"),
    ("scene", "nx", "wide", "scene.nx", "must be an integer"),
    ("scene", "reynolds", -5, "scene.reynolds", "positive"),
    ("scene", "inflow_speed", 0.5, "scene.inflow_speed", "Mach limit"),
    ("scene", "walls", "rubber", "scene.walls", "must be one of"),
    ("scene", "body_position", [500, 10], "scene.body_position", "outside the grid"),
    ("scene", "average_steps", 5000, "scene.average_steps", "must not exceed"),
    ("scene", "average_steps", 205, "scene.average_steps", "multiple of"),
    ("scene", "reynolds", 1e9, "scene.reynolds", "too small"),
    ("edit", "kinds", ["blob"], "edit.kinds", "distinct shape kinds"),
    ("edit", "start", "nowhere.json", "edit.start", "no such shape file"),
    ("constraints", "area", [50, 10], "constraints.area", "larger than max"),
    ("constraints", "area", [1], "constraints.area", "[min, max]"),
    ("constraints", "vertices", [2, 5], "constraints.vertices", ">= 3"),
    ("constraints", "vertices", [3.5, 5], "constraints.vertices", "two integers"),
    ("constraints", "angle", [-100, 0], "constraints.angle", "within [-90, 90]"),
    ("constraints", "min_thickness", 0, "constraints.min_thickness", "positive"),
    ("objective", "kind", "fastest", "objective.kind", "must be one of"),
])
def test_bad_value_names_the_key(section, key, value, where, fragment):
    d = tiny_dict()
    d[section][key] = value
    with pytest.raises(UserError) as err:
        load(d)
    message = str(err.value)
    assert message.startswith(f"ex.toml: {where}: ") and fragment in message and "\n" not in message


@pytest.mark.parametrize("section", [None, "scene", "constraints", "objective"])
def test_unknown_key_names_it(section):
    d = tiny_dict()
    (d if section is None else d[section])["colour"] = "blue"
    with pytest.raises(UserError) as err:
        load(d)
    where = "colour" if section is None else f"{section}.colour"
    assert f"ex.toml: {where}: unknown key" in str(err.value)


def test_target_objective_needs_target_and_tolerance():
    d = tiny_dict()
    d["objective"] = {"kind": "target_cd", "target": 2.0}
    with pytest.raises(UserError, match=r"objective.tolerance: missing"):
        load(d)


def test_reference_that_breaks_a_constraint_is_refused():
    d = tiny_dict()
    d["constraints"]["frontal_height"] = [7.0, 8.0]
    with pytest.raises(UserError, match=r"reference\[0\].file: breaks a constraint: the frontal height"):
        load(d)


def test_file_errors_are_one_line(tmp_path):
    for text, fragment in [("title = ", "not valid TOML"), ("", "title: missing")]:
        p = tmp_path / "e.toml"
        p.write_text(text)
        with pytest.raises(UserError, match=fragment):
            load_exercise(p)
    with pytest.raises(UserError, match="no such exercise file"):
        load_exercise(tmp_path / "none.toml")


# --- constraints ----------------------------------------------------------------------------
def _with(**constraints):
    """The tiny exercise with these constraints (and a 6-cell frontal height) and every kind."""
    from dataclasses import replace

    from feelflow.app.exercises.format import Constraints

    c = {"frontal_height": (5.5, 6.5)} | {k: tuple(v) if isinstance(v, list) else v for k, v in constraints.items()}
    return replace(load_exercise(TINY), constraints=Constraints(**c),
                   kinds=("polygon", "cylinder", "wedge", "plate"))


def _only(ex, shape):
    problems = check_shape(ex, shape)
    assert len(problems) == 1, problems
    return problems[0]


def test_a_valid_shape_has_no_problems(tiny):
    assert check_shape(tiny, Wedge(8, 2 * math.atan(3 / 8))) == []


@pytest.mark.parametrize("constraints,shape,fragment", [
    ({"area": [10.0, 20.0]}, Polygon([[-3, -3], [3, -3], [3, 3], [-3, 3]]), "the area is 36.0 cells"),
    ({"area": [40.0, 60.0]}, Polygon([[-3, -3], [3, -3], [3, 3], [-3, 3]]), "below the smallest allowed 40"),
    ({}, Cylinder(8.0), "the frontal height (across the stream) is 8.00 cells, above the largest allowed 6.5"),
    ({}, Cylinder(4.0), "is 4.00 cells, below the smallest allowed 5.5"),
    ({"length": [2.0, 5.0]}, Wedge(8, 2 * math.atan(3 / 8)), "the length (along the stream) is 8.0 cells"),
    ({"vertices": [4, 5]}, Polygon([[-3, -3], [3, 0], [-3, 3]]), "has 3 vertices, fewer than the 4 required"),
    ({"vertices": [3, 4]}, Polygon([[-3, -3], [0, -3], [3, -3], [3, 3], [-3, 3]]), "5 vertices, more than the 4"),
    ({"angle": [0.0, 0.0]}, Wedge(8, 2 * math.atan(3 / 8), angle=math.radians(5)), "fixed at 0 degrees"),
    ({"angle": [-4.0, 4.0]}, Cylinder(6.0, angle=math.radians(10)), "the angle is 10.0 degrees, above"),
    ({"min_thickness": 3.0}, FlatPlate(6.0, 2.0), "at most 2.0 cells thick, thinner than 3"),
])
def test_each_constraint_says_what_is_wrong(constraints, shape, fragment):
    assert fragment in _only(_with(**constraints), shape)


def test_kind_not_editable(tiny):
    assert "not a plate" in _only(tiny, FlatPlate(6.0, 2.0))


def test_body_must_fit_the_tunnel(tiny):
    long = Polygon([[-3, -3], [40, -3], [40, 3], [-3, 3]])
    assert "does not fit the tunnel" in _only(_with(frontal_height=None), long)


def test_thin_neck_falls_apart_on_the_lattice():
    # two 6 x 6 blocks joined by a neck 0.2 cells thick: one body, two pieces of solid nodes
    shape = Polygon([[-7, -3], [-1, -3], [-1, -0.1], [1, -0.1], [1, -3], [7, -3], [7, 3], [1, 3],
                     [1, 0.1], [-1, 0.1], [-1, 3], [-7, 3]], x=32.0, y=15.5)
    assert solid_pieces(shape, 64, 32) == 2
    assert solid_pieces(Cylinder(6.0, x=32.0, y=15.5), 64, 32) == 1
    assert "separate pieces" in _only(_with(frontal_height=None), shape)


def test_thickness_is_the_largest_inscribed_circle():
    assert thickness(Cylinder(6.0)) == pytest.approx(6.0, abs=0.3)
    assert thickness(FlatPlate(10.0, 2.0)) == pytest.approx(2.0, abs=0.3)


# --- averaging ------------------------------------------------------------------------------
def test_steady_signal_is_averaged_over_the_window():
    cd = np.full(100, 2.0) + 1e-5 * np.linspace(-1, 1, 100)
    a = scoring.average(cd, np.zeros(100), 0.005)
    assert a.settled and a.cd == pytest.approx(2.0) and a.how.startswith("steady")


def test_drifting_signal_is_not_settled():
    cd = 2.0 + np.linspace(0.0, 0.2, 100)
    a = scoring.average(cd, np.zeros(100), 0.005)
    assert not a.settled and "still changing" in a.how


def test_shedding_is_averaged_over_whole_periods():
    # C_D oscillates at twice the shedding frequency, C_L at it; 5.3 periods in the window:
    # averaging over whole periods recovers the mean, the plain window mean would not
    t = np.arange(530)
    cl = 0.5 * np.sin(2 * np.pi * t / 100 + 0.3)
    cd = 2.0 + 0.2 * np.sin(2 * np.pi * t / 50 + 1.0) + 0.1 * np.sin(2 * np.pi * t / 100 + 0.3)
    a = scoring.average(cd, cl, 0.005)
    assert a.settled and a.periods >= 4
    assert abs(a.cd - 2.0) < 2e-3 and abs(a.cl) < 2e-3
    assert abs(cd.mean() - 2.0) > abs(a.cd - 2.0)


def test_too_few_periods_or_nan_is_not_settled():
    t = np.arange(100)
    cl = 0.5 * np.sin(2 * np.pi * t / 80)
    assert not scoring.average(np.full(100, 2.0), cl, 0.005).settled
    cd = np.full(100, 2.0)
    cd[50] = np.nan
    a = scoring.average(cd, np.zeros(100), 0.005)
    assert not a.settled and "diverged" in a.how


def test_objective_scores():
    from feelflow.app.exercises.format import Objective

    assert scoring.objective_score(Objective("least_cd"), 2.0, 0.5) == (2.0, None)
    assert scoring.objective_score(Objective("largest_ld"), 2.0, 0.5) == (0.25, None)
    assert scoring.objective_score(Objective("target_cl", 0.4, 0.05), 2.0, 0.5) == (pytest.approx(0.1), False)


# --- scoring: physics and determinism ---------------------------------------------------------
def test_same_shape_scores_the_same_digits_twice(tiny):
    shape = Wedge(8, 2 * math.atan(3 / 8))
    a = scoring.score_shape(tiny, shape)
    b = scoring.score_shape(tiny, shape.moved(x=3.0, y=-7.0))   # the exercise places the body
    assert a.ok and a.score == b.score and a.cd == b.cd and a.cl == b.cl


def test_reference_reaches_its_recorded_score(tiny):
    from feelflow.app.shape_files import load_shape

    ref = tiny.references[0]
    r = scoring.score_shape(tiny, load_shape(ref.path))
    assert round(r.score, 4) == round(ref.score, 4)


def test_blunt_beats_sharp_only_the_right_way_round(tiny):
    """Physics, not a typed-in number: a wedge pointing upstream has less drag than the same
    wedge turned round, whose flat face fixes a wide wake (a symmetric body has no lift)."""
    up = scoring.score_shape(tiny, Wedge(8, 2 * math.atan(3 / 8), "upstream"))
    down = scoring.score_shape(tiny, Wedge(8, 2 * math.atan(3 / 8), "downstream"))
    assert up.ok and down.ok and up.cd < down.cd
    assert abs(up.cl) < 1e-3 * up.cd


def test_diverging_flow_is_not_settled():
    d = tiny_dict()
    d["scene"]["reynolds"] = 3000.0   # tau close to 1/2 on a coarse grid: blows up
    ex = load(d)
    r = scoring.score_shape(ex, Cylinder(6.0))
    assert r.status == scoring.NOT_SETTLED and r.score is None


def test_cancel_stops_the_run(tiny):
    calls = []
    with pytest.raises(scoring.Cancelled):
        scoring.score_shape(tiny, Cylinder(6.0), progress=calls.append, cancelled=lambda: len(calls) >= 3)
    assert len(calls) == 3 and calls[-1] < 1.0


# --- attempts -------------------------------------------------------------------------------
def test_attempts_file_round_trip_and_best(tiny, tmp_path):
    from feelflow.app.exercises.attempts import Attempts

    store = Attempts(tiny, tmp_path)
    w = Wedge(8, 2 * math.atan(3 / 8))
    store.add(w, scoring.Result(scoring.SCORED, score=2.5, cd=2.5, cl=0.0, steps=10, seconds=1.0))
    store.add(Cylinder(6.0), scoring.Result(scoring.SCORED, score=2.1, cd=2.1, cl=0.0, steps=10, seconds=1.0))
    store.add(Cylinder(6.0), scoring.Result(scoring.NOT_SETTLED, reason="still changing"))
    again = Attempts(tiny, tmp_path)
    assert [a.number for a in again.items] == [1, 2, 3]
    assert again.best().number == 2
    assert again.items[0].load_shape() == w
    (tmp_path / "tiny.attempts.json").write_text("[1, 2")
    with pytest.raises(UserError, match="not valid JSON"):
        Attempts(tiny, tmp_path)


# --- the command line -----------------------------------------------------------------------
def test_check_bad_file_is_one_line_exit_2(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text(TINY.read_text().replace("reynolds = 20", "reynolds = -1"))
    r = feelflow("exercise", "check", p)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert r.stderr.strip().count("\n") == 0 and "scene.reynolds: must be a positive number" in r.stderr


def test_check_scores_the_reference():
    r = feelflow("exercise", "check", TINY, "--backend", "numpy")
    assert r.returncode == 0, r.stdout + r.stderr
    assert "reference wedge pointing upstream: score" in r.stdout and "DIFFERS" not in r.stdout


def test_score_folder_with_broken_files(tmp_path):
    reasons = make_broken(tmp_path / "class")
    good = make_class(tmp_path / "class", 2)
    out = tmp_path / "scores.csv"
    r = feelflow("exercise", "score", TINY, tmp_path / "class", "--out", out, "--workers", "2",
                 "--backend", "numpy")
    assert r.returncode == 0, r.stderr
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == len(reasons) + len(good)
    by = {pathlib.Path(row["file"]).name: row for row in rows}
    for name, fragment in reasons.items():
        assert by[name]["score"] == "" and fragment in by[name]["reason"] + by[name]["verdict"], by[name]
    scored = [row for row in rows if row["status"] == "scored"]
    assert len(scored) == 2 and [row["rank"] for row in scored] == ["1", "2"]
    assert float(scored[0]["score"]) <= float(scored[1]["score"])
    assert "Wall time" in r.stdout and "per shape" in r.stdout and "/7 shapes" in r.stderr


def test_score_missing_path_is_one_line(tmp_path):
    r = feelflow("exercise", "score", TINY, tmp_path / "nothing")
    assert r.returncode == 2 and "no such shape file or folder" in r.stderr


@pytest.mark.slow
def test_class_of_thirty_on_every_core(tmp_path):
    make_class(tmp_path / "class", 30)
    out = tmp_path / "scores.csv"
    r = feelflow("exercise", "score", TINY, tmp_path / "class", "--out", out)
    assert r.returncode == 0, r.stderr
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == 30 and all(row["status"] == "scored" for row in rows)
    import os

    assert f"on {min(os.cpu_count(), 30)} processes" in r.stdout
    # rerun in one process: the same digits
    again = tmp_path / "again.csv"
    r = feelflow("exercise", "score", TINY, tmp_path / "class", "--out", again, "--workers", "1")
    assert [row["score"] for row in rows] == [row["score"] for row in csv.DictReader(again.open())]


@pytest.mark.slow
def test_ranking_is_the_same_at_twice_the_resolution(tmp_path):
    r = feelflow("exercise", "check", "--convergence", TINY)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "the same" in r.stdout


def test_gui_exercise_option_checks_the_file_first(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text("title = 'x'\n")
    r = feelflow("gui", "--exercise", p)
    assert r.returncode == 2 and "instructions: missing" in r.stderr and "Traceback" not in r.stderr


def test_list_names_the_shipped_exercises():
    r = feelflow("exercise", "list")
    assert r.returncode == 0 and len(r.stdout.strip().splitlines()) == len(SHIPPED)


def test_auto_scores_on_the_faster_backend_timed_once_in_a_child_and_remembered(tmp_path, monkeypatch):
    """`--backend auto` (the default of `exercise score|check`): a backend named is used as it
    is; auto times the candidates on the exercise's grid in a child process, says so in one line,
    and remembers the winner per grid (the candidates cut to numpy here: no kernel compiles in
    the default tier; the child inherits the cut, as it inherits the parent by fork)."""
    from feelflow.app.exercises import grading

    ex = load_exercise(TINY)
    store = tmp_path / "choice.json"
    assert grading.resolve_backend("cpu", ex, store_path=store) == ("cpu", None)
    monkeypatch.setattr(scoring, "BACKENDS", ("numpy",))
    name, line = grading.resolve_backend("auto", ex, store_path=store)
    s = ex.scene
    assert name == "numpy" and line.startswith("scoring backend numpy: ") and f"at {s.nx} x {s.ny}" in line
    assert "float64_scoring" in store.read_text()
    assert grading.resolve_backend("auto", ex, store_path=store) == (
        "numpy", f"scoring backend numpy (remembered for {s.nx} x {s.ny})")


# --- what the window shows, Qt-free ------------------------------------------------------------
def test_shape_problems_of_no_shape_a_broken_one_and_a_valid_one(tiny):
    """The window's live check (app/gui/exercise_constraints.py) says what check_shape says,
    "no shape yet" without a shape, and a shape that cannot be measured in one line."""
    from feelflow.app.exercises.constraints import shape_problems

    assert shape_problems(tiny, None) == ["no shape yet"]
    assert shape_problems(tiny, Wedge(8, 2 * math.atan(3 / 8))) == []
    tall = Cylinder(8.0)
    assert shape_problems(tiny, tall) == check_shape(tiny, tall) != []
    unmeasurable = Polygon([[-3, -3], [3, 3], [3, -3], [-3, 3]])   # crosses itself
    problems = shape_problems(tiny, unmeasurable)
    assert len(problems) == 1 and "\n" not in problems[0]


def test_score_text_names_the_score_the_solver_and_the_references(tiny):
    """The exercise panel's verdict (app/exercises/score_text.py): the score to the digits the
    grid uncertainty supports, the reference length and speed of C_D and C_L, the solver it ran
    on, the standing against each reference; a run without a score says why."""
    from feelflow.app.exercises import score_text

    result = scoring.Result(scoring.SCORED, score=3.1539, cd=3.1539, cl=0.0, steps=1500, seconds=1.6,
                            averaging="steady: mean over the window")
    text = score_text.result_html(tiny, result, "cpu")
    s = tiny.scene
    assert "Score 3.1539" in text and f"L = {s.reference_length:g} cells" in text and "s on cpu)" in text
    assert "behind the reference \u201cwedge pointing upstream\u201d (2.8101)" in text
    assert "steady: mean over the window" in text
    unsettled = scoring.Result(scoring.NOT_SETTLED, reason="the flow diverged (NaN)")
    assert "Not settled</b>: the flow diverged (NaN)." in score_text.result_html(tiny, unsettled, "numpy")
    assert score_text.failed_text(score_text.CANCELLED) == "Scoring cancelled."
    assert score_text.failed_text("no memory") == "Scoring failed: no memory"
    assert "(cpu, float64)" in score_text.running_text("cpu") and "compiles" in score_text.running_text("cpu")
    assert "compiles" not in score_text.running_text("numpy")
