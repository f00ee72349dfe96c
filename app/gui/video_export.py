"""Video of the tunnel: a session replay rendered to MP4 or GIF (headless, `feelflow session
render`, or from the window with a progress bar and Cancel), and the live window recorded.

`FrameRenderer` paints a `TunnelModel` (app/model/tunnel.py) as the viewport draws it, the field
coloured by the numpy canvas (app/gui/cpu_field.py: the same colours as shaders/display.glsl)
and the viewport's own overlay (body, force arrows, colour bar) on top, into a QImage: no window,
no OpenGL, so it runs offscreen (QT_QPA_PLATFORM=offscreen) on any machine. `SessionRender`
replays a session frame by frame into a `feelflow.app.video.VideoWriter` (PyAV), one frame every
`steps_per_frame` solver steps; `LiveRecorder` adds the viewport's picture to a video each time
the window draws a frame.
"""
from __future__ import annotations

import math
import time

import numpy as np
from PySide6.QtCore import QObject, QTimer, Signal
from PySide6.QtGui import QImage

from feelflow.app.gui import cpu_field
from feelflow.app.gui.display_modes import COLOUR_BAR_MARGIN, DISPLAY_MODES
from feelflow.app.model import readouts

#: what a video shows by default, and its width in pixels (the height follows the tunnel)
DEFAULT_MODE = "speed"
DEFAULT_WIDTH = 960
DEFAULT_FPS = 25
#: display modes a rendered video can show (tracers need the window's particle state)
VIDEO_MODES = ("speed", "vorticity", "pressure")


def image_to_rgb(image: QImage) -> np.ndarray:
    """A QImage as a (height, width, 3) uint8 RGB array (a copy)."""
    image = image.convertToFormat(QImage.Format_RGB888)
    w, h, stride = image.width(), image.height(), image.bytesPerLine()
    data = np.frombuffer(image.constBits(), np.uint8, count=stride * h).reshape(h, stride)
    return data[:, :3 * w].reshape(h, w, 3).copy()


class FrameRenderer:
    """Frames of `model` as the window draws it, `width` pixels wide, showing `mode`."""

    def __init__(self, model, width: int = DEFAULT_WIDTH, mode: str = DEFAULT_MODE, arrows: bool = True):
        from feelflow.app.gui.viewport import Viewport

        if mode not in VIDEO_MODES:
            raise ValueError(f"a video shows {', '.join(VIDEO_MODES)}, not {mode!r}")
        self.model = model
        view = Viewport()
        view.setMinimumSize(1, 1)
        view.sim = model
        view.mode = mode
        view.show_arrows = arrows
        nx, ny = model.config.nx, model.config.ny
        field_w = max(16, int(width) - COLOUR_BAR_MARGIN)
        view.resize(field_w + COLOUR_BAR_MARGIN, max(16, int(math.ceil(field_w * ny / nx))))
        self.view = view

    @property
    def size(self) -> tuple[int, int]:
        return self.view.width(), self.view.height()

    def frame(self, forces: dict | None = None) -> np.ndarray:
        """The model's flow now, (height, width, 3) uint8; `forces` ({model: (fx, fy)}) draws
        the drag and lift arrows."""
        model, view = self.model, self.view
        rgba = model.field_rgba()
        if view.mode == "pressure":
            view.rho_ref = readouts.free_stream_density(rgba)
        view.arrow_forces = (readouts.arrows(forces.get(model.params.force_model), model.relative_wind(),
                                             model.reference_length()) if forces else None)
        image = QImage(view.width(), view.height(), QImage.Format_RGB32)
        cpu_field.paint(view, rgba, image)
        return image_to_rgb(image)

    def close(self):
        self.view.deleteLater()


class SessionRender:
    """Render `session` (a loaded Session) into a video at `out`: one frame every
    `steps_per_frame` replayed steps (the replay's first picture included), `fps` frames per
    second. Call `step()` until it returns False (each call replays and draws one frame), then
    `finish()`; `cancel()` stops and leaves `out` as it was."""

    def __init__(self, session, out, *, backend: str | None = None, steps_per_frame: int = 50,
                 fps: float = DEFAULT_FPS, width: int = DEFAULT_WIDTH, mode: str = DEFAULT_MODE,
                 factory=None, ctx=None):
        from feelflow.app.model.replay_simulation import ReplaySimulation
        from feelflow.app.video import VideoWriter, video_format

        video_format(out)   # the suffix first: one line, before any work
        if steps_per_frame < 1:
            raise ValueError("steps_per_frame must be at least 1")
        self.model = ReplaySimulation(session, backend, ctx=ctx, factory=factory)
        self.model.split_rows = True
        self.steps_per_frame = int(steps_per_frame)
        self.renderer = FrameRenderer(self.model, width, mode)
        self.writer = VideoWriter(out, fps)
        self.total_steps = max(1, self.model.total_steps)
        self.frames_expected = 1 + math.ceil(self.model.total_steps / self.steps_per_frame)
        self._forces: dict = {}
        self._started = False
        self.replay_seconds = 0.0   # the solver replaying the session
        self.draw_seconds = 0.0     # colouring the field and painting the overlay
        self.encode_seconds = 0.0   # PyAV

    @property
    def frames(self) -> int:
        return self.writer.frames

    @property
    def fraction(self) -> float:
        return min(1.0, self.model.step / self.total_steps)

    def step(self) -> bool:
        """Replay up to the next frame and add it; False when the session is done."""
        if self._started and self.model.done:
            return False
        t0 = time.perf_counter()
        if self._started:
            target = self.model.step + self.steps_per_frame
            while self.model.step < target and not self.model.done:
                forces = self.model.advance(target - self.model.step)
                if forces:
                    self._forces = forces
        self._started = True
        t1 = time.perf_counter()
        rgb = self.renderer.frame(self._forces)
        t2 = time.perf_counter()
        self.writer.add(rgb)
        self.replay_seconds += t1 - t0
        self.draw_seconds += t2 - t1
        self.encode_seconds += time.perf_counter() - t2
        return not self.model.done

    @property
    def seconds(self) -> float:
        """Replaying, drawing and encoding so far."""
        return self.replay_seconds + self.draw_seconds + self.encode_seconds

    def run(self, progress=None, cancelled=None):
        """Every frame; `progress(fraction)` after each, `cancelled()` True stops (returns
        False, the output untouched). True when the video is written."""
        while True:
            if cancelled is not None and cancelled():
                self.cancel()
                return False
            more = self.step()
            if progress is not None:
                progress(self.fraction)
            if not more:
                break
        self.finish()
        return True

    def finish(self):
        try:
            return self.writer.finish()
        finally:
            self._close()

    def cancel(self):
        self.writer.cancel()
        self._close()

    def _close(self):
        self.renderer.close()
        self.model.close()


class VideoExportJob(QObject):
    """A `SessionRender` driven by a timer in the window's thread (the solver and the painting
    stay where the window's are), a frame a tick, with `progressed(fraction)` and
    `finished(path or None, message)` signals."""

    progressed = Signal(float)
    finished = Signal(object, str)

    def __init__(self, render: SessionRender, parent=None):
        super().__init__(parent)
        self.render = render
        self._timer = QTimer(self)
        self._timer.setInterval(0)
        self._timer.timeout.connect(self._tick)
        self.done = False

    def start(self):
        self._timer.start()

    def cancel(self):
        if self.done:
            return
        self._timer.stop()
        self.render.cancel()
        self.done = True
        self.finished.emit(None, "Video export cancelled; nothing was written.")

    def _tick(self):
        if self.done:
            return
        try:
            more = self.render.step()
            self.progressed.emit(self.render.fraction)   # a modal dialog's setValue may run a Cancel here
            if more or self.done:
                return
            self._timer.stop()
            path = self.render.finish()
        except Exception as exc:  # noqa: BLE001 - one line in a dialog, the output untouched
            self._timer.stop()
            if not self.done:
                self.render.cancel()
            self.done = True
            self.finished.emit(None, f"The video could not be written: {str(exc).splitlines()[0] if str(exc) else exc}")
            return
        self.done = True
        r = self.render
        self.finished.emit(path, f"Wrote {path}: {r.frames} frames, {1000 * r.seconds / max(1, r.frames):.0f} ms a frame.")


class LiveRecorder:
    """The live window recorded: each drawn frame of the viewport (what it shows, overlays
    included) into a video; `stop()` writes it. The frame rate is the window's, measured
    over the recording."""

    def __init__(self, viewport, out, fps: float = DEFAULT_FPS):
        from feelflow.app.video import VideoWriter

        self.viewport = viewport
        self.writer = VideoWriter(out, fps)
        self.started = time.perf_counter()

    @property
    def frames(self) -> int:
        return self.writer.frames

    @property
    def seconds(self) -> float:
        return time.perf_counter() - self.started

    def add_frame(self):
        rgb = image_to_rgb(self.viewport.grabFramebuffer())
        self.writer.add(rgb)

    def stop(self):
        return self.writer.finish()

    def cancel(self):
        self.writer.cancel()


def mode_names() -> dict:
    return {m: DISPLAY_MODES[m].label for m in VIDEO_MODES if m in DISPLAY_MODES}
