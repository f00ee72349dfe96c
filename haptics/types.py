"""The small value types that cross the haptics boundary (docs/developer/architecture.md, 'One frame, as data').

Nothing here knows about the solver or Qt: the app turns solver output into `ForceSample`s and
reads `BodyTarget`s back. Times are `time.monotonic()` seconds unless a field says otherwise.
"""
from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class Pose:
    """Where the device's handle is, in the device's own frame.

    x, y: metres in the device workspace (a 1-DOF device reports y = 0; a velocity-input
    device such as the SpaceMouse reports its integrated position in a virtual workspace).
    angle: radians (0 for devices without a rotational axis).
    buttons: bit mask, bit 0 = first button.
    t: time.monotonic() of reception on the host.
    """

    x: float
    y: float = 0.0
    angle: float = 0.0
    buttons: int = 0
    t: float = 0.0


@dataclass(frozen=True)
class ForceSample:
    """The fluid's force on the body as the solver computed it.

    fx, fy: LATTICE units (force per time step on the lattice, as the force models return it),
    in tunnel axes (x downstream, y up). The force loop scales them to newtons; nothing else does.
    t: time.monotonic() when the sample was produced. step: the solver step (optional, for logs).
    torque: the torque on the body about its centre, LATTICE units, counter-clockwise positive
    in tunnel axes (Solver.torques); the loop scales it to newton metres for a device with a
    rotational axis (Capabilities.max_torque > 0) and sends it nowhere else.
    """

    fx: float
    fy: float
    t: float
    step: int | None = None
    torque: float = 0.0


@dataclass(frozen=True)
class Capabilities:
    """What a device can do.

    dof: translational degrees of freedom (1 or 2).
    workspace: ((x_min, x_max), (y_min, y_max)) metres in the device frame.
    max_force: newtons; the most any command to this device may ask for (drivers clamp to it).
    can_output_force: False for input-only devices (SpaceMouse).
    input_mode: 'position' (the pose is where the hand is) or 'velocity' (integrated deflection).
    nominal_rate_hz: the update rate the device is meant to run at.
    max_torque: newton metres the device's rotational axis may give at most (0: it has none
    that outputs force; drivers clamp to it).
    """

    name: str
    dof: int
    workspace: tuple[tuple[float, float], tuple[float, float]]
    max_force: float
    can_output_force: bool = True
    input_mode: str = "position"
    nominal_rate_hz: float = 1000.0
    max_torque: float = 0.0


@dataclass(frozen=True)
class BodyTarget:
    """Where the virtual coupling puts the body, for the solver to move it there.

    x, y: tunnel (lattice node) coordinates; vx, vy: lattice nodes per SECOND (the app divides by
    its steps per second to get lattice velocity and applies its Mach cap). t: monotonic time.
    buttons: the device buttons at that time. valid: False until the first pose has arrived.
    """

    x: float
    y: float
    vx: float = 0.0
    vy: float = 0.0
    t: float = 0.0
    buttons: int = 0
    valid: bool = True


@dataclass(frozen=True)
class DeviceInfo:
    """One entry of `list_devices()`: something `open_device(url)` can open."""

    url: str
    name: str
    kind: str  # 'serial', 'hid' or 'sim'
    driver: str | None = None  # the driver that would handle it, None if unknown
    details: dict = field(default_factory=dict)
