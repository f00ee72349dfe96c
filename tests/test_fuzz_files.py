"""Fuzz: seeded mutations of every example scene (scenes/, scenes/presets/), of every kind of
shape file and of recorded session files, each fed to the command that reads it (in-process).

Each case keeps the property of tests/fuzz_cases.py: exit 0 with finite output, or one error line
and no traceback, within the time bound; no file outside the scratch folder changes. The default
run has a few hundred cases; `pytest -m fuzz tests/test_fuzz_files.py` runs thousands more.
"""
from __future__ import annotations

import io
import json
import os
import pathlib
import random
import time
import tomllib
import zipfile

import numpy as np
import pytest

from fuzz_cases import (BLOCK, ROOT, TIME_LIMIT, CaseTimeout, check_cli, mutate_bytes, mutate_doc, repo_snapshot,
                        seeds, time_limit, to_toml)

SCENES = sorted((ROOT / "scenes").glob("*.toml")) + sorted((ROOT / "scenes" / "presets").glob("*.toml"))
SHAPES = [
    {"kind": "cylinder", "diameter": 20.0, "x": 60.0, "y": 40.0, "angle": 0.0},
    {"kind": "plate", "length": 24.0, "thickness": 3.0, "x": 60.0, "y": 40.0, "angle": 0.3},
    {"kind": "wedge", "length": 20.0, "apex_angle": 0.6, "pointing": "upstream", "x": 60.0, "y": 40.0, "angle": 0.0},
    {"kind": "half_airfoil", "chord": 40.0, "thickness": 6.0, "x": 60.0, "y": 40.0, "angle": 0.1},
    {"kind": "polygon", "vertices": [[-10.0, -5.0], [12.0, -4.0], [8.0, 7.0], [-6.0, 9.0]], "x": 60.0, "y": 40.0,
     "angle": 0.0},
]


@pytest.fixture(scope="module", autouse=True)
def repo_unchanged():
    before = repo_snapshot()
    yield
    after = repo_snapshot()
    changed = sorted(p for p in set(before) | set(after) if before.get(p) != after.get(p))
    assert not changed, changed[:10]


@pytest.fixture
def scratch(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_every_example_scene_is_in_the_fuzz():
    assert len(SCENES) >= 15 and all(p.stat().st_size < 64 << 10 for p in SCENES)


# --- scenes ---------------------------------------------------------------------------------------

def scene_case(seed: int, folder: pathlib.Path):
    rng = random.Random(seed)
    path = rng.choice(SCENES)
    text = path.read_bytes()
    if rng.random() < 0.75:
        doc = mutate_doc(rng, tomllib.loads(text.decode()), rng.randint(1, 3))
        data = to_toml(doc).encode()
    else:
        data = mutate_bytes(rng, text)
    case = folder / f"{path.stem}.toml"
    case.write_bytes(data)
    return path, ["run", case.name, "--out", "o.csv", "--steps", rng.choice([1, 3, 7]), "--backend", "numpy",
                  "--force"]


@pytest.mark.parametrize("first", seeds(1, 4, 40))
def test_fuzz_scenes(first, scratch, capsys):
    codes = []
    for seed in range(first, first + BLOCK):
        folder = scratch / str(seed)
        folder.mkdir()
        source, argv = scene_case(seed, folder)
        os.chdir(folder)
        codes.append(check_cli(argv, capsys, folder, what=f"seed {seed} ({source.name})"))
    assert any(c == 2 for c in codes)   # the mutations do reach the checks


# --- shapes ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("first", seeds(2, 4, 40))
def test_fuzz_shapes(first, scratch):
    from feelflow.shapes.base import Shape, ShapeError
    from feelflow.app.shape_files import load_shape

    for seed in range(first, first + BLOCK):
        rng = random.Random(seed)
        base = {"format": "feelflow-shape", "version": 1, "shape": rng.choice(SHAPES)}
        if rng.random() < 0.75:
            data = json.dumps(mutate_doc(rng, base, rng.randint(1, 3))).encode()
        else:
            data = mutate_bytes(rng, json.dumps(base, indent=1).encode())
        path = scratch / f"{seed}.json"
        path.write_bytes(data)
        t0 = time.perf_counter()
        try:
            with time_limit(TIME_LIMIT):
                shape = load_shape(path)
                shape.validate(400, 160)
        except ShapeError as exc:
            assert "\n" not in str(exc), (seed, str(exc))
        except CaseTimeout:
            pytest.fail(f"seed {seed}: took more than {TIME_LIMIT} s")
        else:
            assert isinstance(shape, Shape)
            assert np.isfinite(shape.bounding_box()).all(), seed
        assert time.perf_counter() - t0 < TIME_LIMIT


# --- sessions -------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def sessions(tmp_path_factory):
    """Two recorded sessions: a scripted run (`feelflow run --record`) and a driven one with
    parameter changes, reset and a shape edit (tests/session_scenes.py)."""
    from feelflow.app.cli.main import main as cli_main
    from feelflow.app.sessions import SessionRecorder, SessionSolver
    from feelflow.solver.backend import create_solver

    from session_scenes import MODELS, drive_moving_cylinder, small_config, start_body
    from test_file_policy import SCENE

    folder = tmp_path_factory.mktemp("sessions")
    (folder / "s.toml").write_text(SCENE)
    assert cli_main(["run", str(folder / "s.toml"), "--out", str(folder / "f.csv"),
                     "--record", str(folder / "a.ffsession")]) == 0
    cfg = small_config()
    rec = SessionRecorder(cfg, start_body(), MODELS)
    drive_moving_cylinder(SessionSolver(create_solver("numpy", cfg), rec), steps=14)
    rec.save(folder / "b.ffsession")
    out = []
    for name in ("a.ffsession", "b.ffsession"):
        with zipfile.ZipFile(folder / name) as zf:
            out.append({n: zf.read(n) for n in zf.namelist()})
    return out, [(folder / n).read_bytes() for n in ("a.ffsession", "b.ffsession")]


def _npz_mutated(rng, raw: bytes) -> bytes:
    with np.load(io.BytesIO(raw)) as z:
        arrays = {k: z[k] for k in z.files}
    key = rng.choice(sorted(arrays))
    a = arrays[key]
    op = rng.randrange(7)
    if op == 0:
        arrays[key] = a.astype(rng.choice([np.float32, np.int32, np.float64, np.int64, np.bool_]))
    elif op == 1 and a.size:
        a = a.copy()
        a.flat[rng.randrange(a.size)] = rng.choice([np.nan, np.inf, -1, 10 ** 9, 1e30, 0]) \
            if a.dtype.kind == "f" else rng.choice([-1, 0, 10 ** 9, 2 ** 62, 7])
        arrays[key] = a
    elif op == 2:
        arrays[key] = a[:max(0, len(a) - rng.randint(1, 3))] if a.ndim else a
    elif op == 3:
        arrays[key] = np.concatenate([a, a[-1:]]) if a.ndim and len(a) else a
    elif op == 4:
        arrays[key] = a.reshape(-1)
    elif op == 5:
        del arrays[key]
    else:
        arrays[rng.choice(["extra", key])] = np.array(["text"])
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def session_case(rng, sessions) -> bytes:
    members_list, raw_list = sessions
    k = rng.randrange(len(raw_list))
    members = dict(members_list[k])
    op = rng.random()
    if op < 0.2:
        return mutate_bytes(rng, raw_list[k])
    if op < 0.5:
        members["manifest.json"] = json.dumps(mutate_doc(rng, json.loads(members["manifest.json"]),
                                                         rng.randint(1, 2))).encode()
    elif op < 0.65:
        members["parameters.json"] = json.dumps(mutate_doc(rng, json.loads(members["parameters.json"]),
                                                           rng.randint(1, 2))).encode()
    elif op < 0.9:
        name = rng.choice([n for n in members if n.endswith(".npz")])
        members[name] = _npz_mutated(rng, members[name])
    else:
        name = rng.choice(sorted(members))
        members[name] = mutate_bytes(rng, members[name]) if rng.random() < 0.5 else b""
        if rng.random() < 0.3:
            del members[name]
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=rng.choice([zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED])) as zf:
        for n, b in members.items():
            zf.writestr(n, b)
    return buf.getvalue()


@pytest.mark.parametrize("first", seeds(3, 4, 40))
def test_fuzz_sessions(first, scratch, capsys, sessions):
    for seed in range(first, first + BLOCK):
        rng = random.Random(seed)
        folder = scratch / str(seed)
        folder.mkdir()
        os.chdir(folder)
        pathlib.Path("s.ffsession").write_bytes(session_case(rng, sessions))
        argv = rng.choice([["session", "info", "s.ffsession"],
                           ["session", "info", "s.ffsession", "--json"],
                           ["session", "replay", "s.ffsession", "--out", "r.csv", "--backend", "numpy"],
                           ["session", "export", "s.ffsession", "--csv", "c.csv", "--manifest", "m.json"]])
        check_cli(argv, capsys, folder, allow_nan=True, what=f"seed {seed}")
