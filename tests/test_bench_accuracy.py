"""`feelflow bench accuracy`: speed against error on Schaefer-Turek 2D-1 (app/bench/accuracy.py)."""
import json
import math

import pytest

from feelflow.app.bench import accuracy as bench_accuracy
from feelflow.app.cli.main import main as cli_main


def _numpy64(config):
    from feelflow.solver.backend import create_solver

    return create_solver("numpy", config)


#: float32 storage: the float64 errors to 2e-5 (the CLI test below), at 1.6x the speed
_numpy32 = bench_accuracy._factory("numpy", "float32", None)


@pytest.mark.slow
def test_error_falls_with_resolution_and_work_rises():
    """Against the reference values (benchmarks.md): from 10 to 20 cells per diameter the C_D
    error falls, and dp converges at better than first order (2.5 observed here); the finer run
    costs more."""
    coarse = bench_accuracy.run_point(_numpy32, 10, 0.075)
    fine = bench_accuracy.run_point(_numpy32, 20, 0.075)
    assert coarse["converged"] and fine["converged"]
    assert abs(fine["cd_error"]) < abs(coarse["cd_error"]) < 0.03
    dp_order = math.log(coarse["dp_error"] / fine["dp_error"]) / math.log(20 / 10)
    assert dp_order > 1.5
    assert fine["node_updates"] > 2 * coarse["node_updates"]
    (order,) = bench_accuracy.observed_orders([coarse, fine])
    assert (order["from_d"], order["to_d"]) == (10, 20) and order["order"] > 0


def test_the_fitted_order_recovers_a_power_law_through_scatter():
    """The least-squares order of C_D errors e = a D^-2 (1 +- 30 %, alternating) is 2 within the
    scatter's pull, and the successive orders show the scatter."""
    rows = [{"d": d, "cd_error": 0.5 * d ** -2.0 * (1.3 if k % 2 else 0.7)} for k, d in enumerate((8, 12, 16, 24, 32))]
    assert bench_accuracy.fitted_order(rows) == pytest.approx(2.0, abs=0.35)
    orders = [o["order"] for o in bench_accuracy.observed_orders(rows)]
    assert min(orders) < 1.0 < 3.0 < max(orders)


def test_cli_sweeps_both_numpy_precisions_and_writes_json(tmp_path, monkeypatch, capsys):
    """One point per axis (monkeypatched axes keep it short): float32 storage of f - w rho0 gives
    the float64 answer to float32 precision, and the JSON holds the machine and every row."""
    monkeypatch.setattr(bench_accuracy, "QUICK_RESOLUTIONS", (10,))
    monkeypatch.setattr(bench_accuracy, "QUICK_SPEEDS", (0.075,))
    monkeypatch.setattr(bench_accuracy, "QUICK_TAU_FIXED", ((10, 0.075),))
    out = tmp_path / "acc.json"
    assert cli_main(["bench", "accuracy", "--quick", "--backend", "numpy", "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["machine"]["cores"] >= 1 and set(data["variants"]) == {"numpy float64", "numpy float32"}
    r64, r32 = (data["variants"][k]["resolution"][0] for k in ("numpy float64", "numpy float32"))
    assert r64["grid"] == "220x41" and r64["steps"] > 0 and r64["mlups"] > 0
    assert r32["cd_error"] == pytest.approx(r64["cd_error"], abs=2e-5)
    assert data["variants"]["numpy float64"]["speed"][0] == r64  # the shared point is not run twice
    assert data["variants"]["numpy float64"]["tau"] == [r64]
    printed = capsys.readouterr().out
    assert "C_D err %" in printed and "numpy float32" in printed


def test_cli_runs_only_the_axes_asked_for(tmp_path, monkeypatch, capsys):
    """`--axis tau`: only the fixed-tau points run (here one, D = 10), the other axes stay empty,
    and the printed tables leave them out."""
    monkeypatch.setattr(bench_accuracy, "QUICK_TAU_FIXED", ((10, 0.075),))
    out = tmp_path / "acc.json"
    assert cli_main(["bench", "accuracy", "--quick", "--backend", "numpy", "--axis", "tau", "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    for v in data["variants"].values():
        assert v["resolution"] == [] and v["speed"] == [] and [(r["d"], r["u_max"]) for r in v["tau"]] == [(10, 0.075)]
    printed = capsys.readouterr().out
    assert "Axis: resolution at fixed tau" in printed and "Axis: time step" not in printed
