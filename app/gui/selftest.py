"""`feelflow --selftest`: open the real window, run the default scene, drag the body with
synthetic mouse events, switch shape and force model, save a screenshot, print frames per
second and solver steps per second; exit 0 only if everything worked (non-blank field, body
moved, plot has data); with `--frame-profile`, where the measured frames' time went
(app/gui/frame_profile.py). `feelflow --selftest gui SESSION` measures the window's replay of SESSION
instead: frames per second and session steps per second while it replays."""
from __future__ import annotations

import math
import sys
import time

import numpy as np
from PySide6.QtCore import QEvent, QPointF, Qt, QTimer
from PySide6.QtGui import QMouseEvent
from PySide6.QtWidgets import QApplication


def send_mouse(widget, kind, pos: QPointF, button=Qt.LeftButton, modifiers=Qt.NoModifier):
    """Deliver a synthetic mouse event to `widget` (what a real press/move/release does);
    "hover" is a move with no button held."""
    types = {"press": QEvent.MouseButtonPress, "move": QEvent.MouseMove, "hover": QEvent.MouseMove,
             "release": QEvent.MouseButtonRelease}
    buttons = Qt.NoButton if kind in ("release", "hover") else button
    ev = QMouseEvent(types[kind], pos, widget.mapToGlobal(pos), Qt.NoButton if kind in ("move", "hover") else button,
                     buttons, modifiers)
    QApplication.sendEvent(widget, ev)


def drag_body(window, dx_cells: float, dy_cells: float, moves: int = 10, hold_ticks: int = 0):
    """Press on the body centre, drag by (dx, dy) cells in `moves` moves and keep holding for
    `hold_ticks` more; a generator: one mouse event per step."""
    vp, sim = window.viewport, window.sim
    start = vp.to_widget(*sim.pos)
    end = vp.to_widget(sim.pos[0] + dx_cells, sim.pos[1] + dy_cells)
    send_mouse(vp, "press", start)
    for k in range(1, moves + 1):
        yield
        send_mouse(vp, "move", start + (end - start) * (k / moves))
    for _ in range(hold_ticks + 1):
        yield
    send_mouse(vp, "release", end)


def field_is_alive(window) -> tuple[bool, str]:
    """Non-blank: finite everywhere and the speed varies across the tunnel."""
    sim = window.sim
    if window.backend == "gl":
        nx, ny = sim.config.nx, sim.config.ny
        window.make_current()
        f = np.frombuffer(sim.field_texture().read(), np.float32).reshape(ny, nx, 4)
    else:
        f = sim.field_rgba()
    if not np.isfinite(f).all():
        return False, "the field has non-finite values"
    speed = np.hypot(f[..., 1], f[..., 2])
    if speed.std() < 1e-4 or speed.max() < 1e-3:
        return False, f"the field is blank (speed max {speed.max():.2g}, std {speed.std():.2g})"
    return True, f"speed max {speed.max():.3f}"


class SelfTest:
    """Drives the window from a timer; `exit_code` is set when the application quits."""

    def __init__(self, window, seconds: float = 8.0, screenshot: str | None = None, out=sys.stdout,
                 replay: bool = False, frame_profile: bool = False, lesson: str | None = None,
                 plot_view: str | None = None):
        self.window, self.seconds, self.screenshot, self.out = window, max(4.0, seconds), screenshot, out
        self.lesson, self.plot_view = lesson, plot_view   # --lesson: run a lesson for the screenshot
        self.replay = replay   # the window replays a session (feelflow --selftest gui SESSION): measure that
        self.profile = None    # a FrameProfile over the measured frames (--frame-profile), or None
        if frame_profile and not replay:
            from feelflow.app.gui.frame_profile import FrameProfile

            self.profile = FrameProfile()
        self.exit_code = 1
        self.failures = []
        self.results = {}
        self._gen = self._script()
        self._timer = QTimer()
        self._timer.setInterval(50)
        self._timer.timeout.connect(self._next)
        self._timer.start()
        self._deadline = time.monotonic() + self.seconds + 60

    def _next(self):
        try:
            next(self._gen)
        except StopIteration:
            self._finish()
        except Exception as exc:  # a broken selftest must still end and say why
            self.failures.append(f"selftest error: {type(exc).__name__}: {exc}")
            self._finish()
        if time.monotonic() > self._deadline:
            self.failures.append("selftest timed out")
            self._finish()

    def _wait(self, seconds):
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            yield

    def _script(self):
        w = self.window
        while w.sim is None:
            yield
        if self.replay:
            yield from self._replay_script()
            return
        if self.lesson is not None:
            yield from self._lesson_script()
            return
        yield from self._measure_frames()
        sim = w.sim
        ok, why = field_is_alive(w)
        if not ok:
            self.failures.append(why)

        # drag the body 40 cells downstream and 12 up
        before = sim.pos
        yield from drag_body(w, 40, 12, hold_ticks=int(0.25 * self.seconds / 0.05))
        yield from self._wait(0.5)
        moved = math.hypot(sim.pos[0] - before[0], sim.pos[1] - before[1])
        self.results["body_moved_cells"] = moved
        if moved < 5:
            self.failures.append(f"the body moved only {moved:.1f} cells when dragged")

        # switch shape and force model through the panel, as a user would
        panel = w.panel
        panel.shape.setCurrentIndex(panel.shape.findData("plate"))
        if sim.params.shape != "plate":
            self.failures.append("switching the shape in the panel did not change the body")
        panel.model.setCurrentIndex(panel.model.findData("pressure"))
        if sim.params.force_model != "pressure":
            self.failures.append("switching the force model in the panel did not change the model")
        n0 = len(sim.history)
        yield from self._wait(0.2 * self.seconds)
        _, drag, _ = sim.history.drag_lift("pressure")
        fresh = drag[n0:]
        if len(fresh) == 0 or not np.isfinite(fresh).any():
            self.failures.append("the plot got no data from the pressure model")
        w.loop.readouts.refresh()
        self._save_screenshot()

    def _measure_frames(self):
        """After a second's warm-up (shader compile, adaptive stepping), frames and solver steps
        per second over 0.45 `seconds` (with `--frame-profile`, where those frames' time went)."""
        w = self.window
        yield from self._wait(1.0)
        sim = w.sim
        if self.profile is not None:
            self.profile.attach(w)
        s0, f0, t0 = sim.solver.time, w.viewport.frames, time.perf_counter()
        yield from self._wait(0.45 * self.seconds)
        dt = time.perf_counter() - t0
        if self.profile is not None:
            self.profile.detach()
        steps, frames = sim.solver.time - s0, w.viewport.frames - f0
        nodes = sim.config.nx * sim.config.ny
        self.results.update(grid=f"{sim.config.nx}x{sim.config.ny}", fps=frames / dt, steps_per_s=steps / dt,
                            mlups=steps * nodes / dt / 1e6, steps_per_frame=steps / max(1, frames),
                            step_ms=1e3 * w.loop.step_cost, rest_of_frame_ms=1e3 * w.loop.other_cost)

    def _lesson_script(self):
        """Run a lesson for `seconds` (its frames and steps per second measured as the default
        scene's are), show the plot view asked for, check the plot has data from the flow, save
        the screenshot (how docs/guide's lesson screenshots are made)."""
        w = self.window
        if not w.lessons.apply(self.lesson):
            self.failures.append(f"the lesson {self.lesson} did not start")
            return
        sim = w.sim
        start = time.monotonic()
        yield from self._measure_frames()
        yield from self._wait(self.seconds - (time.monotonic() - start))
        if self.plot_view is not None:
            index = w.plot.view.findData(self.plot_view)
            if index < 0:
                self.failures.append(f"the plot has no view {self.plot_view!r}")
                return
            w.plot.view.setCurrentIndex(index)
            yield from self._wait(1.5)
        w.loop.readouts.refresh()
        w.plot.refresh(force=True)
        self.results["grid"] = f"{sim.config.nx}x{sim.config.ny}"
        polar = sim.polar
        if polar is not None:
            self.results["polar_points"] = len(polar.sweep.points)
        if len(sim.history) == 0:
            self.failures.append("the plot got no data")
        self._save_screenshot()

    def _replay_script(self):
        """The replay's frame rate and steps per second, and that it moves on."""
        w = self.window
        while w.replays.replay is None:
            yield
        yield from self._wait(1.0)
        r = w.replays.replay
        self.results["grid"] = f"{r.config.nx}x{r.config.ny}"
        for split in (False, True):   # rows whole, then long rows in parts
            r.split_rows = split
            yield from self._wait(0.5)
            s0, f0, t0 = r.step, w.viewport.frames, time.perf_counter()
            yield from self._wait(0.3 * self.seconds)
            dt = time.perf_counter() - t0
            steps, frames = r.step - s0, w.viewport.frames - f0
            self.results.setdefault("replay", []).append(
                (split, frames / dt, steps / dt, steps / max(1, frames)))
            if steps <= 0 and not r.done:
                self.failures.append("the replay did not move on")
        self.results.update(replay_rows=len(r.player.rows), replay_step=r.step, replay_total=r.player.total_steps)
        self._save_screenshot()

    def _save_screenshot(self):
        if self.screenshot:
            self.window.exports.save_screenshot(self.screenshot)
            self.results["screenshot"] = self.screenshot

    def _finish(self):
        if not self._timer.isActive():
            return
        self._timer.stop()
        r = self.results
        print(f"selftest: renderer {self.window.viewport.renderer()}, solver backend {self.window.backend}, "
              f"grid {r.get('grid', '?')}", file=self.out)
        if "fps" in r:
            print(f"selftest: {r['fps']:.1f} frames/s, {r['steps_per_s']:.0f} solver steps/s "
                  f"({r['mlups']:.1f} MLUPS, {r['steps_per_frame']:.1f} steps/frame)", file=self.out)
            print(f"selftest: frame budget: {r['step_ms']:.2f} ms per solver step, "
                  f"{r['rest_of_frame_ms']:.1f} ms per frame for everything else (drawing, Qt)", file=self.out)
        if self.profile is not None and self.profile.frames:
            for line in self.profile.report(self.window.viewport.renderer(), self.window.backend, r.get("grid", "?")):
                print(line, file=self.out)
        for split, fps, steps_s, per_frame in r.get("replay", []):
            print(f"selftest: replay, {'long rows in parts' if split else 'rows whole'}: {fps:.1f} frames/s, "
                  f"{steps_s:.0f} session steps/s ({per_frame:.1f} steps/frame)", file=self.out)
        if "replay_step" in r:
            print(f"selftest: replay at step {r['replay_step']} of {r['replay_total']}, "
                  f"{r['replay_rows']} force rows replayed", file=self.out)
        if "polar_points" in r:
            print(f"selftest: the polar has {r['polar_points']} settled angles", file=self.out)
        if "body_moved_cells" in r:
            print(f"selftest: body moved {r['body_moved_cells']:.1f} cells when dragged", file=self.out)
        if "screenshot" in r:
            print(f"selftest: screenshot saved to {r['screenshot']}", file=self.out)
        for f in self.failures:
            print(f"selftest: FAILED: {f}", file=self.out)
        self.exit_code = 0 if not self.failures else 1
        print("selftest: ok" if self.exit_code == 0 else "selftest: failed", file=self.out)
        self.window.close()
        QApplication.instance().quit()
