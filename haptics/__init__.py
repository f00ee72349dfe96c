"""FeelFlow haptics: devices (serial, HID, simulated) and the safe 1 kHz force loop.

Qt-free and solver-free (docs/developer/architecture.md, rule 1): what crosses the boundary are the small value types
of `feelflow.haptics.types`. The API for the app:

    from feelflow.haptics import list_devices, open_device, ForceLoop, LoopConfig, ForceSample

    for info in list_devices():          # DeviceInfo(url, name, kind, driver, details)
        print(info.url, info.name)       # serial ports, HID devices with a driver, sim://...
    dev = open_device("sim://haply2diy") # or serial:///dev/ttyACM0, hid://046d:c626, ...
    dev.capabilities                     # Capabilities(dof, workspace, max_force, can_output_force, ...)
    loop = ForceLoop(dev, LoopConfig(tunnel_rect=(x0, y0, x1, y1),    # lattice nodes
                                     expected_peak=0.02,               # lattice force units
                                     comfort_fraction=0.5),
                     on_disconnect=callback)       # called from the loop thread
    loop.start()                                   # own thread, 1 kHz, force ramps up
    loop.submit_force(ForceSample(fx, fy, t))      # after each solver frame (lattice units)
    bt = loop.body_target()                        # BodyTarget(x, y, vx, vy [nodes/s], t, buttons, valid)
    loop.pause(); loop.resume()                    # app paused / running
    loop.emergency_stop(); loop.clear_stop()       # the stop key
    loop.status()                                  # LoopStatus: state, rate, jitter, counters
    loop.stop(); dev.close()

In the app, prefer the same loop in a child process, which no GUI or solver thread of the app
can stall through the interpreter lock (docs/guide/haptic-devices.md, 'The force loop'):

    loop = ProcessForceLoop("sim://haply2diy", LoopConfig(...), on_disconnect=callback)
    loop.capabilities; loop.start(); ...same calls as above...; loop.close()

`body_target()` is meant as the target of the app's own coupling (the mouse's), which applies
the Mach cap; divide its velocity (nodes per second) by the steps per second.

Units: ForceSample is in LATTICE units (tunnel axes); the loop alone converts to newtons
(`ForceScale`: the scene's expected peak -> comfort_fraction x device maximum) and clamps to the
device maximum every tick; drivers clamp again. Poses are metres in the device frame.
Errors: `DeviceError` (cannot open / no answer), `DeviceDisconnected`, `BadDeviceURL`
(one-line messages, fit for the user).
"""
from feelflow.haptics.errors import BadDeviceURL, DeviceDisconnected, DeviceError
from feelflow.haptics.loop import ForceLoop, LoopConfig, LoopStatus
from feelflow.haptics.registry import list_devices, open_device
from feelflow.haptics.safety import SafetyConfig
from feelflow.haptics.types import BodyTarget, Capabilities, DeviceInfo, ForceSample, Pose

__all__ = [
    "BadDeviceURL", "BodyTarget", "Capabilities", "DeviceDisconnected", "DeviceError", "DeviceInfo",
    "ForceLoop", "ForceSample", "LoopConfig", "LoopStatus", "Pose", "ProcessForceLoop", "SafetyConfig",
    "list_devices",
    "open_device",
]


def __getattr__(name):  # ProcessForceLoop lazily: `python -m feelflow.haptics.process_loop` imports this package
    if name == "ProcessForceLoop":
        from feelflow.haptics.process_loop import ProcessForceLoop

        return ProcessForceLoop
    raise AttributeError(f"module 'haptics' has no attribute {name!r}")
