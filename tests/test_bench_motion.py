"""`feelflow bench motion` (app/bench/motion_cost.py): every backend by default, a backend that
cannot run here named and skipped, and per backend the held and towed step times, a move's cost
per step and towed / held from the same rounds. Speed itself is measured, not asserted."""
from __future__ import annotations

from types import SimpleNamespace

from feelflow.app.bench import motion_cost
from feelflow.app.errors import UserError


def test_measure_reports_the_move_cost_and_the_ratio_of_the_same_rounds():
    r = motion_cost.measure("numpy", grid=(96, 48), steps=10, rounds=1, warmup=2)
    assert r["backend"] == "numpy" and r["grid"] == "96x48"
    assert r["held_ms_per_step"] > 0 and r["towed_ms_per_step"] > 0
    assert abs(r["move_ms_per_step"] - (r["towed_ms_per_step"] - r["held_ms_per_step"])) < 2e-3
    assert abs(r["towed_over_held"] - r["towed_ms_per_step"] / r["held_ms_per_step"]) < 1e-2


def test_every_backend_by_default_and_one_that_cannot_run_is_named(monkeypatch, capsys):
    asked = []

    def measure(backend, grid, steps, rounds, warmup):
        asked.append(backend)
        if backend == "gl":
            raise UserError("--backend gl: no GL context here")
        return {"backend": backend, "grid": "256x128", "held_ms_per_step": 1.0, "towed_ms_per_step": 1.2,
                "move_ms_per_step": 0.2, "towed_over_held": 1.2, "load_average": 0.5}

    monkeypatch.setattr(motion_cost, "measure", measure)
    args = SimpleNamespace(backend=None, grid=None, quick=True, rounds=None, json=None)
    assert motion_cost.main(args) == 0
    out = capsys.readouterr().out
    assert asked == ["numpy", "cpu", "gl"]
    assert "gl    : skipped, --backend gl: no GL context here" in out
    assert "cpu      256x128: held 1.000 ms/step, towed 1.200 ms/step, a move 0.200 ms/step" in out
