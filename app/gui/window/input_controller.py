"""Who moves the body: the mouse or a haptic device, chosen in the side panel's Input box.

Every body input reaches the model the same way, as a `BodyInput` (app/model/body_input.py)
passed to `TunnelModel.drive`: the viewport's drag (its `bodyPulled` signal), the device's
target each frame, and the handle's and the wheel's turns (through the body controller). A
replay's model refuses them all. Esc stops the device's force at once (haptics safety: the
stop key) and any replay.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

from PySide6.QtWidgets import QMessageBox

from feelflow.app.model.body_input import BodyInput

if TYPE_CHECKING:
    from PySide6.QtWidgets import QStatusBar, QWidget

    from feelflow.app.gui.device_input import DeviceInput
    from feelflow.app.gui.side_panel import SidePanel
    from feelflow.app.gui.viewport import Viewport
    from feelflow.app.gui.window.bodies import BodyController
    from feelflow.app.gui.window.events import WindowEvents
    from feelflow.app.gui.window.replay_controller import ReplayController
    from feelflow.app.model.simulation import Simulation

DEVICE_MOVE_CELLS = 3.0   # a device moved this far during a replay is told it does not move the body


class InputController:
    """Owns the haptic device (None while the mouse drives) and routes body input to the model."""

    def __init__(self, events: "WindowEvents", viewport: "Viewport", panel: "SidePanel", replays: "ReplayController",
                 bodies: "BodyController", status: "QStatusBar", parent: "QWidget"):
        """`parent`: the dialogs' and the device's parent."""
        self.viewport, self.panel, self.replays, self.bodies = viewport, panel, replays, bodies
        self.status, self.parent = status, parent
        self.sim: "Simulation | None" = None   # the live tunnel, once it exists (events.liveCreated)
        events.liveCreated.connect(self._live_created)
        events.replayStarted.connect(self.replay_started)
        events.replayStopped.connect(self.replay_stopped)
        events.flowChanged.connect(self.tunnel_changed)
        events.liveFrame.connect(self.after_frame)
        events.livePaused.connect(self.pause)
        events.replayTick.connect(self.watch_during_replay)
        events.replayRefused.connect(self.show_selected)
        self.device: DeviceInput | None = None
        self._device_seen = None     # the device's target when the replay began

    def _live_created(self, sim):
        self.sim = sim

    # --- one way in -----------------------------------------------------------------------------
    def drive(self, request: BodyInput) -> bool:
        """Pass `request` to the model shown (the live tunnel, or a replay that refuses it)."""
        model = self.replays.shown
        return model is not None and model.drive(request)

    def mouse_pulled(self, target):
        """The viewport's drag: pull the body to `target` (x, y), or let go (None)."""
        request = BodyInput.release("mouse") if target is None else BodyInput.pull(*target, source="mouse")
        if not self.drive(request) and target is not None:
            self.replays.refuse("the mouse does not move the body")

    def after_frame(self, forces):
        """After a live frame: the device's position becomes the body's target, and the selected
        force model's force and torque go to the device (lattice units; the loop scales them; a
        torque not computed goes as 0, so that it never zeroes the force as a NaN would)."""
        dev, sim = self.device, self.sim
        if dev is None:
            return
        target = dev.target()
        if target is not None:
            sim.drive(BodyInput.pull(*target, source="device"))
        f = forces.get(sim.params.force_model)
        if f is not None:
            torque = sim.last_torques.get(sim.params.force_model, 0.0)
            dev.submit(f, sim.solver.time, torque if math.isfinite(torque) else 0.0)

    # --- the input selector ---------------------------------------------------------------------
    def refresh_devices(self):
        """Fill the input selector: the mouse, then every device the haptics layer can drive."""
        from feelflow.haptics import list_devices

        panel = self.panel
        box = panel.input
        box.blockSignals(True)
        current = box.currentData()
        box.clear()
        box.addItem("Mouse", "mouse")
        try:
            devices = list_devices()
        except Exception as exc:   # enumeration trouble must not stop the window
            devices = []
            panel.input_note.setText(f"Could not list devices: {exc}")
        for info in devices:
            if info.driver:
                box.addItem(info.name, info.url)
        i = box.findData(current)
        box.setCurrentIndex(max(0, i))
        box.blockSignals(False)

    def show_selected(self):
        """The selector back at what drives the body now (after a refused change)."""
        box = self.panel.input
        box.blockSignals(True)
        box.setCurrentIndex(max(0, box.findData(self.device.url if self.device is not None else "mouse")))
        box.blockSignals(False)

    def set_input(self, url):
        from feelflow.app.gui.device_input import DeviceInput
        from feelflow.haptics import BadDeviceURL, DeviceError

        if self.replays.refuse("the input cannot be changed"):
            return
        self.close_device()
        if url == "mouse" or self.sim is None:
            self.panel.input_note.setText("")
            return
        try:
            self.device = DeviceInput(url, (self.sim.config.nx, self.sim.config.ny), DeviceInput.expected_peak(self.sim), self.parent,
                                      expected_peak_torque=DeviceInput.expected_peak_torque(self.sim))
        except (DeviceError, BadDeviceURL, OSError, ValueError) as exc:
            QMessageBox.warning(self.parent, "The device cannot be used", f"{exc}\nBack to the mouse.")
            self._back_to_mouse("")
            return
        self.device.disconnected.connect(self._device_lost)
        self.viewport.driver = "The haptic device"
        self.bodies.set_hold_still(False)
        self.panel.input_note.setText("The device moves the body; you feel the selected force model.")

    def tunnel_changed(self):
        """The grid was rebuilt: the device's workspace maps onto the new tunnel."""
        if self.device is not None:
            cfg = self.sim.config
            self.device.loop.set_tunnel((0.0, 0.0, cfg.nx - 1.0, cfg.ny - 1.0))

    # --- stopping ---------------------------------------------------------------------------
    def stop_device_force(self, _=None):
        """Esc: the haptic device's force goes to zero at once (haptics safety: the stop key)."""
        if self.device is not None:
            self.device.emergency_stop()
            self.status.showMessage("Device force stopped (Esc). Choose the device again to feel the flow.",
                                           10000)

    def escape(self, _=None):
        """Esc: the device's force to zero at once, and the replay, if one runs, stopped."""
        self.stop_device_force()
        self.replays.stop()

    def pause(self, paused: bool):
        """The flow paused or runs again: the device's force fades out or comes back."""
        if self.device is not None:
            self.device.pause(paused)

    def _device_lost(self, reason):
        self.close_device()
        self._back_to_mouse(f"The device disconnected ({reason}); the mouse moves the body again.")

    def _back_to_mouse(self, message):
        box = self.panel.input
        box.blockSignals(True)
        box.setCurrentIndex(box.findData("mouse"))
        box.blockSignals(False)
        self.panel.input_note.setText(message)
        if message:
            self.status.showMessage(message, 10000)
        if self.sim is not None:
            self.sim.drive(BodyInput.release("device"))

    def close_device(self):
        device, self.device = self.device, None
        self.viewport.driver = None
        if device is not None:
            device.close()

    # --- during a replay ------------------------------------------------------------------------
    def replay_started(self):
        """The live body is let go; a device's force fades out and its moves are refused."""
        self.sim.drive(BodyInput.release("mouse"))
        if self.device is not None:
            self.device.pause(True)
            self._device_seen = self.device.target()

    def replay_stopped(self, paused: bool):
        self.pause(paused)

    def watch_during_replay(self):
        """A device moved during a replay: say that it does not move the body now."""
        dev = self.device
        target = dev.target() if dev is not None else None
        if target is None:
            return
        if self._device_seen is not None and math.dist(target, self._device_seen) > DEVICE_MOVE_CELLS:
            self.replays.refuse("the device does not move the body")
        self._device_seen = target
