"""`feelflow run` and `feelflow validate` as a user meets them: real subprocesses.

Errors: exit 2, exactly one line on stderr, no traceback. A run writes the documented CSV.
"""
import csv
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]

SMALL = """
[grid]
nx = 64
ny = 32

[flow]
nu = 0.05
inflow_speed = 0.04
inflow_ramp_steps = 20

[body]
kind = "cylinder"
diameter = 8
x = 20
y = 16.3

[[motion]]
steps = 30
move = "stop"

[[motion]]
steps = 30
velocity = [0.02, 0.01]

[output]
forces = ["momentum_exchange", "momentum_exchange_classic"]
interval = 20
"""


def feelflow(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "feelflow.app", *map(str, args)], cwd=cwd or ROOT,
                          capture_output=True, text=True, timeout=300)


def assert_one_line_error(result, *fragments, code=2):
    assert result.returncode == code, (result.returncode, result.stderr)
    lines = result.stderr.strip("\n").split("\n")
    assert len(lines) == 1, result.stderr
    assert "Traceback" not in result.stderr
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


def write(tmp_path, text, name="scene.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_missing_scene_file(tmp_path):
    assert_one_line_error(feelflow("run", tmp_path / "missing.toml"), "missing.toml: no such scene file")


def test_bad_value_names_the_key(tmp_path):
    scene = write(tmp_path, SMALL.replace("diameter = 8", "diameter = -3"))
    assert_one_line_error(feelflow("run", scene), "scene.toml: body.diameter: must be a positive number, got -3")


def test_unknown_key(tmp_path):
    scene = write(tmp_path, SMALL.replace("[flow]", "[flow]\nviscosty = 0.1"))
    assert_one_line_error(feelflow("run", scene), "flow.viscosty: unknown key")


def test_not_toml(tmp_path):
    scene = write(tmp_path, "grid = [\n")
    assert_one_line_error(feelflow("run", scene), "scene.toml: not valid TOML")


@pytest.mark.parametrize("steps", ["-5", "0", "ten", "1.5"])
def test_bad_steps_option(tmp_path, steps):
    scene = write(tmp_path, SMALL)
    assert_one_line_error(feelflow("run", scene, "--steps", steps), "--steps: must be a positive integer")


def test_bad_backend_and_output_directory(tmp_path):
    scene = write(tmp_path, SMALL)
    assert_one_line_error(feelflow("run", scene, "--backend", "cuda"), "--backend: must be one of cpu, gl, numpy or auto")
    assert_one_line_error(feelflow("run", scene, "--out", tmp_path / "no" / "f.csv"), "--out: directory")


def test_validate_rejects_unknown_case_and_bad_resolution():
    assert_one_line_error(feelflow("validate", "--case", "wind"), "--case: unknown case 'wind'")
    assert_one_line_error(feelflow("validate", "--case", "taylor-green", "--resolution", "x"),
                          "--resolution: must be a positive integer")


def test_validate_refine_names_what_it_cannot_refine():
    """`--refine` is the numpy reference's patch around a body (solver/refinement.py)."""
    assert_one_line_error(feelflow("validate", "--refine", "--backend", "gl"),
                          "--refine: the refined patch runs on the numpy backend only, not 'gl'")
    assert_one_line_error(feelflow("validate", "--refine", "--case", "poiseuille"),
                          "--refine: case 'poiseuille' has no body to refine around")


def test_run_writes_the_documented_csv(tmp_path):
    scene = write(tmp_path, SMALL)
    out = tmp_path / "forces.csv"
    result = feelflow("run", scene, "--out", out, "--backend", "numpy")
    assert result.returncode == 0, result.stderr
    rows = list(csv.reader(out.open()))
    assert rows[0] == ["step", "x", "y", "vx", "vy", "fx_momentum_exchange", "fy_momentum_exchange",
                       "fx_momentum_exchange_classic", "fy_momentum_exchange_classic",
                       "torque_momentum_exchange", "torque_momentum_exchange_classic"]
    data = [[float(v) for v in r] for r in rows[1:]]
    assert [r[0] for r in data] == [20, 40, 60]  # one row per interval, the last one shorter
    # the body rests for 30 steps, then moves at (0.02, 0.01): after 60 steps it moved 30 steps
    assert data[-1][1:5] == pytest.approx([20 + 0.6, 16.3 + 0.3, 0.02, 0.01])
    assert data[0][1:5] == pytest.approx([20, 16.3, 0.0, 0.0])
    assert data[-1][5] > 0  # the stream pushes the body downstream
    assert not list(tmp_path.glob(".forces.csv.*"))  # no temporary file left behind


def test_run_steps_option_overrides_the_scene(tmp_path):
    scene = write(tmp_path, SMALL)
    out = tmp_path / "f.csv"
    assert feelflow("run", scene, "--steps", "40", "--out", out, "--backend", "numpy").returncode == 0
    assert [r[0] for r in list(csv.reader(out.open()))[1:]] == ["20", "40"]


def test_divergence_is_one_line_and_exit_1(tmp_path):
    text = SMALL.replace("nu = 0.05", "nu = 0.000001\ncollision = \"bgk\"").replace(
        "inflow_speed = 0.04", "inflow_speed = 0.095").replace("inflow_ramp_steps = 20", "inflow_ramp_steps = 0")
    scene = write(tmp_path, text.replace("[output]", "[run]\nsteps = 3000\n\n[output]"))
    result = feelflow("run", scene, "--out", tmp_path / "f.csv", "--backend", "numpy")
    # far outside the measured stable region: run warns first (one line), then, once its flow has
    # left the operator's local region (solver/local_guard.py), says so (one line), then the error
    warning, local, error = result.stderr.strip("\n").split("\n")
    assert warning.startswith("feelflow: warning:") and "stable" in warning
    assert local.startswith("feelflow: warning: step ") and "where it is fastest" in local
    assert "runs as written" in local
    assert result.returncode == 1 and "diverged" in error and "Traceback" not in result.stderr


def test_validate_prints_a_table_and_writes_json(tmp_path):
    import json

    out = tmp_path / "v.json"
    result = feelflow("validate", "--case", "taylor-green", "--quick", "--json", out)
    assert result.returncode == 0, result.stderr
    assert "| taylor-green | 32 |" in result.stdout and "| nu_rel_error |" in result.stdout
    data = json.loads(out.read_text())
    case = data["cases"][0]
    assert case["name"] == "taylor-green" and case["backend"] == "numpy" and case["resolution"] == 32
    assert case["steps"] > 0 and case["wall_seconds"] > 0 and case["mlups"] > 0
    assert case["case_seconds"] >= case["wall_seconds"]   # the whole case: set-up and analysis too
    assert abs(case["quantities"]["nu_rel_error"]) < 0.01 and case["passed"] is True


@pytest.mark.gl
def test_run_on_gl_matches_numpy(tmp_path):
    """`--backend gl` (own EGL context) writes the same forces as the numpy reference, to the
    float32 tolerance of docs/science/algorithm.md."""
    scene = write(tmp_path, SMALL)
    tables = {}
    for backend in ("numpy", "gl"):
        out = tmp_path / f"{backend}.csv"
        result = feelflow("run", scene, "--backend", backend, "--out", out)
        assert result.returncode == 0, result.stderr
        tables[backend] = [[float(v) for v in r] for r in list(csv.reader(out.open()))[1:]]
    for a, b in zip(tables["numpy"], tables["gl"]):
        assert b[:5] == pytest.approx(a[:5])
        scale = max(abs(v) for v in a[5:])
        assert max(abs(x - y) for x, y in zip(a[5:], b[5:])) <= 1e-4 * scale


def test_validate_reports_a_blow_up_as_a_failed_case():
    # 2D-2 (Re 100) at 10 cells per diameter needs tau = 0.515: the flow blows up
    result = feelflow("validate", "--case", "schaefer-turek-2d2", "--resolution", "10")
    assert result.returncode == 1
    assert "Traceback" not in result.stderr and result.stderr == ""
    assert "| stable | 0 | 1 .. 1 | **no** |" in result.stdout


def test_run_record_replays_to_the_same_forces(tmp_path):
    """`run --record` writes a session whose numpy replay reproduces the run's forces exactly
    (with `--si` the units are recorded too and change nothing in the replay).
    Its export has one row per solver call (finer than the run's interval means): where both
    have a row the velocity agrees (the export's pose is the pose during the call, the run's the
    pose after it: docs/reference/session-format.md), and over the first interval (one call) the forces too."""
    scene = write(tmp_path, SMALL)
    out, session = tmp_path / "forces.csv", tmp_path / "run.ffsession"
    result = feelflow("run", scene, "--out", out, "--record", session, "--si", "water:0.01", "--backend", "numpy")
    assert result.returncode == 0, result.stderr
    from feelflow.app.sessions import load_session
    assert load_session(session).units == {"fluid": "water", "size_m": 0.01, "span_m": 0.1}   # --si recorded
    check = feelflow("session", "replay", session, "--check", "--tolerance", "0")
    assert check.returncode == 0, check.stdout + check.stderr
    exported = tmp_path / "export.csv"
    assert feelflow("session", "export", session, "--csv", exported).returncode == 0
    export_rows = [[float(v) for v in r] for r in list(csv.reader(exported.open()))[1:]]
    lattice = len(export_rows[0])   # the run's lattice columns; its SI ones (--si) follow them
    run_rows = [[float(v) for v in r[:lattice]] for r in list(csv.reader(out.open()))[1:]]
    by_step = {r[0]: r for r in export_rows}
    assert set(r[0] for r in run_rows) <= set(by_step)
    for row in run_rows:
        assert by_step[row[0]][3:5] == pytest.approx(row[3:5], rel=1e-9, abs=1e-12)
    assert by_step[20.0] == pytest.approx(run_rows[0], rel=1e-9, abs=1e-15)


def test_run_record_into_missing_directory_is_one_line(tmp_path):
    scene = write(tmp_path, SMALL)
    result = feelflow("run", scene, "--out", tmp_path / "f.csv", "--record", tmp_path / "nope" / "s.ffsession", "--backend", "numpy")
    assert_one_line_error(result, "nope")


def test_validate_refuses_a_resolution_the_channel_cannot_have():
    """A Schaefer-Turek resolution whose channel (4.1 D) is not whole cells is one line, exit 2,
    before anything runs."""
    result = feelflow("validate", "--case", "schaefer-turek-2d1", "--resolution", "16")
    assert result.returncode == 2 and result.stdout == ""
    line, = result.stderr.strip().splitlines()
    assert "--resolution" in line and "multiple of 10" in line and "got 16" in line
