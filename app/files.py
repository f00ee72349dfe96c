"""Every file FeelFlow writes goes through here (CSV, JSON, PNG, reports, shapes from the window,
sessions, exports): one output policy (docs/reference/files.md).

Before the work starts, `check_output` refuses a destination that is not a regular file (a
folder, a device, a pipe), is an input of the same command, already exists (unless replacing it
was asked for: `--force` on the command line, the file dialog's confirmation in the window), or
lies in a folder that is missing or cannot be written. Writes are atomic: a temporary file
beside the target, flushed to disk, then `os.replace`, so a crash, a kill -9 or a full disk
never leaves half a file and the old file survives a failed write. Temporaries are named
`.feelflow-tmp-<pid>-<token><suffix>`; those of a process that no longer runs (a killed write)
are removed the next time anything is written to that folder. New files get the usual
permissions (0666 less the umask); an overwritten file keeps its mode.
"""
from __future__ import annotations

import errno
import json
import os
import pathlib
import re
import secrets
import stat
import tempfile
from contextlib import contextmanager

from feelflow.app.errors import UserError, shown_path

#: the process umask (read once: os.umask can only be read by setting it)
_UMASK = os.umask(0o022)
os.umask(_UMASK)
TEMP_PREFIX = ".feelflow-tmp-"
_TEMP_NAME = re.compile(r"^\.feelflow-tmp-(\d+)-[A-Za-z0-9_]{8}(\.[A-Za-z0-9]{1,8})?$")


class OutputError(UserError):
    """An output cannot be written (one line naming the path and the reason)."""


def _mode_for(path: pathlib.Path) -> int:
    try:
        return path.stat().st_mode & 0o777
    except OSError:
        return 0o666 & ~_UMASK


def _folder(path: pathlib.Path) -> pathlib.Path:
    return path.parent if str(path.parent) else pathlib.Path(".")


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return True
    return True


def clean_stale_temporaries(folder) -> list[pathlib.Path]:
    """Remove the temporaries of writes whose process has gone (killed mid-write); returns them."""
    removed = []
    try:
        names = os.listdir(folder)
    except OSError:
        return removed
    for name in names:
        m = _TEMP_NAME.match(name)
        if m is None or _alive(int(m.group(1))):
            continue
        p = pathlib.Path(folder) / name
        try:
            if stat.S_ISREG(os.lstat(p).st_mode):
                os.unlink(p)
                removed.append(p)
        except OSError:
            pass
    return removed


def _same_file(a: pathlib.Path, b) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.abspath(a) == os.path.abspath(b)


def check_output(path, option: str = "output", *, inputs=(), others=(), force: bool = False,
                 hint: str = "add --force to replace it") -> pathlib.Path:
    """Check an output destination before any work: OutputError (one line) when it is not a
    regular file, is one of `inputs` (or the same path as one of `others`, the command's other
    outputs), exists and `force` is false, or its folder is missing or not writable. Stale
    temporaries in the folder are removed."""
    path = pathlib.Path(path)
    label = f"{option}: {shown_path(path)!r}"
    if not str(path) or path.name in ("", ".", "..") or "\x00" in str(path):
        raise OutputError(f"{option}: {shown_path(path)!r} is not a file name")
    for other in inputs:
        if other is not None and _same_file(path, other):
            raise OutputError(f"{label} is an input of this command; it would be destroyed (choose another name)")
    for other in others:
        if other is not None and os.path.abspath(path) == os.path.abspath(other):
            raise OutputError(f"{label} is given for two outputs; the first would be lost (choose another name)")
    try:
        st = os.stat(path)
    except FileNotFoundError:
        st = None
    except OSError as exc:
        raise OutputError(f"{label}: cannot be written ({exc.strerror or exc})") from None
    if st is not None:
        if stat.S_ISDIR(st.st_mode):
            raise OutputError(f"{label} is a directory, not a file")
        if not stat.S_ISREG(st.st_mode):
            raise OutputError(f"{label} is not a regular file (a device, pipe or socket); refused")
        if not force:
            raise OutputError(f"{label} already exists; {hint}")
    if len(path.name.encode()) > 255:
        raise OutputError(f"{label}: the file name is too long")
    folder = _folder(path)
    try:
        folder_is_dir = stat.S_ISDIR(os.stat(folder).st_mode)
    except (OSError, ValueError):
        folder_is_dir = False
    if not folder_is_dir:
        raise OutputError(f"{option}: directory {shown_path(folder)!r} does not exist; cannot write {shown_path(path.name)!r} there")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise OutputError(f"{option}: directory {shown_path(folder)!r} is not writable; cannot write {shown_path(path.name)!r} there")
    clean_stale_temporaries(folder)
    return path


def check_output_folder(path, option: str = "--out") -> pathlib.Path:
    """Check a folder a command writes its own files into (`report seed --out DIR`) before any
    work: OutputError (one line) when it is missing, not a folder or not writable. The files in
    it are written with `atomic_path` and belong to the command, so they are replaced."""
    path = pathlib.Path(path)
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise OutputError(f"{option}: {shown_path(path)!r} does not exist (create the folder first)") from None
    except (OSError, ValueError) as exc:
        raise OutputError(f"{option}: {shown_path(path)!r}: cannot be written "
                          f"({getattr(exc, 'strerror', None) or exc})") from None
    if not stat.S_ISDIR(st.st_mode):
        raise OutputError(f"{option}: {shown_path(path)!r} is not a folder")
    if not os.access(path, os.W_OK | os.X_OK):
        raise OutputError(f"{option}: folder {shown_path(path)!r} is not writable")
    clean_stale_temporaries(path)
    return path


def _temporary(folder: pathlib.Path, suffix: str) -> pathlib.Path:
    suffix = suffix if re.fullmatch(r"\.[A-Za-z0-9]{1,8}", suffix or "") else ".tmp"
    for _ in range(100):
        tmp = folder / f"{TEMP_PREFIX}{os.getpid()}-{secrets.token_hex(4)}{suffix}"
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        except FileExistsError:
            continue
        os.close(fd)
        return tmp
    raise FileExistsError(errno.EEXIST, "no free temporary name", str(folder))


@contextmanager
def atomic_path(path, suffix=""):
    """Yield a temporary path in the target's folder; it replaces `path` (flushed to disk, with
    the target's permissions) only if the block succeeds. The temporary file is always removed.
    A target that exists and is not a regular file is refused (OSError)."""
    path = pathlib.Path(path)
    try:
        st = os.stat(path)
    except FileNotFoundError:
        st = None
    if st is not None and not stat.S_ISREG(st.st_mode):
        raise IsADirectoryError(errno.EISDIR if stat.S_ISDIR(st.st_mode) else errno.EINVAL,
                                "not a regular file", str(path))
    folder = _folder(path)
    clean_stale_temporaries(folder)
    tmp = _temporary(folder, suffix or path.suffix)
    try:
        yield tmp
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


def rescue_path(path) -> pathlib.Path:
    """Where work goes when its destination fails: a new file in the temp folder."""
    name = pathlib.Path(path).name or "output"
    fd, tmp = tempfile.mkstemp(prefix="feelflow-rescued-", suffix="-" + name[-80:])
    os.close(fd)
    return pathlib.Path(tmp)


def write_or_rescue(path, write, option: str = "output") -> pathlib.Path:
    """Run `write(target)` on `path`; if that fails with an OSError, write to `rescue_path` and
    raise OutputError naming the path, the reason and where the work went instead."""
    try:
        write(path)
        return pathlib.Path(path)
    except OSError as exc:
        reason = exc.strerror or str(exc)
        saved = None
        try:
            saved = rescue_path(path)
            write(saved)
            where = f"the work was saved to {saved} instead"
        except OSError as exc2:
            where = f"and the rescue copy failed too ({exc2.strerror or exc2})"
            if saved is not None:  # no empty rescue file left behind
                saved.unlink(missing_ok=True)
        raise OutputError(f"{option}: cannot write {shown_path(path)!r} ({reason}); {where}") from None


def save_json(path, data, option: str = "--json") -> pathlib.Path:
    """`write_json_atomic` through `write_or_rescue`: a failed write is one line saying where the
    results went."""
    return write_or_rescue(path, lambda target: write_json_atomic(target, data), option)


def save_text(path, text: str, option: str = "output") -> pathlib.Path:
    """`write_text_atomic` through `write_or_rescue`."""
    return write_or_rescue(path, lambda target: write_text_atomic(target, text), option)


def save_bytes(path, data: bytes, option: str = "output") -> pathlib.Path:
    """`write_bytes_atomic` through `write_or_rescue`."""
    return write_or_rescue(path, lambda target: write_bytes_atomic(target, data), option)


def save_csv(path, header, rows, option: str = "--out") -> pathlib.Path:
    """A CSV file (`header`, then `rows`) written atomically through `write_or_rescue`."""
    import csv
    import io

    buf = io.StringIO(newline="")
    writer = csv.writer(buf)
    writer.writerow(header)
    writer.writerows(rows)
    return save_text(path, buf.getvalue(), option)
