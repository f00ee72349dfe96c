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
