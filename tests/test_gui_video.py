"""Video from the real window (Xvfb): a recorded session exported to MP4 and GIF with the
progress dialog (the files decode to the expected number of frames), a cancelled export that
writes nothing, and the live window recorded until stopped."""
from __future__ import annotations

import pytest

from gui_fixtures import window  # noqa: F401 - the fixture

pytestmark = pytest.mark.gui


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    from feelflow.app.sessions import SessionRecorder, SessionSolver
    from feelflow.solver.backend import create_solver
    from session_scenes import MODELS, drive_moving_cylinder, small_config, start_body

    cfg = small_config()
    rec = SessionRecorder(cfg, start_body(), MODELS, scene_source="scenes/test.toml")
    drive_moving_cylinder(SessionSolver(create_solver("numpy", cfg), rec), steps=25)   # 49 steps
    path = tmp_path_factory.mktemp("video") / "run.ffsession"
    rec.save(path)
    return path


def test_export_a_session_to_video_with_progress_and_cancel(window, qtbot, tmp_path, recorded):  # noqa: F811
    from feelflow.app.video import count_frames

    v = window.video
    for name in ("clip.mp4", "clip.gif"):
        out = tmp_path / name
        assert v.export_session(recorded, out, steps_per_frame=5, width=320)
        assert v.progress is not None and v.progress.isVisible()
        qtbot.waitUntil(lambda: v.job is None, timeout=30000)
        assert count_frames(out) == 11, name         # the first picture and one every 5 of 49 steps
        assert "Wrote" in v.last_message and "11 frames" in v.last_message
    # cancelled: nothing written, no temporary left
    out = tmp_path / "cancelled.mp4"
    assert v.export_session(recorded, out, steps_per_frame=1, width=320)
    from PySide6.QtCore import Qt
    from PySide6.QtWidgets import QPushButton

    qtbot.mouseClick(v.progress.findChild(QPushButton), Qt.LeftButton)   # the dialog's Cancel
    qtbot.waitUntil(lambda: v.job is None, timeout=10000)
    assert "cancelled" in v.last_message, v.last_message
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["clip.gif", "clip.mp4"]


def test_record_the_live_window(window, qtbot, tmp_path):  # noqa: F811
    from feelflow.app.video import count_frames

    v = window.video
    out = tmp_path / "live.mp4"
    assert v.start_live(out)
    qtbot.waitUntil(lambda: v.live.frames >= 6, timeout=10000)
    assert v.label.isVisible() and "Recording video" in v.label.text()
    frames = v.live.frames
    assert v.stop_live() == out
    assert count_frames(out) >= frames and not v.label.isVisible()
