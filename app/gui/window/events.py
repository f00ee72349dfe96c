"""What one controller tells the others: Qt signals on one object, `window.events`, in the way
napari's evented models announce their changes. The controller where a change happens emits;
each controller that has to follow connects its own handler in its constructor, so no
controller calls another's methods to keep it in step.

| signal | emitted by | who follows |
| --- | --- | --- |
| `liveCreated(sim)` | MainWindow, once the live tunnel exists (it needs the GL context) | every controller that reads or changes the live tunnel keeps it (`self.sim`) |
| `replayStarted` | ReplayController, before the replay takes over | bodies (editing ends, a drag is cancelled), inputs (the body is let go, a device's force fades), the frame loop (runs at full rate) |
| `replayStopped(paused)` | ReplayController, back on the live tunnel | inputs (a device as the live tunnel's pause says), the frame loop (its pace), flow (the panel shows the live parameters again) |
| `flowChanged` | FlowController (`after_rebuild`, `reset`), for every controller that changed the tunnel | inputs (the device's workspace), the frame loop (the field, the readouts, a redraw) |
| `liveFrame(forces)` | FrameLoop, after each live frame | inputs (the device's target in, its force out), the replay controller (a recording that filled up) |
| `livePaused(paused)` | FrameLoop, when the live tunnel pauses or runs | inputs (a device's force fades out or comes back) |
| `pauseShown(checked)` | FrameLoop | the Pause action's check mark (menus.py) |
| `guardActed` | FrameLoop, when the local stability guard changed the flow | flow (the status bar says so, the panel shows the viscosity, `flowChanged`) |
| `resetAsked` | FrameLoop's unstable-flow dialog | flow (Reset flow) |
| `fieldShown(field)` | FrameLoop, each frame: the (ny, nx, 4) field, or a callable that reads it back | probes (each samples it) |
| `replayTick` | FrameLoop, at each replay frame | inputs (a device moved during the replay is told it does not move the body) |
| `replayProgressed` | FrameLoop, after a replay frame or its pause | the replay controller (its progress label and banner) |
| `replayFailed(message)` | FrameLoop, when the session asks for something impossible | the replay controller (stops it, one-line dialog) |
| `videoRecording(on)` | VideoController, when the window's recording starts or stops | the Record video action's check mark (menus.py) |
| `probesPlacing(on)` | ProbeController, when clicks start or stop placing probes | the Place probes action's check mark (menus.py) |
| `recordShown(on)`, `recordLabel(text)` | ReplayController, as a recording starts, fills up or stops | the Record session action's check mark and text (menus.py) |
| `replayShown(on)` | ReplayController, once a replay shows or the live tunnel is back | the replay's toolbar, Stop replay, Undo and Redo (menus.py) |
| `replayRefused` | ReplayController.refuse, a request refused during a replay | inputs (the selector back at what drives the body) |
| `shownChanged(model)` | ReplayController, MainWindow once the live tunnel exists | the frame loop: the viewport and the plot show `model` (a TunnelModel) |
"""
from __future__ import annotations

from PySide6.QtCore import QObject, Signal


class WindowEvents(QObject):
    """The window's events (module docstring)."""

    liveCreated = Signal(object)     # the live Simulation, once it exists
    replayStarted = Signal()
    replayStopped = Signal(bool)     # whether the live tunnel is paused
    shownChanged = Signal(object)    # the TunnelModel drawn now
    flowChanged = Signal()           # the live tunnel changed (rebuilt, reset, a lesson or an exercise)
    liveFrame = Signal(object)       # a live frame's forces {model: (fx, fy)}
    livePaused = Signal(bool)        # the live tunnel paused (True) or runs
    pauseShown = Signal(bool)        # the Pause action's check mark
    guardActed = Signal()            # the local stability guard changed the flow
    resetAsked = Signal()            # the unstable-flow dialog asks for Reset flow
    fieldShown = Signal(object)      # this frame's field, or a callable that reads it back
    replayTick = Signal()            # a replay frame begins
    replayProgressed = Signal()      # a replay frame or pause: its progress changed
    replayFailed = Signal(str)       # the replayed session asked for something impossible
    videoRecording = Signal(bool)    # the window is being recorded to a video
    probesPlacing = Signal(bool)     # clicks in the view place probes
    recordShown = Signal(bool)       # a session is being recorded
    recordLabel = Signal(str)        # the Record session entry's words
    replayShown = Signal(bool)       # a replay shows (True) or the live tunnel again
    replayRefused = Signal()         # a request was refused during a replay: the controls go back
