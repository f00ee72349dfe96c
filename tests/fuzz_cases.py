"""Seeded mutations for the fuzz suites (tests/test_fuzz_*.py) and the property every case keeps.

The property: the command line, run in-process, either exits 0 with finite output, or exits
non-zero with exactly one error line on stderr (`feelflow: ...`; one-line `feelflow: warning:`
lines may come before it) and no traceback; within a time bound; and nothing outside the scratch
folder changes (checked per module by `repo_unchanged`).
"""
from __future__ import annotations

import contextlib
import copy
import csv
import json
import math
import os
import pathlib
import random
import signal
import traceback
import warnings

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
#: seconds one case may take (a hang or a runaway run fails the case)
TIME_LIMIT = 20.0
#: cases per test function (one seed each), and test functions in the default run / under -m fuzz
BLOCK = 25
HUGE_INT = 10 ** 30

#: values a hostile or careless user puts where something else belongs
HOSTILE = ["32", "", "1e3", True, False, 0, -1, 1, 2, 7, 0.5, -0.0, 1e-12, 1e300, -1e300, math.nan, math.inf,
           -math.inf, HUGE_INT, 2 ** 53 + 1, 10 ** 5, [], [1], [1, 2], [[1, 2], [3, 4], [5]], [True, False],
           {"a": 1}, {}, "x" * 300, "cylinder", "polygon", "trt", "periodic", "tunnel", "no_slip", "numpy",
           "momentum_exchange", ["momentum_exchange"], [0.05, 0.0], [1e-5, 0.0], [0.5, 0.0], 4096, 8192, 3.3]


class CaseTimeout(Exception):
    pass


@contextlib.contextmanager
def time_limit(seconds: float):
    def expire(signum, frame):
        raise CaseTimeout(f"more than {seconds:g} s")
    old = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


# --- mutations ------------------------------------------------------------------------------------

def _paths(doc, prefix=()):
    """Every (container, key) in a nested dict/list document."""
    out = []
    if isinstance(doc, dict):
        items = list(doc.items())
    elif isinstance(doc, list):
        items = list(enumerate(doc))
    else:
        return out
    for k, v in items:
        out.append((doc, k))
        out.extend(_paths(v))
    return out


def mutate_doc(rng: random.Random, doc, n: int = 1):
    """A deep copy of `doc` with `n` mutations: a value replaced by a hostile one, a key removed
    or added, a list item doubled or dropped, a number scaled."""
    doc = copy.deepcopy(doc)
    for _ in range(n):
        paths = _paths(doc)
        if not paths:
            return doc
        container, key = rng.choice(paths)
        op = rng.random()
        value = container[key]
        if op < 0.45:
            container[key] = copy.deepcopy(rng.choice(HOSTILE))
        elif op < 0.6 and isinstance(value, (int, float)) and not isinstance(value, bool):
            container[key] = value * rng.choice([-1, 0, 2, 10, 1000, 1e-3, 1e6])
            if isinstance(value, int) and rng.random() < 0.5:
                container[key] = int(container[key]) if math.isfinite(container[key]) else container[key]
        elif op < 0.72:
            if isinstance(container, dict):
                del container[key]
            else:
                container.pop(key)
        elif op < 0.82 and isinstance(container, dict):
            container[rng.choice(["extra", "nx", "steps", "kind", "backend", "x", "force"])] = rng.choice(HOSTILE)
        elif op < 0.9 and isinstance(value, list) and value:
            value.append(copy.deepcopy(rng.choice(value)))
        else:
            container[key] = [copy.deepcopy(value)]
    return doc


def mutate_bytes(rng: random.Random, data: bytes) -> bytes:
    """Bit flips, truncation, a chunk doubled or overwritten, junk inserted."""
    data = bytearray(data)
    op = rng.randrange(5)
    if not data:
        return bytes(rng.randrange(256) for _ in range(8))
    if op == 0:
        for _ in range(rng.randint(1, 8)):
            i = rng.randrange(len(data))
            data[i] ^= 1 << rng.randrange(8)
    elif op == 1:
        data = data[:rng.randrange(len(data))]
    elif op == 2:
        i = rng.randrange(len(data))
        j = min(len(data), i + rng.randint(1, 64))
        data[i:i] = data[i:j] * rng.randint(1, 4)
    elif op == 3:
        i = rng.randrange(len(data))
        data[i:i + 4] = rng.choice([b"[[[[", b"\x00\xff\x00\xff", b"9999", b'"""', b"{{{{", b"\n[x]"])
    else:
        i = rng.randrange(len(data))
        data[i:i] = bytes(rng.randrange(256) for _ in range(rng.randint(1, 16)))
    return bytes(data)


def _toml_key(k) -> str:
    k = str(k)
    return k if k and all(c.isalnum() or c in "_-" for c in k) else json.dumps(k)


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{_toml_key(k)} = {_toml_value(x)}" for k, x in v.items()) + "}"
    return json.dumps(str(v))


def to_toml(doc: dict) -> str:
    """A small TOML writer for scene documents: scalars, tables, arrays of tables."""
    lines = []

    def table(d, name):
        scalars = {k: v for k, v in d.items() if not isinstance(v, dict)
                   and not (isinstance(v, list) and v and all(isinstance(x, dict) for x in v))}
        if name:
            lines.append(f"[{name}]")
        lines.extend(f"{_toml_key(k)} = {_toml_value(v)}" for k, v in scalars.items())
        for k, v in d.items():
            if k in scalars:
                continue
            sub = f"{name}.{_toml_key(k)}" if name else _toml_key(k)
            if isinstance(v, dict):
                table(v, sub)
            else:
                for item in v:
                    lines.append(f"[[{sub}]]")
                    lines.extend(f"{_toml_key(a)} = {_toml_value(b)}" for a, b in item.items())
    table(doc, "")
    return "\n".join(lines) + "\n"


# --- the property ---------------------------------------------------------------------------------

def _finite_outputs(folder: pathlib.Path, allow_nan: bool) -> None:
    for p in folder.iterdir():
        if p.suffix not in (".csv", ".json") or not p.is_file():
            continue
        is_json = p.read_bytes()[:1] in (b"{", b"[")   # the name is the user's: look at the content
        if not is_json:
            with open(p) as fh:
                for row in list(csv.reader(fh))[1:]:
                    for cell in row:
                        v = float(cell)
                        assert not math.isinf(v) and (allow_nan or not math.isnan(v)), (p.name, row)
        else:
            def constant(c, name=p.name):
                if c != "NaN" or not allow_nan:   # NaN: "not measured" in a report; never infinite
                    pytest.fail(f"{name}: {c} in output")
                return math.nan
            json.loads(p.read_text(), parse_constant=constant)


def check_cli(argv, capsys, scratch: pathlib.Path, *, allow_nan: bool = False, what: str = "") -> int:
    """Run `feelflow argv` in-process and assert the fuzz property; returns the exit code."""
    from feelflow.app.cli.main import main as cli_main

    capsys.readouterr()
    try:
        with time_limit(TIME_LIMIT), warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")   # a warning would be two more lines on a user's stderr
            try:
                rc = cli_main([str(a) for a in argv])
            except SystemExit as exc:
                rc = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    except CaseTimeout as exc:
        pytest.fail(f"{what}: {argv}: took {exc}")
    except BaseException:
        pytest.fail(f"{what}: {argv}: raised\n{traceback.format_exc()}")
    out, err = capsys.readouterr()
    assert "Traceback" not in err + out, (what, argv, err)
    shown = [w for w in caught if not issubclass(w.category, (DeprecationWarning, PendingDeprecationWarning))]
    assert not shown, (what, argv, [f"{w.category.__name__}: {w.message}" for w in shown][:3])
    if rc == 0:
        _finite_outputs(scratch, allow_nan)
    else:
        lines = [ln for ln in err.splitlines() if ln.strip()]
        errors = [ln for ln in lines if not ln.startswith("feelflow: warning:")
                  and not ln.startswith("feelflow report ") and not ln.startswith("running ")]
        assert len(errors) == 1 and errors[0].startswith("feelflow: "), (what, argv, err)
    return rc


def repo_snapshot() -> dict:
    """(size, mtime) of every file of the repository outside caches and build folders."""
    skip = {".venv", ".git", "__pycache__", ".pytest_cache", "feelflow.egg-info", "build", "dist"}
    snap = {}
    for folder, dirs, names in os.walk(ROOT):
        dirs[:] = [d for d in dirs if d not in skip and not d.endswith("_cache")]   # tools' caches
        for n in names:
            p = os.path.join(folder, n)
            try:
                st = os.lstat(p)
            except OSError:
                continue
            snap[p] = (st.st_size, st.st_mtime_ns)
    return snap


def seeds(prefix: int, default_blocks: int, fuzz_blocks: int):
    """pytest params: `default_blocks` blocks in the default run, more under -m fuzz."""
    params = [pytest.param(prefix * 100_000 + b * BLOCK, id=f"block{b}") for b in range(default_blocks)]
    params += [pytest.param(prefix * 100_000 + b * BLOCK, id=f"block{b}", marks=pytest.mark.fuzz)
               for b in range(default_blocks, default_blocks + fuzz_blocks)]
    return params
