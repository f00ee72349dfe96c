"""Fuzz: seeded mutations of every command's arguments (run, session info|replay|export, validate,
bench, report, devices, gui), run in-process with the property of tests/fuzz_cases.py.

The arguments are mutated: a value replaced by a hostile one (empty, negative, NaN, a number of
thousands of digits, a device, a pipe, a folder, the command's own input, a missing folder, a
name too long), a token dropped, doubled or swapped, an unknown option added. The measuring parts
of `validate` and `bench` (seconds to minutes each) are replaced by instant stand-ins once their
arguments have been checked: what is fuzzed here is the command line, not the physics. `gui` runs
without a display, so it must refuse or reach the display check without opening a window.
"""
from __future__ import annotations

import os
import random

import pytest

from fuzz_cases import BLOCK, ROOT, check_cli, repo_snapshot, seeds
from test_file_policy import SCENE

HOSTILE_ARGS = ["", "-1", "0", "1", "3", "nan", "inf", "-inf", "1e400", "9" * 5000, "9" * 30, "x" * 300,
                "/dev/null", "pipe", ".", "..", "missing/dir/x.csv", "scene.toml", "good.ffsession", "\u0663",
                "1_0", "--", "-x", "--bogus", "numpy", "momentum_exchange", "0.5", "1e-12", "out.csv",
                "a,b,,", "plate", "lessons", "scenes", "seed", "solver", "haptics", "accuracy", "\x00"]


def templates(scenes_dir: str):
    return [
        ["run", "scene.toml", "--out", "o.csv", "--steps", "6", "--backend", "numpy"],
        ["run", "scene.toml", "--out", "o.csv", "--steps", "4", "--record", "r.ffsession"],
        ["session", "info", "good.ffsession"],
        ["session", "info", "good.ffsession", "--json"],
        ["session", "replay", "good.ffsession", "--out", "r.csv", "--check", "--tolerance", "1e-9"],
        ["session", "export", "good.ffsession", "--csv", "c.csv", "--manifest", "m.json"],
        ["validate", "--case", "poiseuille", "--quick", "--resolution", "8", "--json", "v.json"],
        ["bench", "haptics", "--seconds", "1", "--json", "b.json"],
        ["bench", "accuracy", "--quick", "--backend", "numpy", "--axis", "tau", "--json", "b.json"],
        ["report", "scenes", "--quick", "--only", "plate", "--scenes", scenes_dir, "--json", "rep.json"],
        ["devices", "--json", "--no-sim"],
        ["gui", "good.ffsession", "--fresh"],
    ]


def mutate_argv(rng: random.Random, argv: list[str]) -> list[str]:
    argv = list(argv)
    for _ in range(rng.choice([1, 1, 2, 3])):
        op = rng.random()
        i = rng.randrange(1, len(argv)) if len(argv) > 1 else 0
        if op < 0.5:
            argv[i] = rng.choice(HOSTILE_ARGS)
        elif op < 0.62 and len(argv) > 2:
            del argv[i]
        elif op < 0.72:
            argv[i:i] = argv[i:i + 2]
        elif op < 0.8 and len(argv) > 2:
            j = rng.randrange(1, len(argv))
            argv[i], argv[j] = argv[j], argv[i]
        elif op < 0.9:
            argv.append("--force")
        else:
            argv.insert(i, rng.choice(["--bogus", "--out", "--json", "--steps", "--backend"]))
    return argv


@pytest.fixture(scope="module", autouse=True)
def repo_unchanged():
    before = repo_snapshot()
    yield
    after = repo_snapshot()
    changed = sorted(p for p in set(before) | set(after) if before.get(p) != after.get(p))
    assert not changed, changed[:10]


@pytest.fixture(scope="module")
def good_session(tmp_path_factory):
    from feelflow.app.cli.main import main as cli_main

    folder = tmp_path_factory.mktemp("cli")
    (folder / "scene.toml").write_text(SCENE)
    assert cli_main(["run", str(folder / "scene.toml"), "--out", str(folder / "f.csv"),
                     "--record", str(folder / "good.ffsession")]) == 0
    return (folder / "good.ffsession").read_bytes()


@pytest.fixture
def stand_ins(monkeypatch):
    """Instant stand-ins for the measuring parts of validate and bench (their arguments are
    checked by the real code first)."""
    import feelflow.app.cli.commands.validate as validate
    from feelflow.app.files import save_json
    from feelflow.solver.validation.base import CaseResult

    def run_case(name, factory, resolution, quick, backend, refine=False):
        return CaseResult(name, backend, resolution or 8, quantities={"value": 1.0})
    monkeypatch.setattr(validate, "run_case", run_case)

    def measured(args):
        if getattr(args, "json", None):
            save_json(args.json, {"measured": 1.0})
        return 0
    import feelflow.app.bench.accuracy as accuracy
    import feelflow.app.bench.haptic_loop as haptic_loop
    import feelflow.app.bench.solver_speed as solver_speed
    for module in (accuracy, haptic_loop, solver_speed):
        monkeypatch.setattr(module, "main", measured)
    for var in ("DISPLAY", "WAYLAND_DISPLAY"):
        monkeypatch.delenv(var, raising=False)


@pytest.mark.parametrize("first", seeds(4, 4, 40))
def test_fuzz_command_lines(first, tmp_path, monkeypatch, capsys, good_session, stand_ins):
    codes = []
    for seed in range(first, first + BLOCK):
        rng = random.Random(seed)
        folder = tmp_path / str(seed)
        folder.mkdir()
        monkeypatch.chdir(folder)
        (folder / "scene.toml").write_text(SCENE)
        (folder / "good.ffsession").write_bytes(good_session)
        os.mkfifo(folder / "pipe")
        argv = mutate_argv(rng, rng.choice(templates(str(ROOT / "scenes"))))
        inputs = {p: p.read_bytes() for p in (folder / "scene.toml", folder / "good.ffsession")}
        codes.append(check_cli(argv, capsys, folder, allow_nan=True, what=f"seed {seed}"))
        for p, data in inputs.items():   # an input of the command is never changed
            assert p.read_bytes() == data, (seed, argv, p.name)
        assert (folder / "pipe").is_fifo()
    assert any(c == 2 for c in codes), codes   # the mutations do reach the checks
