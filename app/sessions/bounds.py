"""How much a session file may hold, checked before any array is read (docs/reference/files.md).

A session declares its counts (inputs, parameter changes, force rows, steps) and its grid in
the manifest; those are bounded by what a machine can do, and then bound how many bytes each
array member may inflate to. An `.npz` member's `.npy` headers are read and checked against the
bytes that are really there before numpy allocates anything. `fail(message)` raises the
caller's one-line error.
"""
from __future__ import annotations

import io
import math
import tokenize
import zipfile
import zlib

import numpy as np

#: largest JSON member (manifest, parameters) and largest session file, bytes
MAX_JSON_BYTES = 16 << 20
MAX_FILE_BYTES = 1 << 30
#: most input samples, parameter changes or force rows a session may declare: a million rows of
#: forces are about 100 MB of arrays, more than a day of recording at 10 rows a second
MAX_ROWS = 1_000_000
#: room for the .npy headers and zip records of one .npz member, bytes
NPZ_OVERHEAD = 4096
#: most entries in one .npz member (a session's have 1 to 6 arrays)
MAX_ENTRIES = 16
#: an entry's uncompressed size over its member's size (deflate reaches about 1000:1)
MAX_RATIO = 1100


def _count(d, key: str, fail, where: str) -> int:
    v = d.get(key) if isinstance(d, dict) else None
    if isinstance(v, bool) or not isinstance(v, int) or v < 0:
        fail(f"{where}{key} must be a non-negative integer, got {repr(v)[:20]}")
    return v


def rows_problem(counts: dict) -> str | None:
    """Why these counts of inputs, parameter changes and force rows are more than a session may
    hold (MAX_ROWS each), or None."""
    for key in ("inputs", "parameters", "forces"):
        if counts[key] > MAX_ROWS:
            return f"counts.{key} is {counts[key]}, more than a session may hold ({MAX_ROWS})"
    return None


def session_problem(counts: dict, nx: int, ny: int, parameters_bytes: int = 0) -> str | None:
    """Why a session with these counts (inputs, parameters, forces, steps) on its scene's nx x ny
    grid, and a parameters member of `parameters_bytes`, is more than a session may hold, or None:
    the loader's own bounds (`member_limits`, MAX_JSON_BYTES), which the recorder (recorder.py)
    checks before each row so that it never writes a file this loader refuses."""
    from feelflow.app.errors import UserError
    from feelflow.app.inputs import check_work

    problem = rows_problem(counts)
    if problem is not None:
        return problem
    if parameters_bytes > MAX_JSON_BYTES:
        return f"parameters.json would be {parameters_bytes} bytes, more than a session may hold ({MAX_JSON_BYTES})"
    try:
        check_work(max(nx, 1), max(ny, 1), counts["steps"], "the session", "counts.steps")
    except UserError as exc:
        return str(exc)
    return None


def member_limits(manifest, fail, manifest_name: str, members) -> dict:
    """Bytes each array member (inputs, forces, state) may inflate to, from the counts and grid
    the manifest declares, after bounding those (MAX_ROWS; app/inputs.py's grid and steps)."""
    from feelflow.app.errors import UserError
    from feelflow.app.inputs import check_work

    inputs, forces, state = members
    where = f"{manifest_name}: "
    if not isinstance(manifest, dict) or not isinstance(manifest.get("counts"), dict):
        fail(f"{where}'counts' is missing or not a dict")
    counts = manifest["counts"]
    n = {k: _count(counts, k, fail, where + "counts.") for k in ("inputs", "parameters", "forces", "steps")}
    problem = rows_problem(n)
    if problem is not None:
        fail(where + problem)
    if n["forces"] > n["steps"]:
        fail(f"{where}counts.forces is {n['forces']} but a force row covers at least one of the "
             f"{n['steps']} steps")
    scene = manifest.get("scene")
    config = scene.get("config") if isinstance(scene, dict) else None
    nx = _count(config, "nx", fail, where + "scene.config.")
    ny = _count(config, "ny", fail, where + "scene.config.")
    try:
        check_work(max(nx, 1), max(ny, 1), n["steps"], manifest_name, "counts.steps")
    except UserError as exc:
        fail(str(exc))
    declared = manifest.get("forces")
    models = declared.get("models") if isinstance(declared, dict) else None
    columns = 3 * len(models) if isinstance(models, list) and len(models) <= 16 else 48
    return {inputs: NPZ_OVERHEAD + n["inputs"] * 8 * 8,             # seq, step, pose (3), velocity (3)
            forces: NPZ_OVERHEAD + n["forces"] * 8 * (7 + columns),  # seq, step, n, body (4), values, torques
            state: NPZ_OVERHEAD + 9 * nx * ny * 8}                     # f (9, ny, nx) float64


def _entries(raw: bytes, member: str):
    """(name, declared shape, dtype, data bytes present) per .npy entry, or a one-line problem."""
    buf = io.BytesIO(raw)
    if not zipfile.is_zipfile(buf):
        return f"{member} is not an .npz archive (a plain .npy or another file)"
    out = []
    try:
        with zipfile.ZipFile(buf) as zf:
            infos = zf.infolist()
            if len(infos) > MAX_ENTRIES:
                return f"{member} holds {len(infos)} entries, more than a session member has"
            for info in infos:
                name = info.filename[:40]
                if info.file_size > len(raw) * MAX_RATIO:
                    return f"{member}: entry {name!r} claims {info.file_size} bytes"
                with zf.open(info) as fh:
                    version = np.lib.format.read_magic(fh)
                    if version not in ((1, 0), (2, 0)):
                        return f"{member}: entry {name!r} has .npy version {version}"
                    read = (np.lib.format.read_array_header_1_0 if version == (1, 0)
                            else np.lib.format.read_array_header_2_0)
                    shape, _, dtype = read(fh, max_header_size=4096)
                    out.append((name, shape, dtype, info.file_size - fh.tell()))
    except (zipfile.BadZipFile, zlib.error, EOFError, OSError, ValueError, NotImplementedError,
            RuntimeError, SyntaxError, tokenize.TokenError, MemoryError) as exc:
        # numpy's .npy header parser tokenizes the header text: a malformed one raises
        # tokenize.TokenError or SyntaxError
        text = str(exc).splitlines()[0][:80] if str(exc) else type(exc).__name__
        return f"{member} is not a readable .npz archive ({text})"
    return out


def check_npz(raw: bytes, member: str, fail) -> None:
    """The member is a zip of .npy arrays whose headers are plausible before any is read: numeric
    dtypes (never pickle), and a declared shape that matches the bytes actually there (a crafted
    header cannot make numpy allocate terabytes)."""
    entries = _entries(raw, member)
    if isinstance(entries, str):
        fail(entries)
    for name, shape, dtype, present in entries:
        if dtype.hasobject or dtype.kind not in "iuf":
            fail(f"{member}: entry {name!r} holds {dtype} data (numbers only; never pickle)")
        if math.prod(shape) * dtype.itemsize != present:
            fail(f"{member}: entry {name!r} declares shape {shape[:4]} but holds {present} bytes of data")
