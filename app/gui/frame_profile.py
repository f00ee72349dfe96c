"""Where a window frame's time goes (`feelflow --selftest --frame-profile`).

`FrameProfile.attach(window)` wraps, on the running window's own objects (instance attributes,
so nothing else changes and nothing is timed when no profile is attached), the calls a frame
makes: the solver's steps, the force models, the physical-range check, the body's moves, the
field for drawing, the viewport's GL draw and its QPainter overlay, the readouts and the force
plot (its refresh and its paint), and the top-level window's update (Qt's compositing of the
widgets into the window). Each part is timed with `time.perf_counter`, exclusive of the parts
nested in it; `detach()` restores the objects and `report()` gives per-frame means and shares
of the wall time. "Rest" is the wall time no part measured: Qt's event loop, the other
widgets, the self-test's own timer.

On the gl backend the solver's steps include the read-back at the end of each block of steps
(solver/gl_backend.py), which waits for llvmpipe to run the queued steps: that wait is the
steps' own time.
"""
from __future__ import annotations

import math
import os
import time

from PySide6.QtCore import QEvent

#: part key -> the label the report prints, in the report's order
PARTS = {
    "steps": "solver steps",
    "forces": "force models (evaluate)",
    "moves": "body moves (raster, upload)",
    "check": "physical-range check",
    "field": "field for drawing",
    "loop": "frame loop, other",
    "draw": "viewport GL draw, read-back",
    "overlay": "viewport overlay (QPainter)",
    "readouts": "panel readouts",
    "plot_data": "force plot refresh (pyqtgraph)",
    "plot_paint": "force plot paint (pyqtgraph)",
    "compose": "Qt compositing (window update)",
}


class FrameProfile:
    """Exclusive wall time per part over the frames between `attach` and `detach`."""

    def __init__(self):
        self.totals = dict.fromkeys(PARTS, 0.0)
        self.calls = dict.fromkeys(PARTS, 0)
        self._stack: list[list] = []   # [part, start, time of nested parts]
        self._undo: list = []
        self._slots: list = []
        self.frames = 0
        self.steps = 0
        self.wall = 0.0
        self._t0 = None
        self.window = None

    # --- timing ---------------------------------------------------------------------------
    def _timed(self, part: str, fn, only=None):
        """`fn` timed as `part` (when `only(args)` says so, if given)."""
        stack, totals, calls = self._stack, self.totals, self.calls

        def wrapper(*args, **kwargs):
            if only is not None and not only(*args):
                return fn(*args, **kwargs)
            frame = [part, time.perf_counter(), 0.0]
            stack.append(frame)
            try:
                return fn(*args, **kwargs)
            finally:
                stack.pop()
                spent = time.perf_counter() - frame[1]
                totals[part] += spent - frame[2]
                calls[part] += 1
                if stack:
                    stack[-1][2] += spent
        return wrapper

    def _wrap(self, obj, name: str, part: str, only=None):
        """Time `obj.name` (public names only: a rename fails here, loudly, not a silent skip)."""
        had = name in getattr(obj, "__dict__", {})
        old = obj.__dict__[name] if had else None
        setattr(obj, name, self._timed(part, getattr(obj, name), only))
        self._undo.append((obj, name, had, old))

    def _wrap_slot(self, signal, slot, part: str):
        """A timer's slot (connected as a bound method, so not reached through the instance)."""
        timed = self._timed(part, slot)
        signal.disconnect(slot)
        signal.connect(timed)
        self._slots.append((signal, slot, timed))

    def attach(self, window) -> None:
        """Start timing the running window's frames (the live tunnel, its current solver)."""
        self.window = window
        sim, loop, vp, plot = window.sim, window.loop, window.viewport, window.plot
        session = sim.solver                  # the SessionSolver
        backend = session.solver              # the backend it drives
        self._wrap(backend, "step", "steps")
        for model in backend.force_models.values():
            self._wrap(model, "evaluate", "forces")
        self._wrap(backend, "check_physical", "check")
        self._wrap(session, "set_body", "moves")
        self._wrap_slot(loop.timer.timeout, loop.tick, "loop")
        self._wrap_slot(loop.slow_timer.timeout, loop.readouts.refresh, "readouts")
        self._wrap(loop.display, "upload_field", "field")
        self._wrap(loop.readouts, "refresh", "readouts")
        self._wrap(vp, "field_image", "draw")
        self._wrap(vp.overlay, "paint", "overlay")
        self._wrap(plot, "refresh", "plot_data")
        self._wrap(plot.plot, "paintEvent", "plot_paint")
        self._wrap(window, "event", "compose", only=lambda ev: ev.type() == QEvent.UpdateRequest)
        self._frames0 = vp.frames
        self._steps0 = sim.solver.time
        self._t0 = time.perf_counter()

    def detach(self) -> None:
        """Stop timing; the window's objects are as they were."""
        if self._t0 is None:
            return
        self.wall = time.perf_counter() - self._t0
        w = self.window
        self.frames = w.viewport.frames - self._frames0
        self.steps = w.sim.solver.time - self._steps0
        for obj, name, had, old in reversed(self._undo):
            if had:
                setattr(obj, name, old)
            else:
                delattr(obj, name)
        self._undo.clear()
        for signal, slot, timed in self._slots:
            signal.disconnect(timed)
            signal.connect(slot)
        self._slots.clear()
        self._t0 = None

    # --- the report -----------------------------------------------------------------------
    def rows(self) -> list[tuple[str, float, float, float]]:
        """(label, mean ms per frame, share of the wall time, calls per frame), the measured
        parts then "rest" (its calls: nan)."""
        frames, wall = max(1, self.frames), max(self.wall, 1e-9)
        out = [(PARTS[k], 1e3 * v / frames, v / wall, self.calls[k] / frames) for k, v in self.totals.items()]
        rest = max(0.0, wall - sum(self.totals.values()))
        out.append(("rest (event loop, other widgets)", 1e3 * rest / frames, rest / wall, math.nan))
        return out

    def report(self, renderer: str, backend: str, grid: str) -> list[str]:
        from feelflow.app.machine import cpu_name

        try:
            load = " ".join(f"{v:.2f}" for v in os.getloadavg())
        except OSError:
            load = "?"
        frames, wall = max(1, self.frames), max(self.wall, 1e-9)
        lines = [f"frame profile: {cpu_name()}, {os.cpu_count()} cores, load average {load}",
                 f"frame profile: renderer {renderer}, backend {backend}, grid {grid}",
                 f"frame profile: {self.frames} frames in {self.wall:.2f} s: {self.frames / wall:.1f} frames/s, "
                 f"{self.steps / wall:.0f} solver steps/s, {1e3 * wall / frames:.2f} ms per frame",
                 f"frame profile: {'part':<36} {'ms/frame':>9} {'share':>7} {'calls/frame':>12}"]
        for label, ms, share, calls in self.rows():
            count = "" if math.isnan(calls) else f"{calls:.2f}"
            lines.append(f"frame profile: {label:<36} {ms:9.2f} {100 * share:6.1f}% {count:>12}")
        return lines
