"""The output policy (app/files.py) and the input policy's file checks, as a user meets them.

Outputs: checked before the work, never an input, never a device or folder, --force to replace,
atomic (a kill -9 at any moment leaves the old file or the whole new one, and the next start
removes the temporary), a failed write says where the work went. Inputs: a named pipe is
refused at once (real subprocesses, so a hang would show as a timeout).
"""
from __future__ import annotations

import errno
import os
import pathlib
import random
import signal
import subprocess
import sys
import time

import pytest

from feelflow.app import files
from feelflow.app.cli.main import main as cli_main
from feelflow.app.errors import UserError

ROOT = pathlib.Path(__file__).resolve().parents[1]

SCENE = """
[grid]
nx = 48
ny = 24

[flow]
nu = 0.05
inflow_speed = 0.04
inflow_ramp_steps = 10

[body]
kind = "cylinder"
diameter = 6
x = 16
y = 12.3

[output]
interval = 5

[run]
steps = 10
"""


def one_error_line(err: str) -> str:
    lines = [ln for ln in err.strip("\n").split("\n") if ln]
    assert "Traceback" not in err
    assert len(lines) == 1 and lines[0].startswith("feelflow: "), err
    return lines[0]


def dead_pid() -> int:
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


# --- check_output ---------------------------------------------------------------------------

def test_check_output_refuses_what_it_must(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text("x")
    link = tmp_path / "link.toml"
    link.symlink_to(scene)
    cases = [
        (dict(path=scene, inputs=[scene], force=True), "is an input"),
        (dict(path=link, inputs=[scene], force=True), "is an input"),           # the same file by another name
        (dict(path=tmp_path / "a.csv", others=[str(tmp_path / "a.csv")]), "two outputs"),
        (dict(path=scene), "already exists; add --force"),
        (dict(path=tmp_path), "is a directory"),
        (dict(path="/dev/null", force=True), "not a regular file"),
        (dict(path=tmp_path / "no" / "x.csv"), "does not exist"),
        (dict(path=tmp_path / ("n" * 300)), "too long"),
    ]
    for kwargs, words in cases:
        with pytest.raises(UserError) as info:
            files.check_output(option="--out", **kwargs)
        assert words in str(info.value) and "\n" not in str(info.value), (kwargs, info.value)
    assert files.check_output(scene, "--out", force=True) == scene   # replacing asked for: allowed
    assert files.check_output(tmp_path / "new.csv", "--out") == tmp_path / "new.csv"


def test_fifo_output_refused(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    with pytest.raises(UserError, match="not a regular file"):
        files.check_output(fifo, "--out", force=True)
    with pytest.raises(OSError):
        with files.atomic_path(fifo) as tmp:
            tmp.write_text("x")
    assert fifo.is_fifo()


# --- temporaries ----------------------------------------------------------------------------

def test_stale_temporaries_are_removed_at_the_next_write_and_live_ones_kept(tmp_path):
    stale = tmp_path / f"{files.TEMP_PREFIX}{dead_pid()}-0badf00d.tmp"
    live = tmp_path / f"{files.TEMP_PREFIX}{os.getppid()}-abcdef12.csv"   # a running process's
    other = tmp_path / ".feelflow-tmp-notes.txt"                            # not ours: kept
    for p in (stale, live, other):
        p.write_text("partial")
    files.write_text_atomic(tmp_path / "out.csv", "a,b\n")
    assert not stale.exists() and live.exists() and other.exists()
    assert (tmp_path / "out.csv").read_text() == "a,b\n"


def test_failed_write_keeps_old_file_no_temporary_and_says_where_the_work_went(tmp_path, monkeypatch):
    target = tmp_path / "forces.csv"
    target.write_text("old\n")

    real_replace = os.replace

    def full_disk(src, dst):
        if pathlib.Path(dst) == target:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real_replace(src, dst)
    monkeypatch.setattr(files.os, "replace", full_disk)
    with pytest.raises(UserError) as info:
        files.save_text(target, "new\n", "--out")
    msg = str(info.value)
    assert "\n" not in msg and str(target) in msg and "No space left" in msg
    saved = pathlib.Path(msg.split("saved to ")[1].split(" instead")[0])
    try:
        assert saved.read_text() == "new\n"
    finally:
        saved.unlink()
    assert target.read_text() == "old\n"
    assert sorted(os.listdir(tmp_path)) == ["forces.csv"]


KILL_CHILD = r"""
import sys, pathlib
from feelflow.app.files import write_bytes_atomic
from feelflow.shapes.cylinder import Cylinder
from feelflow.app.shape_files import save_shape
folder = pathlib.Path(sys.argv[1])
k = 0
print("ready", flush=True)
while True:
    k += 1
    tag = b"%08d" % k
    write_bytes_atomic(folder / "big.bin", tag * 250000)          # 2 MB, every byte tells its write
    save_shape(folder / "shape.json", Cylinder(diameter=10 + k % 7, x=50, y=50))
"""


def test_kill_9_during_writes_leaves_old_or_new_file_and_the_next_start_removes_temporaries(tmp_path):
    """A writer killed with SIGKILL at random moments (seeded): each file is always whole (one
    write's bytes throughout; a shape file that loads), and the next write in that folder
    removes what the killed one left."""
    from feelflow.app.shape_files import load_shape

    rng = random.Random(34)
    killed_mid_write = 0
    for round_ in range(6):
        child = subprocess.Popen([sys.executable, "-c", KILL_CHILD, str(tmp_path)], cwd=tmp_path,
                                 stdout=subprocess.PIPE, text=True)
        assert child.stdout.readline().strip() == "ready"
        time.sleep(rng.uniform(0.05, 0.6))
        child.send_signal(signal.SIGKILL)
        child.wait(timeout=30)
        child.stdout.close()
        big = (tmp_path / "big.bin").read_bytes() if (tmp_path / "big.bin").exists() else None
        if big is not None:
            assert len(big) == 2_000_000 and big == big[:8] * 250000, round_
        if (tmp_path / "shape.json").exists():
            load_shape(tmp_path / "shape.json")
        killed_mid_write += any(n.startswith(files.TEMP_PREFIX) for n in os.listdir(tmp_path))
    assert killed_mid_write >= 1   # the kills did land inside writes (the writer is mostly writing)
    # the next start: any write in the folder cleans up after the killed ones
    files.write_text_atomic(tmp_path / "next.txt", "x")
    left = [n for n in os.listdir(tmp_path) if n.startswith(files.TEMP_PREFIX)]
    assert left == [], left


# --- the commands: nothing is destroyed ------------------------------------------------------

@pytest.fixture
def scene(tmp_path):
    path = tmp_path / "scene.toml"
    path.write_text(SCENE)
    return path


def test_run_never_overwrites_its_inputs_or_an_existing_file_without_force(scene, tmp_path, capsys):
    original = scene.read_bytes()
    out = tmp_path / "f.csv"
    for argv, words in [
        (["run", str(scene), "--out", str(scene)], "is an input"),
        (["run", str(scene), "--out", str(out), "--record", str(scene)], "is an input"),
        (["run", str(scene), "--out", str(out), "--record", str(out)], "two outputs"),
        (["run", str(scene), "--out", "/dev/null", "--force"], "not a regular file"),
        (["run", str(scene), "--out", str(tmp_path / "missing" / "f.csv")], "does not exist"),
    ]:
        assert cli_main(argv) == 2, argv
        assert words in one_error_line(capsys.readouterr().err), argv
        assert scene.read_bytes() == original
    assert cli_main(["run", str(scene), "--out", str(out), "--backend", "numpy"]) == 0
    first = out.read_bytes()
    capsys.readouterr()
    assert cli_main(["run", str(scene), "--out", str(out), "--backend", "numpy"]) == 2           # exists: refused before the run
    assert "--force" in one_error_line(capsys.readouterr().err)
    assert out.read_bytes() == first
    assert cli_main(["run", str(scene), "--out", str(out), "--force", "--steps", "5", "--backend", "numpy"]) == 0
    assert out.read_bytes() != first


def test_session_commands_never_destroy_the_session(scene, tmp_path, capsys):
    session = tmp_path / "s.ffsession"
    assert cli_main(["run", str(scene), "--out", str(tmp_path / "f.csv"), "--record", str(session), "--backend", "numpy"]) == 0
    original = session.read_bytes()
    capsys.readouterr()
    for argv in (["session", "replay", str(session), "--out", str(session), "--force"],
                 ["session", "export", str(session), "--csv", str(session), "--force"],
                 ["session", "export", str(session), "--manifest", str(session)],
                 ["session", "export", str(session), "--csv", str(tmp_path / "a"), "--manifest", str(tmp_path / "a")]):
        assert cli_main(argv) == 2, argv
        one_error_line(capsys.readouterr().err)
        assert session.read_bytes() == original


def test_force_is_in_every_writing_commands_help(capsys):
    for argv in (["run", "-h"], ["session", "replay", "-h"], ["session", "export", "-h"], ["validate", "-h"],
                 ["bench", "-h"], ["report", "-h"]):
        with pytest.raises(SystemExit):
            cli_main(argv)
        assert "--force" in capsys.readouterr().out, argv


# --- inputs: a named pipe never blocks (real processes: a hang would be a timeout) ----------------

@pytest.mark.parametrize("argv", [["run", "{p}"], ["session", "info", "{p}"], ["gui", "{p}"]])
def test_a_named_pipe_as_input_is_refused_at_once(tmp_path, argv):
    fifo = tmp_path / "pipe.toml"
    os.mkfifo(fifo)
    if argv[0] == "gui":   # the shape loader: the window's path, without a window
        code = ("import sys\nfrom feelflow.app.shape_files import load_shape\nfrom feelflow.shapes.base import ShapeError\n"
                "try:\n    load_shape(sys.argv[1])\nexcept ShapeError as e:\n    print(e, file=sys.stderr); sys.exit(2)\n")
        cmd = [sys.executable, "-c", code, str(fifo)]
    else:
        cmd = [sys.executable, "-m", "feelflow.app", *[a.format(p=fifo) for a in argv]]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=60, cwd=tmp_path)
    assert r.returncode == 2, r.stderr
    assert "not a regular file" in r.stderr and "Traceback" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1


def test_run_whose_csv_cannot_be_written_keeps_the_work(scene, tmp_path, capsys, monkeypatch):
    """The simulation is done when the disk fills: the rows go to a rescue file (named in the one
    line), and the session is still recorded; a session that cannot be written is rescued too."""
    out, session = tmp_path / "f.csv", tmp_path / "s.ffsession"
    real_replace = os.replace
    failing = {out}

    def full_disk(src, dst):
        if pathlib.Path(dst) in failing:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real_replace(src, dst)
    monkeypatch.setattr(files.os, "replace", full_disk)
    assert cli_main(["run", str(scene), "--out", str(out), "--record", str(session)]) == 2
    line = one_error_line(capsys.readouterr().err)
    assert str(out) in line and "No space left" in line
    rescued = pathlib.Path(line.split("saved to ")[1].split(" instead")[0])
    try:
        assert rescued.read_text().startswith("step,x,y")
    finally:
        rescued.unlink()
    assert not out.exists() and session.exists()
    failing.add(session)
    session.unlink()
    assert cli_main(["run", str(scene), "--out", str(tmp_path / "g.csv"), "--record", str(session)]) == 2
    line = one_error_line(capsys.readouterr().err)
    assert str(session) in line and "saved to" in line and f"the forces are in {tmp_path / 'g.csv'}" in line
    rescued = pathlib.Path(line.split("saved to ")[1].split(" instead")[0])
    try:
        from feelflow.app.sessions import load_session
        load_session(rescued)
    finally:
        rescued.unlink()
