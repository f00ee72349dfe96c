"""`feelflow --selftest --frame-profile` (app/gui/frame_profile.py): the parts of a frame are timed
on the running window, every part is reported, and detaching leaves the window as it was; and
the frame length the frame loop aims at (app/gui/window/frame_loop.py)."""
from __future__ import annotations

import subprocess
import sys

import pytest

pytestmark = pytest.mark.gui


def test_the_command_line_takes_frame_profile():
    from feelflow.app.cli.main import build_parser

    args = build_parser().parse_args(["--selftest", "--frame-profile", "--seconds", "5"])
    assert args.selftest and args.frame_profile


@pytest.mark.slow
def test_a_lessons_frames_are_measured_and_profiled():
    """`feelflow --selftest --frame-profile --lesson KEY` measures the lesson's frames as the
    default scene's: frames and solver steps per second, and the profile's table."""
    r = subprocess.run([sys.executable, "-m", "feelflow.app", "--selftest", "--frame-profile", "--seconds", "4",
                        "--lesson", "vortex_street", "gui", "--backend", "numpy"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    out = r.stdout
    assert "grid 256x128" in out and "frames/s" in out and "solver steps/s" in out, out
    assert "frame profile: solver steps" in out and out.rstrip().endswith("selftest: ok"), out


def test_frame_profile_times_every_part_and_leaves_the_window_as_it_was(window, qtbot):
    from feelflow.app.gui.frame_profile import PARTS, FrameProfile

    loop, session = window.loop, window.sim.solver
    backend = session.solver
    profile = FrameProfile()
    profile.attach(window)
    qtbot.wait(700)   # a few hundred frames, and the readouts (twice a second) at least once
    profile.detach()
    assert profile.frames > 3 and profile.steps > 0 and profile.wall > 0.5
    measured = {k for k, v in profile.totals.items() if v > 0}
    # everything a frame of the numpy tunnel does was seen (the plot paints when Qt says so)
    assert {"steps", "forces", "check", "field", "loop", "draw", "overlay", "readouts", "plot_data",
            "compose"} <= measured
    lines = profile.report("llvmpipe", "numpy", "128x64")
    text = "\n".join(lines)
    for label in list(PARTS.values()) + ["rest", "load average", "cores", "renderer llvmpipe", "backend numpy",
                                         "grid 128x64", "frames/s", "solver steps/s"]:
        assert label in text, (label, text)
    shares = [share for _, _, share, _ in profile.rows()]
    assert all(s >= 0 for s in shares) and sum(shares) == pytest.approx(1.0, abs=0.02)
    # nothing of the profile is left on the window's objects; the timers call the frame loop again
    for obj in (backend, session, window.sim, loop, window.viewport, window.viewport.overlay, window.plot,
                window.plot.plot, window):
        assert not any(getattr(v, "__qualname__", "").startswith("FrameProfile") for v in vars(obj).values())
    frames = window.viewport.frames
    qtbot.waitUntil(lambda: window.viewport.frames > frames + 2, timeout=5000)


def test_frames_aim_at_60_per_second_while_the_solver_keeps_half_of_each():
    from types import SimpleNamespace

    from feelflow.app.gui.window.frame_loop import FASTEST_FRAME_S, SLOWEST_FRAME_S, FrameLoop

    def frame(other_ms):
        return FrameLoop.frame_seconds(SimpleNamespace(other_cost=other_ms / 1e3))
    assert frame(4.0) == FASTEST_FRAME_S == 1 / 61.5       # drawing takes a quarter: 60 fps
    assert frame(10.0) == pytest.approx(0.020)              # half for the solver: 50 fps
    assert frame(25.0) == SLOWEST_FRAME_S == 1 / 31.5      # never below 30 fps
