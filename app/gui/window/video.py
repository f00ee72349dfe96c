"""Videos from the window (File menu): a recorded session rendered to MP4 or GIF with a progress
bar and Cancel, and the live window recorded to a video until the user stops it.

The work is app/gui/video_export.py's (the pictures) and app/video.py's (the encoding, PyAV);
this controller adds the dialogs, the progress, and the timer that grabs the live viewport
`LIVE_FPS` times a second (the video's time is the wall clock's, whatever the window's frame
rate).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtCore import Qt, QTimer
from PySide6.QtWidgets import QFileDialog, QLabel, QMessageBox, QProgressDialog

from feelflow.app.gui.window.dialogs import attempt

if TYPE_CHECKING:
    from PySide6.QtWidgets import QStatusBar, QWidget

    from feelflow.app.gui.viewport import Viewport
    from feelflow.app.gui.window.events import WindowEvents
    from feelflow.app.gui.window.frame_loop import FrameLoop

LIVE_FPS = 25
VIDEO_FILTER = "Video (*.mp4 *.gif)"
#: a session's replay for a video runs on the recorded backend where the window can run it
#: beside its own tunnel without a second OpenGL context (numpy, cpu); a gl recording is
#: replayed on numpy (the same flow to float32 rounding)
RENDER_BACKENDS = ("numpy", "cpu")


class VideoController:
    """The File menu's video entries; `job` is the session export running (or None), `live` the
    window's recording (or None)."""

    def __init__(self, events: "WindowEvents", viewport: "Viewport", loop: "FrameLoop", status: "QStatusBar",
                 parent: "QWidget"):
        """`parent`: the dialogs', the export job's and the timer's parent."""
        self.events, self.status, self.parent = events, status, parent
        self.viewport = viewport
        self.loop = loop
        self.job = None
        self.progress: QProgressDialog | None = None
        self.live = None
        self.last_message = ""
        self.timer = QTimer(parent)
        self.timer.setInterval(int(1000 / LIVE_FPS))
        self.timer.timeout.connect(self._grab)
        self.label = QLabel()
        status.addWidget(self.label)
        self.label.hide()

    # --- a session to a video -----------------------------------------------------------------
    def export_session_dialog(self, _=None):
        session, _ = QFileDialog.getOpenFileName(self.parent, "Session to render as a video", "", "Sessions (*.ffsession)")
        if not session:
            return
        out, _ = QFileDialog.getSaveFileName(self.parent, "Save the video", "replay.mp4", VIDEO_FILTER)
        if out:
            self.export_session(session, out, force=True)   # the dialog asked before replacing a file

    def export_session(self, session_path, out, *, steps_per_frame: int = 50, force: bool = False,
                       width: int = 960) -> bool:
        """Start rendering the session file into `out` (.mp4 or .gif) with a progress dialog;
        a bad file or name is a one-line dialog. True when it started."""
        if self.job is not None:
            QMessageBox.information(self.parent, "A video is being written", "Wait for it or cancel it first.")
            return False
        job = attempt(self.parent, lambda: self._make_job(session_path, out, steps_per_frame, force, width),
                      "Could not render the video")
        if job is None:
            return False
        self.job = job
        dialog = QProgressDialog(f"Rendering {out}\u2026", "Cancel", 0, 1000, self.parent)
        dialog.setObjectName("video-progress")
        dialog.setWindowTitle("Video")
        dialog.setWindowModality(Qt.WindowModal)
        dialog.setMinimumDuration(0)
        dialog.setAutoClose(False)
        dialog.setAutoReset(False)
        dialog.canceled.connect(job.cancel)
        job.progressed.connect(lambda f: dialog.setValue(int(round(1000 * f))))
        job.finished.connect(self._export_done)
        self.progress = dialog
        dialog.show()
        job.start()
        return True

    def _make_job(self, session_path, out, steps_per_frame, force, width):
        from feelflow.app.files import check_output
        from feelflow.app.gui.video_export import SessionRender, VideoExportJob
        from feelflow.app.sessions import load_session
        from feelflow.app.video import video_format

        video_format(out)
        check_output(out, "video", inputs=[session_path], force=force, hint="choose another name")
        session = load_session(session_path)
        backend = session.backend if session.backend in RENDER_BACKENDS else "numpy"
        mode = self.loop.display.mode if self.loop.display.mode in ("speed", "vorticity", "pressure") else "speed"
        render = SessionRender(session, out, backend=backend, steps_per_frame=steps_per_frame, width=width, mode=mode)
        return VideoExportJob(render, self.parent)

    def cancel(self):
        if self.job is not None:
            self.job.cancel()

    def _export_done(self, path, message):
        self.last_message = message
        if self.progress is not None:
            self.progress.canceled.disconnect()
            self.progress.close()
            self.progress = None
        self.job = None
        self.status.showMessage(message, 10000)
        if path is None and "cancelled" not in message:
            QMessageBox.warning(self.parent, "Could not render the video", message)

    # --- the live window ----------------------------------------------------------------------
    def toggle_live(self, _=None):
        if self.live is None:
            out, _ = QFileDialog.getSaveFileName(self.parent, "Record the window to a video", "feelflow.mp4", VIDEO_FILTER)
            if out:
                self.start_live(out, force=True)
        else:
            self.stop_live()
        self.events.videoRecording.emit(self.live is not None)

    def start_live(self, out, force: bool = False) -> bool:
        from feelflow.app.files import check_output
        from feelflow.app.gui.video_export import LiveRecorder

        def make():
            check_output(out, "video", force=force, hint="choose another name")
            return LiveRecorder(self.viewport, out, LIVE_FPS)
        live = attempt(self.parent, make, "Could not record a video")
        if live is None:
            return False
        self.live = live
        self.timer.start()
        self._grab()
        self.label.show()
        return True

    def _grab(self):
        live = self.live
        if live is None:
            return
        try:
            live.add_frame()
        except (OSError, ValueError) as exc:
            self.timer.stop()
            self.live = None
            live.cancel()
            self.label.hide()
            QMessageBox.warning(self.parent, "The video recording stopped", str(exc).splitlines()[0])
            return
        self.label.setText(f"\u25cf Recording video: {live.seconds:.1f} s, {live.frames} frames "
                           f"(File > Record video of the window stops it)")

    def stop_live(self):
        """Stop recording the window and write the video; returns its path (None if none)."""
        live, self.live = self.live, None
        self.timer.stop()
        self.label.hide()
        if live is None:
            return None
        path = attempt(self.parent, live.stop, "Could not write the video")
        if path is not None:
            self.last_message = f"Wrote {path}: {live.frames} frames, {live.seconds:.1f} s."
            self.status.showMessage(self.last_message, 10000)
        return path

    def close(self):
        """The window closes: a running export is cancelled, a live recording is written."""
        self.cancel()
        if self.live is not None:
            self.stop_live()
