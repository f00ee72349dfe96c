"""Video files from frames: MP4 (H.264) and animated GIF, encoded by PyAV (FFmpeg's libraries,
shipped inside PyAV's wheel: no system ffmpeg is needed).

`VideoWriter(path, fps)` takes (height, width, 3) uint8 RGB frames, all of one size. MP4 is
H.264 in yuv420p (what slides and browsers play; the frame is padded by one row or column to
even sizes, which yuv420p needs). GIF gets a palette made for each frame by FFmpeg's
palettegen/paletteuse filters (a GIF holds 256 colours a frame; one palette per frame keeps the
colour maps' gradients smooth). The file is written through app/files.py: into a temporary file
beside the target that replaces it only when `finish` succeeds; `cancel`, or an error, leaves
the target as it was.

Qt-free: the window (app/gui/video_export.py) and `feelflow session render` both use it.
"""
from __future__ import annotations

import fractions
import pathlib
from contextlib import ExitStack

import numpy as np

from feelflow.app.errors import UserError

#: file suffix -> (container format, codec)
FORMATS = {".mp4": ("mp4", "libx264"), ".gif": ("gif", "gif")}
#: H.264 quality: constant rate factor (18 - 28 is the usual range; lower is better and larger)
MP4_CRF = "20"


def video_format(path) -> str:
    """The container for `path`'s suffix ('mp4' or 'gif'); UserError for any other suffix."""
    suffix = pathlib.Path(path).suffix.lower()
    if suffix not in FORMATS:
        raise UserError(f"{path}: a video is written as .mp4 or .gif, not {suffix or 'a file without a suffix'!r}")
    return FORMATS[suffix][0]


class VideoWriter:
    """Encode frames into `path` (.mp4 or .gif) at `fps` frames per second."""

    def __init__(self, path, fps: float = 25.0):
        import av

        from feelflow.app.files import atomic_path

        self.path = pathlib.Path(path)
        self.format = video_format(path)
        self.fps = fps
        self.frames = 0
        self._size = None
        self._graph = None
        self._stack = ExitStack()
        self._tmp = self._stack.enter_context(atomic_path(self.path))
        self._container = av.open(str(self._tmp), "w", format=self.format)
        self._rate = fractions.Fraction(fps).limit_denominator(1000)
        self._stream = None

    # --- frames -------------------------------------------------------------------------------
    def _open_stream(self, width: int, height: int):
        import av

        codec = FORMATS["." + self.format][1]
        stream = self._container.add_stream(codec, rate=self._rate)
        if self.format == "mp4":
            width, height = width + width % 2, height + height % 2
            stream.pix_fmt = "yuv420p"
            stream.options = {"crf": MP4_CRF, "preset": "veryfast"}
        else:
            stream.pix_fmt = "pal8"
            g = av.filter.Graph()
            src = g.add_buffer(width=width, height=height, format="rgb24", time_base=1 / self._rate)
            split = g.add("split")
            palette = g.add("palettegen", "stats_mode=single:reserve_transparent=0")
            use = g.add("paletteuse", "new=1:dither=bayer:bayer_scale=3")
            sink = g.add("buffersink")
            src.link_to(split)
            split.link_to(use, 0, 0)
            split.link_to(palette, 1, 0)
            palette.link_to(use, 0, 1)
            use.link_to(sink)
            g.configure()
            self._graph = g
        stream.width, stream.height = width, height
        self._stream = stream
        self._size = (height, width)

    def add(self, rgb: np.ndarray) -> None:
        """Append one frame, (height, width, 3) uint8 RGB (the first frame fixes the size)."""
        import av

        rgb = np.ascontiguousarray(rgb, dtype=np.uint8)
        if rgb.ndim != 3 or rgb.shape[2] != 3:
            raise ValueError(f"a video frame is (height, width, 3) RGB, got shape {rgb.shape}")
        if self._stream is None:
            self._open_stream(rgb.shape[1], rgb.shape[0])
        h, w = self._size
        if rgb.shape[:2] != (h, w):
            if self.format == "mp4" and rgb.shape[0] <= h and rgb.shape[1] <= w:
                rgb = np.pad(rgb, ((0, h - rgb.shape[0]), (0, w - rgb.shape[1]), (0, 0)), mode="edge")
            else:
                raise ValueError(f"frame {self.frames + 1} is {rgb.shape[1]} x {rgb.shape[0]}, the video {w} x {h}")
        frame = av.VideoFrame.from_ndarray(rgb, format="rgb24")
        frame.pts = self.frames
        frame.time_base = 1 / self._rate
        self.frames += 1
        if self._graph is None:
            self._mux(self._stream.encode(frame))
            return
        self._graph.push(frame)
        self._pull()

    def _pull(self):
        import av

        while True:
            try:
                out = self._graph.pull()
            except (av.BlockingIOError, av.EOFError):
                return
            self._mux(self._stream.encode(out))

    def _mux(self, packets):
        for p in packets:
            self._container.mux(p)

    # --- the end ------------------------------------------------------------------------------
    def finish(self) -> pathlib.Path:
        """Flush the encoder and put the file in place; returns its path."""
        if self.frames == 0:
            self.cancel()
            raise UserError(f"{self.path}: no frames to write")
        if self._graph is not None:
            self._graph.push(None)
            self._pull()
        self._mux(self._stream.encode())
        self._container.close()
        self._stack.close()    # atomic_path: the temporary file replaces the target
        return self.path

    def cancel(self) -> None:
        """Stop without writing: the target is left as it was."""
        try:
            self._container.close()
        except Exception:  # noqa: BLE001 - a half-written container has nothing worth saving
            pass
        self._stack.__exit__(RuntimeError, RuntimeError("cancelled"), None)

    def __enter__(self):
        return self

    def __exit__(self, kind, value, tb):
        if kind is None:
            return False
        self.cancel()
        return False


def count_frames(path) -> int:
    """How many frames the video file at `path` decodes to (tests, and a check after writing)."""
    import av

    with av.open(str(path)) as container:
        return sum(1 for _ in container.decode(video=0))
