"""`feelflow bench`: its alternating rounds, the ratios it takes within each round, and the
tunnel's warm-up (app/bench/solver_speed.py)."""
import json

import numpy as np
import pytest

from feelflow.app.cli.main import main as cli_main


def test_bench_alternates_the_backends_in_rounds_and_takes_the_median_ratio(tmp_path, capsys):
    """`feelflow bench --rounds N`: every scene and grid on both backends in N alternating rounds;
    a row is the median of its rounds, a speedup the median of the per-round ratios."""
    out = tmp_path / "bench.json"
    assert cli_main(["bench", "--quick", "--rounds", "2", "--seconds", "0.01", "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["rounds"] == 2 and len(data["results"]) == 12
    for row in data["results"]:
        if "error" in row:  # no EGL context here: the numpy rows stay
            continue
        assert len(row["rounds_mlups"]) == 2 and row["mlups"] == pytest.approx(np.median(row["rounds_mlups"]), abs=0.01)
    for key, per_round in data["speedups_per_round"].items():
        assert len(per_round) == 2 and data["speedups"][key] == round(float(np.median(per_round)), 2)
    assert "rounds:" in capsys.readouterr().out


def test_bench_refuses_fewer_than_one_round(capsys):
    """One line on stderr, before anything is measured or printed."""
    assert cli_main(["bench", "--rounds", "0"]) == 2
    out, err = capsys.readouterr()
    assert err.strip().splitlines() == ["feelflow: --rounds: must be at least 1, got 0"] and out == ""


def test_tunnel_warm_up_outlasts_the_subnormal_start_up_transient():
    """The bench measures a tunnel only after its start-up transient: while the inlet's sound
    front crosses the still fluid, float32 stores populations so small they are subnormal, which
    slow numpy's arithmetic (not llvmpipe's, which flushes them to zero) and so bias the ratio."""
    from feelflow.app.bench.solver_speed import SceneRun, scene_config, warmup_steps
    from feelflow.solver.backend import create_solver

    run = SceneRun("tunnel", create_solver("numpy", scene_config("tunnel", 256, 128)))
    tiny = np.finfo(np.float32).tiny

    def subnormal():
        f = run.solver.shifted_distributions()
        return int(np.count_nonzero((f != 0) & (np.abs(f) < tiny)))

    run.advance(128)
    assert subnormal() > 1000  # mid-transient: the premise
    run.advance(warmup_steps("tunnel", run.solver.config, quick=False) - 128)
    assert subnormal() == 0
    assert warmup_steps("tunnel", run.solver.config, quick=True) == warmup_steps("box", run.solver.config, False) == 20
