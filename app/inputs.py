"""Every file FeelFlow reads goes through here first: one input policy (docs/reference/files.md).

A path must name a regular file (checked with `stat` before opening, so a named pipe never
blocks and a device is never read), no larger than the type's bound; text is parsed only after
the bound, and the parsed document is checked for nesting depth and for numbers a scene or
shape could never need (integers of more than 15 digits, lists of more than `MAX_ITEMS`).
Problems are a `UserError`, one line naming the file and what is wrong.
"""
from __future__ import annotations

import json
import math
import os
import stat
import tomllib

from feelflow.app.errors import UserError, shown, shown_path

#: largest scene (TOML) or JSON document read, bytes (the largest example scene is ~2 KB)
MAX_TEXT_BYTES = 1 << 20
#: deepest nesting of tables/lists a document may have (a scene needs 4)
MAX_DEPTH = 16
#: largest |integer| in a document (2**53: every integer a float can hold exactly)
MAX_INTEGER = 2 ** 53
#: most items in one list (a polygon's vertices: shapes.polygon.MAX_VERTICES)
MAX_ITEMS = 10_000


def _errno_text(exc: OSError) -> str:
    return exc.strerror or type(exc).__name__


def check_regular_file(path, what: str = "file", max_bytes: int | None = None) -> int:
    """The file's size; UserError when `path` is missing, not a regular file, or larger than
    `max_bytes`. Never opens the file (a FIFO cannot block)."""
    src = shown_path(path)
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise UserError(f"{src}: no such {what}") from None
    except OSError as exc:   # a name too long, a loop of links, a path through a regular file
        raise UserError(f"{src}: cannot be read ({_errno_text(exc)})") from None
    except ValueError:   # a NUL byte in the name
        raise UserError(f"{shown(repr(str(path)))}: not a valid file name") from None
    if stat.S_ISDIR(st.st_mode):
        raise UserError(f"{src}: is a directory, not {_a(what)}")
    if not stat.S_ISREG(st.st_mode):
        raise UserError(f"{src}: not a regular file (a pipe, device or socket); refused")
    if max_bytes is not None and st.st_size > max_bytes:
        raise UserError(f"{src}: {st.st_size} bytes, more than {_a(what)} can be ({max_bytes} bytes)")
    return st.st_size


def _a(what: str) -> str:
    return ("an " if what[:1] in "aeiou" else "a ") + what


def read_bytes(path, what: str = "file", max_bytes: int = MAX_TEXT_BYTES) -> bytes:
    """The file's bytes after `check_regular_file`; opened non-blocking (a pipe swapped in after
    the check still cannot block), checked again on the open descriptor, read up to the bound."""
    src = shown_path(path)
    check_regular_file(path, what, max_bytes)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError as exc:
        raise UserError(f"{src}: cannot be read ({_errno_text(exc)})") from None
    try:
        with os.fdopen(fd, "rb") as fh:
            if not stat.S_ISREG(os.fstat(fh.fileno()).st_mode):
                raise UserError(f"{src}: not a regular file (a pipe, device or socket); refused")
            data = fh.read(max_bytes + 1)
    except OSError as exc:   # /proc/self/mem and the like: a "regular file" that cannot be read
        raise UserError(f"{src}: cannot be read ({_errno_text(exc)})") from None
    if data is None:
        raise UserError(f"{src}: cannot be read (no data available without waiting)")
    if len(data) > max_bytes:
        raise UserError(f"{src}: more than {_a(what)} can be ({max_bytes} bytes)")
    return data


def exists(path) -> bool:
    """Whether `path` names something (never raises: a name too long or a loop of links is not there)."""
    try:
        os.stat(path)
    except (OSError, ValueError):
        return False
    return True


def is_folder(path) -> bool:
    """Whether `path` is a folder (never raises, like `exists`)."""
    try:
        return stat.S_ISDIR(os.stat(path).st_mode)
    except (OSError, ValueError):
        return False


def check_document(doc, source: str, max_items: int = MAX_ITEMS) -> None:
    """Bound nesting depth, integer size and list length of a parsed document (iteratively); the
    message names the key where the problem is (`scene.steps`, `reference[0].score`)."""
    stack = [(doc, 1, "")]
    while stack:
        value, depth, where = stack.pop()
        at = f"{shown(where)}: " if where else ""
        if isinstance(value, (dict, list)):
            if depth > MAX_DEPTH:
                raise UserError(f"{source}: {at}nested more than {MAX_DEPTH} levels deep")
            if isinstance(value, list) and len(value) > max_items:
                raise UserError(f"{source}: {at}a list of {len(value)} items (at most {max_items})")
            if isinstance(value, dict):
                stack.extend((v, depth + 1, f"{where}.{k}" if where else str(k)) for k, v in value.items())
            else:
                stack.extend((v, depth + 1, f"{where}[{i}]") for i, v in enumerate(value))
        elif isinstance(value, int) and not isinstance(value, bool) and abs(value) > MAX_INTEGER:
            raise UserError(f"{source}: {at}the integer {shown(value)} is too large (at most 2**53)")


def _text(data: bytes, source: str, kind: str) -> str:
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        raise UserError(f"{source}: not valid {kind}: not UTF-8 text") from None


def _int(text: str):
    if len(text.lstrip("+-")) > 16:
        raise ValueError(f"the integer {text[:8]}... ({len(text)} characters) is too large (at most 2**53)")
    return int(text)


def _scan_depth(text: str, source: str, opens: str) -> None:
    """Refuse brackets nested deeper than MAX_DEPTH before a recursive parser sees them (strings
    are skipped roughly: a bracket inside a quoted string may count, which only errs strict)."""
    depth = 0
    in_string = None
    escape = False
    for ch in text:
        if in_string:
            if escape:
                escape = False
            elif ch == "\\" and in_string == '"':
                escape = True
            elif ch == in_string or ch == "\n":
                in_string = None
            continue
        if ch in "\"'":
            in_string = ch
        elif ch in opens:
            depth += 1
            if depth > MAX_DEPTH:
                raise UserError(f"{source}: nested more than {MAX_DEPTH} levels deep")
        elif ch in "]}":
            depth = max(0, depth - 1)


def loads_json(data: bytes, source: str, *, allow_nan: bool = False, max_items: int = MAX_ITEMS):
    """Strict JSON: UTF-8, no NaN/Infinity (NaN allowed with `allow_nan`: a report's "not
    measured"), integers of at most 16 digits, bounded depth and list length."""
    text = _text(data, source, "JSON")
    _scan_depth(text, source, "[{")

    def constant(name):
        if allow_nan and name == "NaN":
            return math.nan
        raise ValueError(f"{name} is not allowed")

    try:
        doc = json.loads(text, parse_int=_int, parse_constant=constant)
    except json.JSONDecodeError as exc:
        raise UserError(f"{source}: not valid JSON (line {exc.lineno}, column {exc.colno}: {exc.msg})") from None
    except RecursionError:
        raise UserError(f"{source}: nested more than {MAX_DEPTH} levels deep") from None
    except MemoryError:
        raise UserError(f"{source}: not enough memory to read it") from None
    except ValueError as exc:
        raise UserError(f"{source}: not valid JSON: {shown(str(exc).splitlines()[0], 120)}") from None
    check_document(doc, source, max_items)
    return doc


def loads_toml(data: bytes, source: str):
    """TOML after the same bounds as `loads_json` (depth scanned before parsing)."""
    text = _text(data, source, "TOML")
    _scan_depth(text, source, "[{")
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise UserError(f"{source}: not valid TOML: {shown(str(exc).splitlines()[0], 120)}") from None
    except RecursionError:
        raise UserError(f"{source}: nested more than {MAX_DEPTH} levels deep") from None
    except MemoryError:
        raise UserError(f"{source}: not enough memory to read it") from None
    except ValueError as exc:
        if "integer string conversion" in str(exc):
            raise UserError(f"{source}: an integer is too large (at most 2**53)") from None
        raise UserError(f"{source}: not valid TOML: {shown(str(exc).splitlines()[0], 120)}") from None
    check_document(doc, source)
    return doc


def load_json(path, what: str = "JSON file", max_bytes: int = MAX_TEXT_BYTES, **options):
    """A JSON file read through `read_bytes` and parsed by `loads_json` (`options`: its
    `allow_nan`, `max_items`): the one bounded JSON reader (shape, attempts, backend choice,
    stored report series and session member files all come through here)."""
    return loads_json(read_bytes(path, what, max_bytes), shown_path(path), **options)


def load_toml(path, what: str = "TOML file", max_bytes: int = MAX_TEXT_BYTES):
    """A TOML file (scene, exercise) read through `read_bytes` and parsed by `loads_toml`."""
    return loads_toml(read_bytes(path, what, max_bytes), shown_path(path))


# --- counts a file may declare, by what this kind of machine can do ------------------------
#: most lattice nodes (nx * ny) a scene or session may ask for: 2**22 nodes hold about 600 MB of
#: float64 populations (two copies of 9 per node), a tenth of a small laptop's memory
MAX_NODES = 1 << 22
#: most steps one run or session may declare (about 3 hours at 1000 steps per second)
MAX_STEPS = 10_000_000
#: most node updates (nodes x steps) one run may ask for: about 2 hours at 30 MLUPS
MAX_NODE_STEPS = 2 * 10 ** 11


def check_work(nx: int, ny: int, steps: int, source: str, key: str = "steps") -> None:
    """UserError when a grid or a number of steps is beyond MAX_NODES / MAX_STEPS / MAX_NODE_STEPS."""
    if nx * ny > MAX_NODES:
        raise UserError(f"{source}: grid {nx} x {ny} has {nx * ny} nodes, more than {MAX_NODES} "
                        f"(about 600 MB of populations)")
    if steps > MAX_STEPS:
        raise UserError(f"{source}: {key}: {steps} steps, more than {MAX_STEPS} (about 3 hours of running)")
    if nx * ny * steps > MAX_NODE_STEPS:
        raise UserError(f"{source}: {key}: {steps} steps on {nx} x {ny} nodes is more than {MAX_NODE_STEPS:.0e} "
                        f"node updates (about 2 hours at 30 MLUPS)")


# --- memory a run needs, checked before anything is allocated -------------------------------
#: float64 values a run holds per lattice node: the 9 D2Q9 populations in about 4.5 copies (two
#: buffers and the collision's and forces' temporaries); measured 320 bytes per node on the numpy
#: backend at 1024 x 512 and 2048 x 1024 (float32 scenes too: the numpy path computes in float64)
VALUES_PER_NODE = 9 * 4.5
BYTES_PER_VALUE = 8


def run_bytes(nx: int, ny: int) -> int:
    """Bytes one run on an nx x ny grid needs (nx * ny * 9 populations * 4.5 copies * 8 bytes)."""
    return int(nx * ny * VALUES_PER_NODE * BYTES_PER_VALUE)


#: the fraction of the available memory a run may plan to use (the rest: Python, the window,
#: libraries loaded later, the other programs)
USABLE_FRACTION = 0.8


def available_memory() -> int | None:
    """Bytes a run may plan to allocate: USABLE_FRACTION of the smaller of the memory the system
    has available (MemAvailable, else the free physical pages) and what the address-space and
    data limits (`ulimit -v`, `ulimit -d`) leave. None when nothing can be read."""
    limits = []
    try:
        with open("/proc/meminfo", "rb") as fh:
            for line in fh.read(1 << 16).decode("ascii", "replace").splitlines():
                if line.startswith("MemAvailable:"):
                    limits.append(int(line.split()[1]) * 1024)
    except (OSError, ValueError, IndexError):
        pass
    if not limits:
        try:
            limits.append(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
        except (ValueError, OSError, AttributeError):
            pass
    try:
        import resource

        used = _address_space_used()
        for which in ("RLIMIT_AS", "RLIMIT_DATA"):
            soft = resource.getrlimit(getattr(resource, which))[0]
            if soft != resource.RLIM_INFINITY and soft > 0:
                limits.append(max(0, soft - used))
    except (ImportError, ValueError, OSError, AttributeError):
        pass
    return int(USABLE_FRACTION * min(limits)) if limits else None


def _address_space_used() -> int:
    try:
        with open("/proc/self/statm", "rb") as fh:
            return int(fh.read(256).split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


def _gib(n: float) -> str:
    return f"{n / 2 ** 30:.2f} GiB" if n < 2 ** 40 else f"{n / 2 ** 40:.1f} TiB"


def check_memory(nx: int, ny: int, source: str, key: str = "grid", copies: int = 1) -> int:
    """UserError naming the need and the limit when `copies` runs on an nx x ny grid need more
    memory than `available_memory()`; returns the bytes one run needs."""
    need = run_bytes(nx, ny)
    limit = available_memory()
    if limit is not None and need * copies > limit:
        times = f" x {copies} processes" if copies > 1 else ""
        raise UserError(f"{source}: {key}: {nx} x {ny} nodes need about {_gib(need)}{times} of memory "
                        f"(9 populations x 4.5 copies x 8 bytes per node), more than the {_gib(limit)} "
                        f"that can be used here")
    return need
