"""A recording stops at the most a session file may hold (app/sessions/bounds.py), so that it
never saves a file its own loader refuses; the bound is made small here to reach it quickly."""
from __future__ import annotations

import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from feelflow.app import inputs
from feelflow.app.sessions import SessionRecorder, SessionSolver, bounds, load_session, replay
from feelflow.solver.backend import create_solver
from session_scenes import MODELS, drive_moving_cylinder, small_config, start_body

ROOT = Path(__file__).resolve().parents[1]
BOUND = 12


def _record(steps=40):
    cfg = small_config()
    rec = SessionRecorder(cfg, start_body(), MODELS)
    ss = SessionSolver(create_solver("numpy", cfg), rec)
    drive_moving_cylinder(ss, steps=steps, extras=False)   # an input and a force row per move
    return rec


def test_recorder_stops_at_the_row_bound_and_its_file_opens_and_replays(monkeypatch, tmp_path):
    monkeypatch.setattr(bounds, "MAX_ROWS", BOUND)   # the loader's bound and the recorder's: one constant
    rec = _record()
    assert rec.full is not None and "\n" not in rec.full and f"at most {BOUND} " in rec.full
    s = rec.session()
    counts = s.manifest["counts"]
    assert max(counts["inputs"], counts["parameters"], counts["forces"]) == BOUND
    # nothing after the stop: the clock stays where the last force row ended
    assert counts["steps"] == int(s.forces["step"][-1]) and rec.record_forces(1, {}) is False
    path = rec.save(tmp_path / "full.ffsession")
    loaded = load_session(path)          # under the same small bound
    assert loaded.manifest["counts"] == counts
    result = replay(loaded)
    assert result.max_force > 1e-3 and result.max_deviation == 0.0


def test_recorder_stops_at_the_step_bound(monkeypatch, tmp_path):
    monkeypatch.setattr(inputs, "MAX_STEPS", 20)
    rec = _record()
    assert rec.full is not None and "steps" in rec.full
    assert 18 <= rec.step <= 20    # rows of 1-3 steps: the last one that fits
    result = replay(load_session(rec.save(tmp_path / "steps.ffsession")))
    assert result.max_deviation == 0.0


def test_a_recording_within_the_bound_is_not_cut():
    rec = _record(steps=10)
    assert rec.full is None and rec.session().manifest["counts"]["forces"] == 10


SCENE = """
[grid]
nx = 64
ny = 32
[flow]
nu = 0.05
inflow_speed = 0.03
inflow_ramp_steps = 10
[body]
kind = "cylinder"
diameter = 8
x = 24
y = 16.2
[[motion]]
steps = 10
move = "stop"
[[motion]]
steps = 20
move = "against"
[output]
forces = ["momentum_exchange"]
interval = 5
"""


def test_cli_run_record_stops_the_recording_goes_on_and_exits_1(tmp_path):
    """`feelflow run --record` past the bound: one line on stderr, exit 1, every force row in
    --out, and the session holds the recording's first part, opens and replays."""
    scene, out, rec = tmp_path / "s.toml", tmp_path / "f.csv", tmp_path / "r.ffsession"
    scene.write_text(SCENE)
    code = ("import sys; from feelflow.app.sessions import bounds; bounds.MAX_ROWS = %d; "
            "from feelflow.app.cli.main import main; sys.exit(main(sys.argv[1:]))" % BOUND)
    r = subprocess.run([sys.executable, "-c", code, "run", scene, "--backend", "numpy", "--out", out,
                        "--record", rec], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert r.returncode == 1, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "--record" in lines[0] and "stopped" in lines[0] and "Traceback" not in r.stderr
    steps = sum(p["steps"] for p in tomllib.loads(SCENE)["motion"])
    assert len(out.read_text().splitlines()) == 1 + steps // 5    # the run went on to its end
    s = load_session(rec)
    assert s.manifest["counts"]["inputs"] == BOUND and s.steps < steps
    assert replay(s).max_deviation == 0.0


def test_cli_run_record_within_the_bound_exits_0(tmp_path):
    scene, out, rec = tmp_path / "s.toml", tmp_path / "f.csv", tmp_path / "r.ffsession"
    scene.write_text(SCENE)
    r = subprocess.run([sys.executable, "-m", "feelflow.app", "run", scene, "--backend", "numpy", "--out", out,
                        "--record", rec], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and r.stderr == "", r.stderr
    assert load_session(rec).steps == 30


def test_recorder_stops_before_its_parameter_changes_outgrow_their_member(monkeypatch, tmp_path):
    """parameters.json is bounded by bytes (bounds.MAX_JSON_BYTES), not only by rows: the recorder
    counts the bytes it will write, exactly, and stops before the member would pass them."""
    import json
    import zipfile

    cfg = small_config()
    rec = SessionRecorder(cfg, start_body(), MODELS)
    manifest = len(json.dumps(rec.session().manifest, indent=2)) + 1
    monkeypatch.setattr(bounds, "MAX_JSON_BYTES", manifest + 600)   # the manifest fits; a few changes do
    ss = SessionSolver(create_solver("numpy", cfg), rec)
    for _ in range(40):
        ss.pause()
        ss.resume()
    assert rec.full is not None and "bytes of parameter changes" in rec.full
    path = rec.save(tmp_path / "params.ffsession")
    with zipfile.ZipFile(path) as zf:
        size = zf.getinfo("parameters.json").file_size
    assert size == rec.parameters_bytes <= bounds.MAX_JSON_BYTES
    assert len(load_session(path).parameters) == len(rec.session().parameters) > 3
