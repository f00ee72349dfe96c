"""Atomic file writes for everything FeelFlow saves (CSV, JSON, PNG, reports, shapes from the
window, sessions): write a temporary file beside the target, flush it to disk, then
`os.replace` it into place, so a crash or a full disk never leaves half a file and the old file
survives a failed write. New files get the usual permissions (0666 less the umask; `mkstemp`
alone would make them private); an overwritten file keeps its mode.
"""
from __future__ import annotations

import json
import os
import pathlib
import tempfile
from contextlib import contextmanager

#: the process umask (read once: os.umask can only be read by setting it)
_UMASK = os.umask(0o022)
os.umask(_UMASK)


def _mode_for(path: pathlib.Path) -> int:
    try:
        return path.stat().st_mode & 0o777
    except OSError:
        return 0o666 & ~_UMASK


@contextmanager
def atomic_path(path, suffix=""):
    """Yield a temporary path in the target's folder; it replaces `path` (flushed to disk, with
    the target's permissions) only if the block succeeds. The temporary file is always removed."""
    path = pathlib.Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix or path.suffix or ".tmp",
                               dir=path.parent if str(path.parent) else ".")
    os.close(fd)
    try:
        yield pathlib.Path(tmp)
        os.chmod(tmp, _mode_for(path))
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_bytes_atomic(path, data: bytes) -> None:
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


def write_text_atomic(path, text: str) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


def write_json_atomic(path, data) -> None:
    write_text_atomic(path, json.dumps(data, indent=2) + "\n")
