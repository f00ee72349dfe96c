"""Atomic file writes for everything the window saves: write a temp file beside, then os.replace."""
from __future__ import annotations

import os
import pathlib
import tempfile
from contextlib import contextmanager


@contextmanager
def atomic_path(path, suffix=""):
    """Yield a temporary path in the target's folder; it replaces `path` only if the block succeeds."""
    path = pathlib.Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix or path.suffix, dir=path.parent)
    os.close(fd)
    try:
        yield pathlib.Path(tmp)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_text_atomic(path, text: str):
    with atomic_path(path) as tmp:
        tmp.write_text(text)
