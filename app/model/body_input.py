"""What a hand (the mouse, a haptic device) or a script asks of the body: one small value that
every input passes to the tunnel model's one way in, `TunnelModel.drive` (app/model/tunnel.py).

The model answers through its couplings (app/model/coupling.py): the spring-damper pulls the
body's reference point towards a target (speed capped below the Mach limit) and the angle
spring swings it to an angle, so no input sets the pose directly.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

#: who may ask: the window's mouse (drag, handle, wheel), a haptic device, a script (Python,
#: a test); a replay refuses them all, since its body follows the recording
SOURCES = ("mouse", "device", "script")


@dataclass(frozen=True)
class BodyInput:
    """One request for the body, lattice units. Build it with `pull`, `release` or `turn`.

    `target`: where to pull the reference point, (x, y) in cells, or None (no pull asked).
    `let_go`: end the pull (the body coasts to rest under the coupling's damping).
    `angle_deg`: the angle to swing to, in degrees, any number of turns (190 turns 20 past
    170, not 340 back), or None. `source`: one of `SOURCES`."""

    target: tuple[float, float] | None = None
    angle_deg: float | None = None
    let_go: bool = False
    source: str = "script"

    def __post_init__(self):
        if self.source not in SOURCES:
            raise ValueError(f"body input source must be one of {', '.join(SOURCES)}, not {self.source!r}")
        if self.target is not None:
            if self.let_go:
                raise ValueError("body input cannot both pull the body and let it go")
            x, y = (float(v) for v in self.target)
            if not (math.isfinite(x) and math.isfinite(y)):
                raise ValueError(f"body input target must be finite, not ({x}, {y})")
            object.__setattr__(self, "target", (x, y))
        if self.angle_deg is not None and not math.isfinite(self.angle_deg):
            raise ValueError(f"body input angle must be finite, not {self.angle_deg}")

    @classmethod
    def pull(cls, x: float, y: float, source: str = "script") -> "BodyInput":
        """Pull the body's reference point towards (x, y)."""
        return cls(target=(x, y), source=source)

    @classmethod
    def release(cls, source: str = "script") -> "BodyInput":
        """Let go of the body (the mouse button released, the device gone)."""
        return cls(let_go=True, source=source)

    @classmethod
    def turn(cls, degrees: float, source: str = "script") -> "BodyInput":
        """Swing the body to `degrees` (any number of turns)."""
        return cls(angle_deg=float(degrees), source=source)
