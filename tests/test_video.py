"""Video: a recorded session rendered to MP4 and to an animated GIF without a window
(`feelflow session render`, Qt offscreen, PyAV), each file decoded back to the expected number
of frames; bad names are one line; a cancelled render leaves nothing behind."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from feelflow.app.sessions import SessionRecorder, SessionSolver
from feelflow.solver.backend import create_solver
from session_scenes import MODELS, drive_moving_cylinder, small_config, start_body

ROOT = Path(__file__).resolve().parents[1]


def feelflow(*args):
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen")
    return subprocess.run([sys.executable, "-m", "feelflow.app", *map(str, args)], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=120)


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    cfg = small_config()
    rec = SessionRecorder(cfg, start_body(), MODELS, scene_source="scenes/test.toml")
    drive_moving_cylinder(SessionSolver(create_solver("numpy", cfg), rec), steps=25)   # 49 steps
    path = tmp_path_factory.mktemp("video") / "run.ffsession"
    rec.save(path)
    return path


def test_writer_round_trip_mp4_and_gif(tmp_path):
    from feelflow.app.video import VideoWriter, count_frames

    for name in ("a.mp4", "a.gif"):
        w = VideoWriter(tmp_path / name, fps=10)
        for k in range(7):
            frame = np.zeros((41, 63, 3), np.uint8)     # odd sizes: the MP4 pads to even ones
            frame[:, 9 * k:9 * k + 9] = (255, 200, 0)
            w.add(frame)
        assert w.finish() == tmp_path / name
        assert count_frames(tmp_path / name) == 7
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.gif", "a.mp4"]   # no temporaries left


def test_cancel_leaves_the_old_file(tmp_path):
    from feelflow.app.video import VideoWriter

    out = tmp_path / "keep.mp4"
    out.write_bytes(b"old")
    w = VideoWriter(out)
    w.add(np.zeros((16, 16, 3), np.uint8))
    w.cancel()
    assert out.read_bytes() == b"old" and [p.name for p in tmp_path.iterdir()] == ["keep.mp4"]


@pytest.mark.parametrize("suffix", [".mp4", pytest.param(".gif", marks=pytest.mark.slow)])
def test_session_render_headless(recorded, tmp_path, suffix):
    from feelflow.app.video import count_frames

    out = tmp_path / f"clip{suffix}"
    r = feelflow("session", "render", recorded, "--out", out, "--steps-per-frame", "5", "--width", "320")
    assert r.returncode == 0, r.stderr
    assert count_frames(out) == 1 + 10     # the first picture, then one every 5 of the 49 steps
    assert "11 frames" in r.stdout and "ms a frame" in r.stdout
    again = feelflow("session", "render", recorded, "--out", out)
    assert again.returncode == 2 and "already exists" in again.stderr and "Traceback" not in again.stderr


def test_session_render_bad_input_is_one_line(recorded, tmp_path):
    r = feelflow("session", "render", recorded, "--out", tmp_path / "clip.avi")
    assert r.returncode == 2 and "written as .mp4 or .gif" in r.stderr and r.stderr.count("\n") == 1
    r = feelflow("session", "render", recorded, "--out", tmp_path / "c.mp4", "--steps-per-frame", "0")
    assert r.returncode == 2 and "--steps-per-frame: must be at least 1" in r.stderr
    assert not (tmp_path / "c.mp4").exists()
