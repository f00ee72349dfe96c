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
    results = exercise.parent / "results.csv"
    results.write_text("old\n")
    before = digest(exercise.parent / "shapes")
    code, out, err = run(capsys, "exercise", "score", exercise, exercise.parent / "shapes" / "ref.json",
                         "--out", results, "--force", "--workers", "1")
    assert code == 0, err
    text = results.read_text()
    assert text.startswith("rank,file,status") and "ref.json" in text and "scored" in text
    assert digest(exercise.parent / "shapes") == before
    assert not [p for p in exercise.parent.iterdir() if p.name.startswith(".feelflow-tmp-")]
