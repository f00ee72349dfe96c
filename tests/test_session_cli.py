"""`feelflow session ...` as a user runs it: exit codes, one-line errors, no tracebacks."""
from __future__ import annotations

import csv
import json
import subprocess
import sys
from pathlib import Path

import pytest

from feelflow.app.sessions import SessionRecorder, SessionSolver
from session_scenes import MODELS, drive_moving_cylinder, small_config, start_body
from feelflow.solver.backend import create_solver

ROOT = Path(__file__).resolve().parents[1]


def feelflow(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "feelflow.app", *map(str, args)], cwd=cwd or ROOT,
                          capture_output=True, text=True, timeout=120)


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    cfg = small_config()
    rec = SessionRecorder(cfg, start_body(), MODELS, scene_source="scenes/test.toml")
    drive_moving_cylinder(SessionSolver(create_solver("numpy", cfg), rec), steps=25)
    path = tmp_path_factory.mktemp("cli") / "run.ffsession"
    rec.save(path)
    return path


def test_info_replay_export(recorded, tmp_path):
    r = feelflow("session", "info", recorded)
    assert r.returncode == 0, r.stderr
    assert "64 x 32" in r.stdout and "momentum_exchange, pressure" in r.stdout
    r = feelflow("session", "info", recorded, "--json")
    assert r.returncode == 0 and json.loads(r.stdout)["format"] == "feelflow-session"

    out = tmp_path / "replayed.csv"
    r = feelflow("session", "replay", recorded, "--check", "--out", out)
    assert r.returncode == 0, r.stderr
    assert "largest force deviation 0 " in r.stdout

    exported, manifest = tmp_path / "recorded.csv", tmp_path / "manifest.json"
    r = feelflow("session", "export", recorded, "--csv", exported, "--manifest", manifest)
    assert r.returncode == 0, r.stderr
    assert exported.read_text() == out.read_text()  # the replay wrote what was recorded
    with open(exported, newline="") as fh:
        header = next(csv.reader(fh))
    assert header == ["step", "x", "y", "vx", "vy", "fx_momentum_exchange", "fy_momentum_exchange",
                      "fx_pressure", "fy_pressure", "torque_momentum_exchange", "torque_pressure"]
    assert json.loads(manifest.read_text())["counts"]["inputs"] == 25


def one_line_error(r, *words):
    assert r.returncode == 2, (r.returncode, r.stdout, r.stderr)
    assert "Traceback" not in r.stderr + r.stdout
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("feelflow: "), r.stderr
    for w in words:
        assert w in lines[0], lines[0]


def test_bad_files_exit_2_with_one_line(recorded, tmp_path):
    junk = tmp_path / "junk.ffsession"
    junk.write_bytes(b"PK\x03\x04 not really a zip")
    cut = tmp_path / "cut.ffsession"
    cut.write_bytes(recorded.read_bytes()[:-200])
    for action in (["info"], ["replay"], ["export", "--csv", tmp_path / "x.csv"]):
        one_line_error(feelflow("session", *action[:1], junk, *action[1:]), "not a zip")
        one_line_error(feelflow("session", *action[:1], cut, *action[1:]), str(cut))
        one_line_error(feelflow("session", *action[:1], tmp_path / "none.ffsession", *action[1:]), "no such")


def test_bad_options_exit_2(recorded, tmp_path):
    one_line_error(feelflow("session", "replay", recorded, "--backend", "cuda"), "--backend")
    one_line_error(feelflow("session", "replay", recorded, "--tolerance", "abc"), "--tolerance")
    one_line_error(feelflow("session", "export", recorded), "--csv")
    one_line_error(feelflow("session", "export", recorded, "--csv", tmp_path / "no" / "x.csv"), "cannot write")
