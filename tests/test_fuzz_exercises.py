"""Fuzz: seeded mutations of exercise files, students' attempts files and class folders, each
read the way FeelFlow reads it (in-process): `load_exercise` and `feelflow exercise check`, the
window's `Attempts`, and `feelflow exercise score` on a class folder full of odd entries.

Each case keeps the property of tests/fuzz_cases.py: a valid result, or one error line (exit 2 on
the command line) and no traceback, within the time bound; no file outside the case's output
changes (the class folder is hashed before and after; the repository too, per module). The
default run has 60 cases; `pytest -m fuzz tests/test_fuzz_exercises.py` runs 1000 more exercise
files, 200 more attempts files and 200 more class folders.
"""
from __future__ import annotations

import copy
import hashlib
import json
import os
import pathlib
import random
import shutil
import time
import tomllib

import pytest

from fuzz_cases import (ROOT, TIME_LIMIT, CaseTimeout, check_cli, mutate_bytes, mutate_doc, repo_snapshot,
                        time_limit, to_toml)

TINY = ROOT / "tests" / "data" / "exercises" / "tiny.toml"
SHIPPED = sorted((ROOT / "exercises").glob("*.toml"))

#: file names a careless or hostile exercise or class folder names
HOSTILE_NAMES = ["../../../../../../etc/passwd", "/etc/passwd", "/dev/zero", "/proc/self/mem", "shapes",
                 "shapes/../../outside.json", "shapes/missing.json", "x" * 300, "y" * 5000, "", " ",
                 "shapes/start.json\x00", "shapes/ref.json/x", "loop.json", "fifo.json", "zero.json",
                 "ex.toml", ".", "..", "~/x.json"]
#: numbers for the exercise's numeric keys (the bounds: docs/reference/exercise-format.md)
HOSTILE_NUMBERS = [10 ** 18, 2 ** 63 + 2, 10 ** 399, "@5000 digits@", -1, 0, 1, 99, 2048, 2049, 10 ** 9, 1e-300,
                   1e300, 4.5, -0.0, "1500", True]


def seeds(prefix: int, block: int, default_blocks: int, fuzz_blocks: int):
    """pytest params: first seeds of `default_blocks` blocks of `block` cases by default, and of
    `fuzz_blocks` more under -m fuzz."""
    params = [pytest.param((prefix * 100_000 + b * block, block), id=f"block{b}") for b in range(default_blocks)]
    params += [pytest.param((prefix * 100_000 + b * block, block), id=f"block{b}", marks=pytest.mark.fuzz)
               for b in range(default_blocks, default_blocks + fuzz_blocks)]
    return params


def digest(folder: pathlib.Path, skip=()) -> dict:
    """Every entry of `folder` (recursively, links not followed): its kind and, for a regular
    file, its content hash."""
    out = {}
    for dirpath, dirnames, names in os.walk(folder):
        for n in names + dirnames:
            p = pathlib.Path(dirpath) / n
            if p.name in skip:
                continue
            st = os.lstat(p)
            if os.path.isfile(p) and not os.path.islink(p):
                out[str(p)] = hashlib.sha256(p.read_bytes()).hexdigest()
            else:
                out[str(p)] = (st.st_mode, os.readlink(p) if os.path.islink(p) else None)
    return out


@pytest.fixture(scope="module", autouse=True)
def repo_unchanged():
    before = repo_snapshot()
    yield
    after = repo_snapshot()
    changed = sorted(p for p in set(before) | set(after) if before.get(p) != after.get(p))
    assert not changed, changed[:10]


@pytest.fixture
def block_folder(tmp_path, monkeypatch):
    """A scratch folder with the tiny exercise's shapes, an outside file and odd entries the
    hostile names point at."""
    shutil.copytree(TINY.parent / "shapes", tmp_path / "shapes")
    (tmp_path / "outside.json").write_text((TINY.parent / "shapes" / "start.json").read_text())
    os.mkfifo(tmp_path / "fifo.json")
    (tmp_path / "zero.json").symlink_to("/dev/zero")
    (tmp_path / "loop.json").symlink_to(tmp_path / "loop.json")
    monkeypatch.chdir(tmp_path)
    return tmp_path


# --- exercise files -------------------------------------------------------------------------------
def exercise_doc(rng) -> dict:
    source = TINY if rng.random() < 0.7 else rng.choice(SHIPPED)
    doc = tomllib.loads(source.read_text())
    if source != TINY:   # the shipped exercises name shapes/...: ours has the tiny exercise's
        doc["edit"]["start"] = "shapes/start.json"
        for ref in doc.get("reference", []):
            ref["file"] = "shapes/ref.json"
        doc.get("check", {})["shapes"] = ["shapes/cylinder.json"]
    return doc


def _references(doc):
    """(container, key) of every file name the exercise holds."""
    out = [(doc.get("edit", {}), "start")] + [(r, "file") for r in doc.get("reference", []) if isinstance(r, dict)]
    shapes = doc.get("check", {}).get("shapes") if isinstance(doc.get("check"), dict) else None
    if isinstance(shapes, list):
        out += [(shapes, i) for i in range(len(shapes))]
    return [(c, k) for c, k in out if isinstance(c, (dict, list))]


def exercise_case(rng) -> bytes:
    doc = exercise_doc(rng)
    op = rng.random()
    if op < 0.2:
        return mutate_bytes(rng, to_toml(doc).encode())
    if op < 0.45:   # a file name
        refs = _references(doc)
        if refs:
            container, key = rng.choice(refs)
            container[key] = rng.choice(HOSTILE_NAMES)
    elif op < 0.7:   # a number of the scene, the constraints or a reference
        table = rng.choice(["scene", "constraints", "objective", "reference"])
        target = doc.get(table)
        if isinstance(target, list) and target:
            target = rng.choice(target)
        if isinstance(target, dict) and target:
            target[rng.choice(sorted(target))] = copy.deepcopy(rng.choice(HOSTILE_NUMBERS))
    elif op < 0.8:   # deep or long
        kind = rng.randrange(3)
        if kind == 0:
            text = to_toml(doc) + "deep = " + "[" * rng.choice([17, 100, 10 ** 5]) + "]" * 10 + "\n"
        elif kind == 1:
            n = rng.choice([17, 3000])
            text = to_toml(doc) + "deep = " + "{a = " * n + "1" + "}" * n + "\n"
        else:
            text = to_toml(doc).replace("[scene]", "[scene]\n" + "k" * rng.choice([100, 100_000]) + " = 1", 1)
        return text.encode()
    else:
        doc = mutate_doc(rng, doc, rng.randint(1, 3))
    # an integer too long for Python's str() is written into the text directly
    return to_toml(doc).replace('"@5000 digits@"', "9" * 5000).encode()


@pytest.mark.parametrize("first", seeds(5, 25, 1, 40))
def test_fuzz_exercise_files(first, block_folder, capsys):
    from feelflow.app.errors import UserError
    from feelflow.app.exercises.format import Exercise, load_exercise

    start, block = first
    before = digest(block_folder)
    refused = 0
    for seed in range(start, start + block):
        rng = random.Random(seed)
        path = block_folder / "ex.toml"
        path.write_bytes(exercise_case(rng))
        t0 = time.perf_counter()
        try:
            with time_limit(TIME_LIMIT):
                exercise = load_exercise(path)
        except UserError as exc:
            text = str(exc)
            assert "\n" not in text and len(text) < 600, (seed, text[:300])
            refused += 1
            # the command line says the same in one line, exit 2
            assert check_cli(["exercise", "check", path.name], capsys, block_folder / "shapes",
                             what=f"seed {seed}") == 2
        except CaseTimeout:
            pytest.fail(f"seed {seed}: took more than {TIME_LIMIT} s")
        except Exception as exc:
            pytest.fail(f"seed {seed}: {type(exc).__name__}: {str(exc)[:300]}")
        else:
            assert isinstance(exercise, Exercise)
            for p in exercise.input_files():   # every file it names lies in its folder
                assert os.path.realpath(p).startswith(str(block_folder)), (seed, p)
        assert time.perf_counter() - t0 < TIME_LIMIT
        path.unlink()
    assert refused, "the mutations do reach the checks"
    assert digest(block_folder) == before


# --- attempts files -------------------------------------------------------------------------------
def attempts_doc() -> dict:
    shape = json.loads((TINY.parent / "shapes" / "ref.json").read_text())["shape"]
    attempt = {"number": 1, "time": "2026-01-01T10:00:00+00:00", "shape": shape, "status": "scored",
               "score": 2.81, "cd": 2.81, "cl": 0.001, "steps": 1500, "seconds": 1.2, "reason": ""}
    second = dict(attempt, number=2, status="not settled", score=None, cd=None, cl=None, reason="drifts")
    return {"format": "feelflow-attempts", "version": 1, "exercise": "Tiny test exercise",
            "attempts": [attempt, second]}


@pytest.mark.parametrize("first", seeds(6, 25, 1, 8))
def test_fuzz_attempts_files(first, tmp_path):
    from feelflow.app.errors import UserError
    from feelflow.app.exercises.attempts import Attempts
    from feelflow.app.exercises.format import load_exercise

    exercise = load_exercise(TINY)
    start, block = first
    for seed in range(start, start + block):
        rng = random.Random(seed)
        folder = tmp_path / str(seed)
        folder.mkdir()
        path = folder / "tiny.attempts.json"
        if rng.random() < 0.75:
            path.write_text(json.dumps(mutate_doc(rng, attempts_doc(), rng.randint(1, 3))))
        else:
            path.write_bytes(mutate_bytes(rng, json.dumps(attempts_doc(), indent=1).encode()))
        data = path.read_bytes()
        try:
            with time_limit(TIME_LIMIT):
                attempts = Attempts(exercise, folder)
                best = attempts.best()
                shapes = [a.load_shape() for a in attempts.items]
        except UserError as exc:
            assert "\n" not in str(exc) and len(str(exc)) < 600, (seed, str(exc)[:300])
        except CaseTimeout:
            pytest.fail(f"seed {seed}: took more than {TIME_LIMIT} s")
        except Exception as exc:
            pytest.fail(f"seed {seed}: {type(exc).__name__}: {str(exc)[:300]}")
        else:
            assert len(shapes) == len(attempts.items)
            assert best is None or best.status == "scored"
        assert path.read_bytes() == data   # reading never changes the file


# --- class folders --------------------------------------------------------------------------------
FAST = {"steps = 1500": "steps = 100", "average_steps = 500": "average_steps = 50"}


def class_entry(rng, folder: pathlib.Path, k: int, exercise: pathlib.Path) -> None:
    """One odd (or good) entry of a class folder."""
    ref = (TINY.parent / "shapes" / "ref.json").read_text()
    kind = rng.choice(["good", "mutated", "bytes", "fifo", "devzero", "loop", "dangling", "exercise", "dir",
                       "long", "empty", "deep", "text", "outside"])
    name = folder / f"{k}-{kind}.json"
    if kind == "good":
        name.write_text(ref)
    elif kind == "mutated":
        name.write_text(json.dumps(mutate_doc(rng, json.loads(ref), rng.randint(1, 3))))
    elif kind == "bytes":
        name.write_bytes(mutate_bytes(rng, ref.encode()))
    elif kind == "fifo":
        os.mkfifo(name)
    elif kind == "devzero":
        name.symlink_to("/dev/zero")
    elif kind == "loop":
        name.symlink_to(name)
    elif kind == "dangling":
        name.symlink_to(folder / "nowhere" / "x.json")
    elif kind == "exercise":
        name.symlink_to(exercise)
    elif kind == "dir":
        name.mkdir()
    elif kind == "long":
        (folder / (f"{k}-" + "n" * 240 + ".json")).write_text(ref)
    elif kind == "empty":
        name.write_bytes(b"")
    elif kind == "deep":
        name.write_text('{"format": "feelflow-shape", "version": 1, "shape": ' + "[" * 10 ** 4 + "]" * 10 ** 4 + "}")
    elif kind == "text":
        (folder / f"{k}-notes.txt").write_text("not a shape")
    else:
        name.symlink_to(TINY.parent / "shapes" / "ref.json")


@pytest.mark.parametrize("first", seeds(7, 10, 1, 20))
def test_fuzz_class_folders(first, tmp_path, capsys, monkeypatch):
    start, block = first
    exercise = tmp_path / "ex" / "tiny.toml"
    shutil.copytree(TINY.parent, exercise.parent)
    text = exercise.read_text()
    for old, new in FAST.items():
        text = text.replace(old, new)
    exercise.write_text(text)
    for seed in range(start, start + block):
        rng = random.Random(seed)
        folder = tmp_path / str(seed) / "class"
        folder.mkdir(parents=True)
        for k in range(rng.randint(0, 6)):
            class_entry(rng, folder, k, exercise)
        out = tmp_path / str(seed) / "scores.csv"
        target = rng.random()
        if target < 0.1 and any(folder.iterdir()):   # an output that is one of the inputs
            out = rng.choice(sorted(folder.iterdir()))
        elif target < 0.2:
            out.write_text("earlier results\n")      # an existing file, without --force
        quiet = tmp_path / str(seed) / "quiet"
        quiet.mkdir()
        before = digest(tmp_path / str(seed), skip={"scores.csv"})
        before_out = out.exists()
        rc = check_cli(["exercise", "score", exercise, folder, "--out", out, "--workers", "1", "--backend", "numpy"], capsys, quiet,
                       what=f"seed {seed}")
        assert digest(tmp_path / str(seed), skip={"scores.csv"}) == before, seed
        if rc == 0:
            import csv

            rows = list(csv.DictReader(out.open()))
            entries = [p for p in folder.iterdir() if p.name.lower().endswith(".json")]
            assert len(rows) == len(entries), seed
            for row in rows:
                if row["status"] == "scored":
                    assert float(row["score"]) == float(row["score"]) and abs(float(row["score"])) < 1e6
                else:
                    assert row["score"] == "" and "\n" not in row["reason"] and len(row["reason"]) < 300
        elif before_out and target >= 0.1:
            assert out.read_text() == "earlier results\n", seed
