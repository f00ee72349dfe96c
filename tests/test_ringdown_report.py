"""`feelflow report ringdown` (app/reports/ringdown.py): the chain runs, before and after in one
table, bad input refused in one line. The figures themselves are in docs/science/quiet-tunnel.md,
measured by the full command; --quick runs a few hundred steps (a smoke test, not physics)."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from feelflow.app.model.simulation import default_base_config
from feelflow.app.reports.ringdown import WINDOW_BEFORE, run_window, window_case

ROOT = Path(__file__).resolve().parents[1]
CLI = [sys.executable, "-c", "import sys; from feelflow.app.cli.main import main; sys.exit(main())"]


def test_window_case_is_the_windows_tunnel_and_before_differs_only_by_the_inlet():
    cfg, body, _ = window_case()
    assert (cfg.nx, cfg.ny) == (256, 128) and body.diameter == 20
    assert cfg.inlet_nonreflecting == default_base_config((256, 128)).inlet_nonreflecting > 0
    assert cfg.inflow_speed * body.diameter / cfg.nu == 40.0
    assert WINDOW_BEFORE == {"inlet_nonreflecting": 0.0}


def test_quick_window_run_reports_both_swings():
    r = run_window("numpy", before=False, quick=True)
    assert r["settled_drag"] > 0 and r["swing_after_stop"] > 0 and r["swing_before_move"] > 0
    assert r["boundaries"] == "after" and r["quiet_inlet"] > 0


def test_report_ringdown_refuses_bad_input_in_one_line():
    for extra in (["--only", "d40"], ["--phase-steps", "10"]):
        r = subprocess.run([*CLI, "report", "ringdown", *extra], capture_output=True, text=True, cwd=ROOT)
        assert r.returncode == 2, r.stderr
        assert len(r.stderr.strip().splitlines()) == 1 and extra[1] in r.stderr


def test_report_towed_quick_runs_held_and_towed_rows():
    """`feelflow report towed --quick` (app/reports/towed.py): the held row and one towed row per
    impulse scheme asked for (a smoke test of the chain, not physics)."""
    r = subprocess.run([*CLI, "report", "towed", "--quick", "--impulse", "absolute"], capture_output=True,
                       text=True, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    rows = [line for line in r.stdout.splitlines() if line.startswith("| held") or line.startswith("| towed")]
    assert len(rows) == 2 and "absolute" in rows[1]


def test_report_towed_refuses_bad_schemes_in_one_line():
    for extra in (["--impulse", "smooth"], ["--refill", "magic"], ["--backend", "fast"]):
        r = subprocess.run([*CLI, "report", "towed", "--quick", *extra], capture_output=True, text=True, cwd=ROOT)
        assert r.returncode == 2, r.stderr
        assert len(r.stderr.strip().splitlines()) == 1 and extra[1] in r.stderr


@pytest.mark.slow
@pytest.mark.timeout(1800)   # (a few minutes on cpu; numba compiles the moving body's kernels first)
def test_towed_cylinder_drag_is_calm_and_galilean_invariant():
    """The full towed-versus-held case (docs/science/force-models.md, 'A moving body';
    `feelflow report towed --backend cpu`): the momentum exchange's mean drag within 2 % of the
    held body's, its noise per step at most 15 % and over 25-step means at most 2 % of the mean.
    On the compiled cpu backend (equal to numpy, tests/test_body_local_move.py; on numpy it took
    350 s on a loaded 2-core machine)."""
    from feelflow.app.reports.towed import run

    held, towed = run("cpu", False), run("cpu", True)
    mea = towed["momentum_exchange"]
    assert mea["mean"] == pytest.approx(held["momentum_exchange"]["mean"], rel=0.02)
    assert mea["noise_1"] <= 0.15 and mea["noise_25"] <= 0.02


def test_report_ringdown_runs_a_scene_file_and_refuses_one_that_never_moves(tmp_path):
    """`feelflow report ringdown --scene FILE --quick`: the scene as it stands (here with no
    boundary keys: the quiet tunnel by default), one row; a scene whose body never moves is one
    line, exit 2."""
    scene = tmp_path / "moved.toml"
    body = ('[grid]\nnx = 96\nny = 48\n[flow]\nnu = 0.02\ninflow_speed = 0.04\ninflow_ramp_steps = 0\n'
            'initial_velocity = [0.04, 0.0]\n[body]\nkind = "cylinder"\ndiameter = 8\nx = 30\ny = 24\n')
    scene.write_text(body + '[[motion]]\nsteps = 20\nmove = "stop"\n[[motion]]\nsteps = 20\nmove = "against"\n'
                     '[[motion]]\nsteps = 300\nmove = "stop"\n')
    r = subprocess.run([*CLI, "report", "ringdown", "--scene", str(scene), "--quick"], capture_output=True,
                       text=True, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    row = [line for line in r.stdout.splitlines() if line.startswith("| scene")]
    assert len(row) == 1 and "| 0.001 | 0.1 |" in row[0]
    still = tmp_path / "still.toml"
    still.write_text(body + "[run]\nsteps = 100\n")
    r = subprocess.run([*CLI, "report", "ringdown", "--scene", str(still), "--quick"], capture_output=True,
                       text=True, cwd=ROOT)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and "never moves" in r.stderr
