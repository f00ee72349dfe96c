"""Exercises through the one door for files (app/files.py, app/inputs.py): `exercise score`
never destroys an input or an existing file, and every bad exercise file, attempts file, class
folder or option is one line on stderr and exit 2 (docs/reference/files.md)."""
from __future__ import annotations

import hashlib
import os
import pathlib
import shutil

import pytest

from feelflow.app.cli.main import main as feelflow_main

ROOT = pathlib.Path(__file__).resolve().parents[1]
TINY = ROOT / "tests" / "data" / "exercises" / "tiny.toml"


def run(capsys, *argv):
    """`feelflow ARGV` in this process: (exit code, stdout, stderr)."""
    code = feelflow_main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line_refusal(code, err, fragment=""):
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("feelflow: "), err
    assert "Traceback" not in err and fragment in err, err
    assert len(lines[0]) < 400, lines[0]


def digest(folder: pathlib.Path) -> dict:
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file() and not p.is_symlink()}


@pytest.fixture
def exercise(tmp_path):
    """A copy of the tiny test exercise and its shapes in a scratch folder."""
    folder = tmp_path / "ex"
    shutil.copytree(TINY.parent, folder)
    return folder / "tiny.toml"


# --- exercise score: the output ---------------------------------------------------------------
@pytest.mark.parametrize("which", ["exercise", "scored shape", "reference shape", "symlink to input",
                                   "hard link to input"])
def test_score_never_writes_over_an_input(exercise, capsys, which):
    shapes = exercise.parent / "shapes"
    scored = shapes / "cylinder.json"
    out = {"exercise": exercise, "scored shape": scored, "reference shape": shapes / "ref.json",
           "symlink to input": exercise.parent / "link.csv",
           "hard link to input": exercise.parent / "hard.csv"}[which]
    if which == "symlink to input":
        out.symlink_to(exercise)
    if which == "hard link to input":
        os.link(scored, out)
    before = digest(exercise.parent)
    code, _, err = run(capsys, "exercise", "score", exercise, scored, "--out", out, "--force")
    one_line_refusal(code, err, "is an input of this command")
    assert digest(exercise.parent) == before


def test_score_refuses_existing_results_and_default_scores_csv_without_force(exercise, capsys, monkeypatch):
    results = exercise.parent / "results.csv"
    results.write_text("rank,file\n1,mine.json\n")
    shape = exercise.parent / "shapes" / "cylinder.json"
    code, _, err = run(capsys, "exercise", "score", exercise, shape, "--out", results)
    one_line_refusal(code, err, "already exists; add --force")
    assert results.read_text() == "rank,file\n1,mine.json\n"
    monkeypatch.chdir(exercise.parent)
    (exercise.parent / "scores.csv").write_text("kept\n")
    code, _, err = run(capsys, "exercise", "score", exercise, shape)
    one_line_refusal(code, err, "'scores.csv' already exists")
    assert (exercise.parent / "scores.csv").read_text() == "kept\n"


@pytest.mark.parametrize("out", ["/dev/null", "fifo", "folder", "missing/scores.csv"])
def test_score_refuses_devices_pipes_folders_and_missing_folders(exercise, capsys, out):
    if out == "fifo":
        out = exercise.parent / "pipe.csv"
        os.mkfifo(out)
    elif out == "folder":
        out = exercise.parent / "shapes"
    elif out.startswith("missing"):
        out = exercise.parent / out
    code, _, err = run(capsys, "exercise", "score", exercise, exercise.parent / "shapes" / "cylinder.json",
                       "--out", out, "--force")
    one_line_refusal(code, err, "--out")


def test_score_with_force_replaces_the_results_atomically(exercise, capsys):
    edited(exercise, "steps = 1500", "steps = 100")   # a short run: this test is about the file
    edited(exercise, "average_steps = 500", "average_steps = 50")
    results = exercise.parent / "results.csv"
    results.write_text("old\n")
    before = digest(exercise.parent / "shapes")
    code, out, err = run(capsys, "exercise", "score", exercise, exercise.parent / "shapes" / "ref.json",
                         "--out", results, "--force", "--workers", "1", "--backend", "numpy")
    assert code == 0, err
    text = results.read_text()
    assert text.startswith("rank,file,status") and "ref.json" in text and len(text.splitlines()) == 2
    assert digest(exercise.parent / "shapes") == before
    assert not [p for p in exercise.parent.iterdir() if p.name.startswith(".feelflow-tmp-")]


# --- exercise files: every bad file is one line, fast ------------------------------------------
def edited(exercise, old, new):
    text = exercise.read_text()
    assert old in text, old
    exercise.write_text(text.replace(old, new, 1))
    return exercise


BAD_EXERCISES = {
    # name: (old text, new text, fragment of the one line)
    "long start name": ('start = "shapes/start.json"', 'start = "' + "s" * 5000 + '.json"', "edit.start"),
    "long check name": ('"shapes/cylinder.json"', '"' + "c" * 300 + '.json"', "check.shapes[0]"),
    "deep arrays": ('why = "', "deep = " + "[" * 100000 + "]" * 100000 + '\nwhy = "', "nested more than"),
    "deep inline tables": ('why = "', "deep = " + "{a = " * 3000 + "1" + "}" * 3000 + '\nwhy = "', "nested more than"),
    "5000-digit integer": ("nx = 64", "nx = " + "9" * 5000, "too large"),
    "400-digit reynolds": ("reynolds = 20", "reynolds = " + "4" * 400, "too large"),
    "400-digit reference score": ("score = 2.8101", "score = " + "7" * 400, "too large"),
    "400-digit area bound": ("area = [10.0, 60.0]", "area = [10, " + "6" * 400 + "]", "too large"),
    "steps 10^18": ("steps = 1500", "steps = 1" + "0" * 18, "scene.steps"),
    "steps 2^63 + 2": ("steps = 1500", f"steps = {2 ** 63 + 2}", "scene.steps"),
    "steps 10^399": ("steps = 1500", "steps = 1" + "0" * 399, "too large"),
    "2048 x 2048, 10^9 steps": ("nx = 64\nny = 32", "nx = 2048\nny = 2048", "scene.steps"),
    "tau of 300 digits": ("reynolds = 20", "reynolds = 1e-300", "tau = 1.08e+300"),
    "100 kB key": ('why = "', "k" * 100_000 + ' = 1\nwhy = "', "unknown key"),
    "climbs out": ('start = "shapes/start.json"', 'start = "../../../../../../../etc/passwd"', "outside"),
    "absolute path": ('file = "shapes/ref.json"', 'file = "/etc/passwd"', "outside"),
}


@pytest.mark.parametrize("case", list(BAD_EXERCISES))
def test_bad_exercise_files_are_one_short_line(exercise, capsys, case):
    old, new, fragment = BAD_EXERCISES[case]
    if case == "2048 x 2048, 10^9 steps":
        edited(exercise, "steps = 1500", "steps = 1000000000")
    edited(exercise, old, new)
    before = digest(exercise.parent)
    code, out, err = run(capsys, "exercise", "check", exercise)
    one_line_refusal(code, err, fragment)
    assert "valid" not in out
    assert digest(exercise.parent) == before


def test_a_link_out_of_the_exercise_folder_is_refused(exercise, capsys, tmp_path):
    outside = tmp_path / "outside.json"
    shutil.copy(exercise.parent / "shapes" / "start.json", outside)
    (exercise.parent / "shapes" / "sneaky.json").symlink_to(outside)
    edited(exercise, 'start = "shapes/start.json"', 'start = "shapes/sneaky.json"')
    code, _, err = run(capsys, "exercise", "check", exercise)
    one_line_refusal(code, err, "lies outside the exercise file's folder")


@pytest.mark.parametrize("what", ["/dev/zero", "/proc/self/mem", "self-symlink", "through a file",
                                  "folder", "long name", "nul byte"])
def test_exercise_paths_that_are_not_files_are_one_line(exercise, capsys, what):
    path = {"/dev/zero": "/dev/zero", "/proc/self/mem": "/proc/self/mem",
            "self-symlink": exercise.parent / "loop.toml", "through a file": exercise / "x.toml",
            "folder": exercise.parent, "long name": exercise.parent / ("x" * 5000 + ".toml"),
            "nul byte": "a\x00b.toml"}[what]
    if what == "self-symlink":
        path.symlink_to(path)
    for action in (("check",), ("score",)):
        argv = ["exercise", *action, path] + ([exercise.parent / "shapes"] if action == ("score",) else [])
        code, _, err = run(capsys, *argv)
        one_line_refusal(code, err)


def test_a_fifo_as_exercise_or_shape_never_blocks(exercise, tmp_path):
    import subprocess
    import sys

    fifo = tmp_path / "pipe.toml"
    os.mkfifo(fifo)
    shape_fifo = exercise.parent / "shapes" / "pipe.json"
    os.mkfifo(shape_fifo)
    r = subprocess.run([sys.executable, "-m", "feelflow.app", "exercise", "check", str(fifo)],
                       capture_output=True, text=True, timeout=30)
    one_line_refusal(r.returncode, r.stderr, "not a regular file")
    edited(exercise, 'start = "shapes/start.json"', 'start = "shapes/pipe.json"')
    r = subprocess.run([sys.executable, "-m", "feelflow.app", "exercise", "check", str(exercise)],
                       capture_output=True, text=True, timeout=30)
    one_line_refusal(r.returncode, r.stderr, "edit.start")


@pytest.mark.parametrize("scale,fragment", [("1000", "--scale: must be in 1..8"),
                                            ("9" * 5000, "at most 18 digits"), ("0", "positive"),
                                            ("2.5", "positive integer")])
def test_scale_out_of_range_is_one_line(exercise, capsys, scale, fragment):
    code, _, err = run(capsys, "exercise", "score", exercise, exercise.parent / "shapes", "--scale", scale,
                       "--out", exercise.parent / "s.csv")
    one_line_refusal(code, err, fragment)
    assert not (exercise.parent / "s.csv").exists()


def test_memory_a_run_needs_is_checked_before_it_starts(exercise, capsys, monkeypatch):
    from feelflow.app import inputs

    # scale 2: 128 x 64 nodes, about 2.5 MiB per run; 4 MiB can be used: one process, not two
    monkeypatch.setattr(inputs, "available_memory", lambda: 4 << 20)
    edited(exercise, "steps = 1500", "steps = 100")
    edited(exercise, "average_steps = 500", "average_steps = 50")
    code, _, err = run(capsys, "exercise", "score", exercise, exercise.parent / "shapes" / "ref.json",
                       exercise.parent / "shapes" / "cylinder.json", "--scale", "2", "--workers", "2",
                       "--out", exercise.parent / "s.csv", "--backend", "numpy")
    assert code == 0, err
    assert "1 processes instead of 2" in err
    monkeypatch.setattr(inputs, "available_memory", lambda: 20 << 20)
    code, _, err = run(capsys, "exercise", "score", exercise, exercise.parent / "shapes" / "ref.json",
                       "--scale", "8", "--out", exercise.parent / "t.csv")
    one_line_refusal(code, err, "512 x 256 nodes need about 0.04 GiB")
    assert "0.02 GiB that can be used here" in err and not (exercise.parent / "t.csv").exists()


def test_a_real_memory_limit_is_a_refusal_not_a_traceback(tmp_path):
    """Under `ulimit -v`, a grid that needs more than the limit is refused in one line."""
    import resource
    import subprocess
    import sys

    folder = tmp_path / "big"
    shutil.copytree(TINY.parent, folder)
    big = edited(folder / "tiny.toml", "nx = 64\nny = 32", "nx = 2048\nny = 2048")

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30))
    r = subprocess.run([sys.executable, "-m", "feelflow.app", "exercise", "check", str(big)],
                       capture_output=True, text=True, timeout=60, preexec_fn=limit)
    one_line_refusal(r.returncode, r.stderr, "of memory")


# --- attempts files and class folders ----------------------------------------------------------
@pytest.mark.parametrize("content,fragment", [
    ("[1, 2", "not valid JSON"),
    ('{"format": "feelflow-attempts", "version": 1, "attempts": ' + "[" * 10000 + "]" * 10000 + "}",
     "nested more than"),
    ('{"format": "feelflow-attempts", "version": ' + "9" * 5000 + ', "attempts": []}', "too large"),
    ('{"format": "feelflow-attempts", "version": 1, "attempts": [{"number": 1}]}', "not an attempt record"),
    ('{"format": "feelflow-attempts", "version": 1, "attempts": [{"number": 1, "time": "t", "shape": '
     '{"kind": "cylinder", "diameter": 6}, "status": "scored", "score": "2.0", "cd": null, "cl": null, '
     '"steps": 10, "seconds": 1.0, "reason": ""}]}', "attempts[0].score has the wrong type"),
    ('{"format": "feelflow-attempts", "version": 1, "attempts": [{"number": 1, "time": "t", "shape": '
     '{"kind": "cylinder", "diameter": -6}, "status": "scored", "score": 2.0, "cd": null, "cl": null, '
     '"steps": 10, "seconds": 1.0, "reason": ""}]}', "attempts[0].shape"),
    ("fifo", "not a regular file"),
    ("/dev/zero", "not a regular file"),
    ("loop", "cannot be read"),
])
def test_bad_attempts_files_are_one_line(tmp_path, content, fragment):
    from feelflow.app.errors import UserError
    from feelflow.app.exercises.attempts import Attempts
    from feelflow.app.exercises.format import load_exercise

    ex = load_exercise(TINY)
    path = tmp_path / "tiny.attempts.json"
    if content == "fifo":
        os.mkfifo(path)
    elif content == "/dev/zero":
        path.symlink_to("/dev/zero")
    elif content == "loop":
        path.symlink_to(path)
    else:
        path.write_text(content)
    with pytest.raises(UserError) as info:
        Attempts(ex, tmp_path)
    text = str(info.value)
    assert fragment in text and "\n" not in text and len(text) < 400, text


def test_a_class_folder_of_odd_entries_gets_a_row_each_and_changes_nothing(exercise, capsys, tmp_path):
    folder = tmp_path / "class"
    folder.mkdir()
    shutil.copy(exercise.parent / "shapes" / "ref.json", folder / "good.json")
    os.mkfifo(folder / "pipe.json")
    (folder / "zero.json").symlink_to("/dev/zero")
    (folder / "loop.json").symlink_to(folder / "loop.json")
    (folder / "dir.json").mkdir()
    (folder / ("n" * 250 + ".json")).write_text('{"format": "feelflow-shape", "version": 1, "shape": ' +
                                                "[" * 5000 + "]" * 5000 + "}")
    (folder / "huge.json").write_text('{"format": "feelflow-shape", "version": ' + "1" * 5000 + "}")
    (folder / "notes.txt").write_text("not a shape")
    before = digest(folder)
    out = tmp_path / "scores.csv"
    code, stdout, err = run(capsys, "exercise", "score", exercise, folder, "--out", out, "--workers", "1",
                            "--backend", "numpy")
    assert code == 0, err
    assert "Traceback" not in err
    import csv

    rows = {pathlib.Path(r["file"]).name: r for r in csv.DictReader(out.open())}
    assert len(rows) == 7 and rows["good.json"]["status"] == "scored"
    for name, row in rows.items():
        if name != "good.json":
            assert row["status"] == "not a shape file" and len(row["reason"]) < 300, row
    assert digest(folder) == before


def test_class_folder_problems_are_one_line(exercise, capsys, tmp_path):
    code, _, err = run(capsys, "exercise", "score", exercise, tmp_path / ("x" * 5000))
    one_line_refusal(code, err, "no such shape file or folder")
    empty = tmp_path / "empty"
    empty.mkdir()
    code, _, err = run(capsys, "exercise", "score", exercise, empty)
    one_line_refusal(code, err, "no shape files")


def test_the_window_shows_the_scored_flow_in_float32():
    """ScoringScene.live_scene: the window's tunnel for an exercise is the flow it is scored in
    (grid, viscosity, wind, walls, outlet sponge), in float32."""
    from feelflow import EXERCISE_DIR
    from feelflow.app.exercises.format import load_exercise
    from feelflow.app.model.scene import scene_from_dict

    exercise = load_exercise(EXERCISE_DIR / "most_lift.toml")
    s = exercise.scene
    live, scored = scene_from_dict(s.live_scene(), exercise.source).config, s.flow_config()
    for key in ("nx", "ny", "nu", "inflow_speed", "y_boundary", "sponge_cells", "initial_velocity"):
        assert getattr(live, key) == getattr(scored, key), key
    assert live.dtype == "float32" and scored.dtype == "float64"
