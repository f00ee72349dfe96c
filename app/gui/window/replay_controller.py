"""Recording a session of the live tunnel, and replaying a recorded one in the window.

While a session replays, an `feelflow.app.model.replay_simulation.ReplaySimulation` takes the
live simulation's place in the viewport and the plot (both are `TunnelModel`s,
app/model/tunnel.py) at the same steps-per-frame budget; the live one waits untouched, and Stop
replay (Esc) brings it back as it was. Requests that would change the live tunnel meanwhile
are refused with one status-bar sentence (`refuse`).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtWidgets import QFileDialog, QLabel, QMessageBox

from feelflow.app.gui.window.dialogs import attempt
from feelflow.app.model.display_units import choice_to_dict

if TYPE_CHECKING:
    from collections.abc import Callable

    from PySide6.QtWidgets import QStatusBar, QWidget

    from feelflow.app.gui.side_panel import SidePanel
    from feelflow.app.gui.viewport import Viewport
    from feelflow.app.gui.window.events import WindowEvents
    from feelflow.app.gui.window.frame_loop import FrameLoop
    from feelflow.app.gui.window.probes import ProbeController
    from feelflow.app.gui.window.units import UnitsController
    from feelflow.app.model.replay_simulation import ReplaySimulation
    from feelflow.app.model.simulation import Simulation
    from feelflow.app.model.tunnel import TunnelModel


class ReplayController:
    """Owns the replay (None while the live tunnel shows) and its status-bar label."""

    def __init__(self, events: "WindowEvents", viewport: "Viewport", loop: "FrameLoop", panel: "SidePanel",
                 probes: "ProbeController", units: "UnitsController", status: "QStatusBar",
                 make_current: "Callable[[], None]", backend: "Callable[[], str]", parent: "QWidget"):
        """`probes`, `units`: what a saved session carries besides the flow; `backend`: the
        window's solver backend now (a replay runs on it); `parent`: the dialogs' parent."""
        self.events, self.viewport, self.loop, self.panel = events, viewport, loop, panel
        self.probes, self.units, self.status, self.make_current = probes, units, status, make_current
        self.backend, self.parent = backend, parent
        self.sim: "Simulation | None" = None   # the live tunnel, once it exists (events.liveCreated)
        events.liveCreated.connect(self._live_created)
        events.liveFrame.connect(lambda _forces: self.watch_recording())
        events.replayProgressed.connect(self.show_progress)
        events.replayFailed.connect(self._failed)
        self.replay: ReplaySimulation | None = None
        self.label = QLabel()   # "Replaying <name>: step N / M" (hidden by passing messages)
        status.addWidget(self.label, 1)
        self.label.hide()
        self._full_said = False   # the recording's stop at the session bound has been shown

    def _live_created(self, sim):
        self.sim = sim

    @property
    def shown(self) -> "TunnelModel | None":
        """What the viewport and the plot show: the replay while one runs, else the live tunnel."""
        return self.replay if self.replay is not None else self.sim

    # --- recording ----------------------------------------------------------------------------
    def toggle_recording(self, _=None):
        if self.sim is None:
            return
        solver = self.sim.solver
        if self.refuse("recording is for the live tunnel"):
            self.events.recordShown.emit(solver.recorder is not None)
            return
        if solver.recorder is None:
            solver.start_recording(renderer=self.viewport.renderer())
            self._full_said = False
            self.events.recordShown.emit(True)
            self.status.showMessage("Recording a session: inputs, parameter changes and forces.", 5000)
            return
        self.events.recordShown.emit(False)
        self.events.recordLabel.emit("Record session")
        recorder = solver.stop_recording()
        path, _ = QFileDialog.getSaveFileName(self.parent, "Save session", "lesson.ffsession", "Sessions (*.ffsession)")
        if path:
            recorder.probes = self.probes.session_arrays()   # the probes placed while it recorded, if any
            recorder.units = choice_to_dict(self.units.choice)   # the units shown (View > Units)
            attempt(self.parent, lambda: recorder.save(path), "Could not save the session")

    def watch_recording(self):
        """After each live frame: once the recording stopped at the most a session file may hold
        (SessionRecorder.full), say so in the status bar and on the Record action until it is
        saved; the tunnel runs on."""
        rec = self.sim.solver.recorder if self.sim is not None else None
        if rec is None or rec.full is None or self._full_said:
            return
        self._full_said = True
        self.events.recordLabel.emit("Record session (full: choose to stop and save)")
        self.status.showMessage(f"Session: {rec.full}. Choose File > Record session to save it.")

    # --- replaying ----------------------------------------------------------------------------
    def open_dialog(self, _=None):
        if self.sim is None:
            return
        path, _ = QFileDialog.getOpenFileName(self.parent, "Replay session", "", "Sessions (*.ffsession)")
        if path:
            self.start(path)

    def start(self, path) -> bool:
        """Replay the session file at `path` in the window; a bad file is a one-line dialog and
        changes nothing. The live tunnel waits, untouched, until `stop`."""
        if self.sim is None:
            return False
        if self.sim.solver.recorder is not None:
            QMessageBox.warning(self.parent, "Could not replay the session",
                                "A session is being recorded: stop the recording (File > Record session) first.")
            return False
        replay = attempt(self.parent, lambda: self._open(path), "Could not replay the session")
        if replay is None:
            return False
        if self.replay is not None:
            self.stop()
        self.events.replayStarted.emit()   # before the replay takes over: editing ends, the body is let go
        self.replay = replay
        self.events.shownChanged.emit(replay)
        self.events.replayShown.emit(True)   # the replay's toolbar; undo and redo off
        self.status.clearMessage()   # a passing message (the mouse hint) would be drawn over the label
        self.label.show()
        self.show_progress()
        return True

    def _open(self, path):
        """A ReplaySimulation of the file on the window's backend; SessionError (one line)."""
        from feelflow.app.model.replay_simulation import ReplaySimulation
        from feelflow.app.sessions import load_session
        from feelflow.app.sessions.replay import check_replay_memory

        session = load_session(path)
        check_replay_memory(session, path)   # before any grid is allocated
        self.make_current()
        return ReplaySimulation(session, self.backend(), ctx=self.viewport.ctx)

    def stop(self, _=None):
        """Back to the live tunnel exactly as it was when the replay began."""
        replay, self.replay = self.replay, None
        if replay is None:
            return
        self.make_current()
        self.events.shownChanged.emit(self.sim)
        replay.close()
        self.viewport.banner = None
        self.label.hide()
        self.events.replayShown.emit(False)
        self.events.replayStopped.emit(self.loop.paused)
        self.status.showMessage("Replay stopped: back to the live tunnel.", 4000)

    def _failed(self, message: str):
        """The session asked for something impossible: back to the live tunnel, one line."""
        self.stop()
        QMessageBox.warning(self.parent, "Could not replay the session", message)

    def close(self):
        """The window closes: the replay's solver goes with it."""
        if self.replay is not None:
            self.make_current()
            self.replay.close()

    def show_progress(self):
        r = self.replay
        if r is None:
            return
        where = f"step {r.step} / {r.total_steps}"
        if r.done:
            text = f"Replay of {r.name} finished at {where}: Stop replay (Esc) returns to the live tunnel."
            self.viewport.banner = f"replay finished ({where})"
        else:
            text = f"Replaying {r.name}: {where}" + (" (paused: space to run)" if r.paused else "")
            self.viewport.banner = f"replay: {where}" + (", paused" if r.paused else "")
        if r.player.diverged_at is not None:
            text += f"; the flow diverged at step {r.player.diverged_at}"
        self.label.setText(text)

    def refuse(self, why: str) -> bool:
        """During a replay: say in the status bar why a request is refused, put the controls back
        as they were and return True; otherwise False."""
        r = self.replay
        if r is None:
            return False
        self.status.showMessage(f"Replaying {r.name}: {why}. Stop replay (Esc) to return to the live tunnel.",
                                  6000)
        p = self.panel
        if self.sim is not None:
            p.show_params(self.sim.params, self.loop.display.mode)
            for box, on in ((p.hold_still, self.sim.hold_still), (p.edit, self.viewport.editing)):
                box.blockSignals(True)
                box.setChecked(on)
                box.blockSignals(False)
        self.events.replayRefused.emit()   # the input selector back at what drives the body
        return True
