"""The right backend on every machine (app/model/backend_choice.py): real backends timed on a
small grid, the fastest chosen, the choice remembered per (GL renderer, grid), and
`feelflow run --backend auto` making the same choice in one printed line."""
from __future__ import annotations

import json

import pytest

from feelflow.app.cli.main import main as cli_main
from feelflow.app.model.backend_choice import (JsonFileStore, choice_key, choose_backend,
                                               time_backend)
from feelflow.solver.backend import create_solver
from feelflow.solver.config import FlowConfig

CFG = FlowConfig(nx=64, ny=32, nu=0.02, dtype="float32", inflow_ramp_steps=20)


class MemoryStore:
    """A ChoiceStore (app/model/backend_choice.py) in a dict."""

    def __init__(self):
        self.values: dict[str, str] = {}

    def get(self, key: str) -> str | None:
        return self.values.get(key)

    def set(self, key: str, value: str) -> None:
        self.values[key] = value


class Counting:
    """make_solver that counts the solvers it builds (real ones, from the registry)."""

    def __init__(self):
        self.made = []

    def __call__(self, name, config):
        self.made.append(name)
        return create_solver(name, config)


def test_the_fastest_measured_backend_is_chosen_and_remembered():
    store, make = MemoryStore(), Counting()
    choice = choose_backend(CFG, make, store, renderer="llvmpipe (LLVM 15.0.7, 256 bits)",
                            candidates=("numpy", "cpu"), seconds=0.05)
    assert not choice.remembered and sorted(make.made) == ["cpu", "numpy"]
    rates = {t.backend: t.steps_per_s for t in choice.timings}
    assert all(r > 0 for r in rates.values())
    assert choice.backend == max(rates, key=rates.get)
    assert store.get(choice.key) == choice.backend
    line = choice.describe(64, 32)
    assert "\n" not in line and f"backend {choice.backend}" in line and "steps/s" in line
    # remembered: nothing is built or timed again, unless asked to measure again
    again = choose_backend(CFG, make, store, renderer="llvmpipe (LLVM 15.0.7, 256 bits)",
                           candidates=("numpy", "cpu"), seconds=0.05)
    assert again.remembered and again.backend == choice.backend and len(make.made) == 2
    choose_backend(CFG, make, store, renderer="llvmpipe (LLVM 15.0.7, 256 bits)",
                   candidates=("numpy", "cpu"), seconds=0.05, remeasure=True)
    assert len(make.made) == 4


def test_another_renderer_or_grid_is_measured_afresh():
    store = MemoryStore()
    store.set(choice_key("GPU A", 64, 32), "numpy")
    make = Counting()
    assert choose_backend(CFG, make, store, renderer="GPU A", candidates=("numpy", "cpu"), seconds=0.02).remembered
    assert not choose_backend(CFG, make, store, renderer="GPU B", candidates=("numpy", "cpu"), seconds=0.02).remembered
    other = FlowConfig(nx=48, ny=32, nu=0.02, dtype="float32", inflow_ramp_steps=20)
    assert not choose_backend(other, make, store, renderer="GPU A", candidates=("numpy", "cpu"), seconds=0.02).remembered
    # a remembered backend that is not among the candidates is not used
    assert not choose_backend(CFG, make, store, renderer="GPU A", candidates=("cpu",), seconds=0.02).remembered


def test_keys_are_one_settings_group_per_renderer():
    key = choice_key("llvmpipe (LLVM 15.0.7, 256 bits)", 512, 256)
    assert key.startswith("backend/") and key.endswith("/512x256") and key.count("/") == 2
    assert " " not in key and "(" not in key
    assert choice_key("NVIDIA GeForce/PCIe/SSE2", 1, 2) != choice_key("NVIDIA GeForce", 1, 2)


def test_a_backend_that_cannot_start_is_reported_not_chosen():
    def make(name, config):
        if name == "numpy":
            raise RuntimeError("no such thing here\nsecond line")
        return create_solver(name, config)

    choice = choose_backend(CFG, make, None, candidates=("numpy", "cpu"), seconds=0.02)
    assert choice.backend == "cpu"
    failed = next(t for t in choice.timings if t.backend == "numpy")
    assert failed.error == "no such thing here" and "unavailable" in failed.describe()
    with pytest.raises(RuntimeError, match="no solver backend can run here"):
        choose_backend(CFG, make, None, candidates=("numpy",), seconds=0.02)


def test_timing_moves_the_body_as_the_window_does():
    """The timed solver has the default cylinder and the momentum exchange, and is closed."""
    built = []

    def make(name, config):
        built.append(create_solver(name, config))
        return built[-1]

    t = time_backend("numpy", CFG, make, seconds=0.02)
    s = built[0]
    assert t.error is None and t.steps_per_s > 0 and s.body is not None
    assert "momentum_exchange" in s.forces() and s.time >= 13
    assert t.mlups == pytest.approx(t.steps_per_s * 64 * 32 / 1e6)


def test_json_store_survives_a_missing_or_broken_file(tmp_path):
    path = tmp_path / "sub" / "choice.json"
    store = JsonFileStore(path)
    assert store.get("k") is None
    store.set("k", "cpu")
    assert JsonFileStore(path).get("k") == "cpu" and json.loads(path.read_text()) == {"k": "cpu"}
    path.write_text("{not json")
    assert store.get("k") is None
    store.set("j", "gl")
    assert json.loads(path.read_text()) == {"j": "gl"}


SCENE = """
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
steps = 20
move = "stop"

[output]
forces = ["momentum_exchange"]
interval = 10
"""


def test_run_backend_auto_prints_its_choice_in_one_line(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    scene = tmp_path / "scene.toml"
    scene.write_text(SCENE)
    out = tmp_path / "forces.csv"
    assert cli_main(["run", str(scene), "--backend", "auto", "--out", str(out)]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    chosen = [line for line in lines if line.startswith("feelflow: backend ")]
    assert len(chosen) == 1 and "the fastest of" in chosen[0]
    backend = chosen[0].split()[2].rstrip(":")
    assert f"steps on {backend} " in lines[-1] and out.exists()
    stored = json.loads((tmp_path / "cache" / "feelflow" / "backend-choice.json").read_text())
    assert list(stored.values()) == [backend] and list(stored)[0].endswith("/64x32")
    # the second run, without --backend (the default: auto), uses the remembered choice
    assert cli_main(["run", str(scene), "--out", str(out), "--force"]) == 0
    assert f"feelflow: backend {backend} (remembered" in capsys.readouterr().out
