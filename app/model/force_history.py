"""The force history: one sample per frame of the running tunnel (its reporter, as lettuce's
reporters are): step, body velocity, relative wind, the force and torque of each model in use, and whether
the sample is settled. The plot, the readouts (app/model/readouts.py) and the lessons report read
it. Qt-free; lattice units."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from feelflow.app.model import readouts


@dataclass
class History:
    """One sample per frame: step, body velocity, relative wind, force of each model in use, and
    whether the sample is *settled*: the relative wind has stayed within `WIND_TOLERANCE` of its
    value for at least `SETTLE_STEPS` steps. Only settled samples are steady drag; the
    drag-against-speed view fits those (app/model/plot_series.py). SETTLE_STEPS was chosen from a probe
    of the 'Drag grows with speed' lesson (not a command: indicative only): 750
    steps after a wind change had finished, the drag's 250-step means stayed within 5 % of the
    hold's end value at every wind of the sweep, while the first few hundred steps carry the
    acceleration's added-mass force and the flow's rearrangement (up to +60 %). What the choice
    gives is measured by `feelflow report lessons` (docs/science/validation.md 'Calm tunnels': the fitted exponent)."""

    time: list = field(default_factory=list)
    body_velocity: list = field(default_factory=list)
    wind: list = field(default_factory=list)
    forces: dict = field(default_factory=dict)  # model -> list of (Fx, Fy)
    torques: dict = field(default_factory=dict)  # model -> list of torques about the body's centre
    settled: list = field(default_factory=list)
    _wind_ref: tuple = (math.nan, math.nan)      # relative wind when it last changed, and when
    _since: float = 0.0

    MAX = 20000
    SETTLE_STEPS = 1000
    WIND_TOLERANCE = 0.02

    def add(self, time, body_velocity, wind, forces, torques=None):
        self.time.append(time)
        self.body_velocity.append(body_velocity)
        self.wind.append(wind)
        self.settled.append(self._settled(time, wind))
        for name, f in forces.items():
            series = self.forces.setdefault(name, [])
            series.extend([(math.nan, math.nan)] * (len(self.time) - 1 - len(series)))
            series.append(f)
        for name, t in (torques or {}).items():
            series = self.torques.setdefault(name, [])
            series.extend([math.nan] * (len(self.time) - 1 - len(series)))
            series.append(t)
        if len(self.time) > self.MAX:
            cut = len(self.time) - self.MAX
            del self.time[:cut], self.body_velocity[:cut], self.wind[:cut], self.settled[:cut]
            for series in (*self.forces.values(), *self.torques.values()):
                del series[:max(0, len(series) - self.MAX)]

    def _settled(self, time, wind) -> bool:
        ref = self._wind_ref
        scale = max(math.hypot(*ref), math.hypot(*wind), 1e-9) if all(map(math.isfinite, ref)) else 0.0
        if not scale or math.hypot(wind[0] - ref[0], wind[1] - ref[1]) > self.WIND_TOLERANCE * scale:
            self._wind_ref, self._since = tuple(wind), time
        return time - self._since >= self.SETTLE_STEPS

    def clear(self):
        self.time.clear(), self.body_velocity.clear(), self.wind.clear(), self.forces.clear(), self.torques.clear()
        self.settled.clear()
        self._wind_ref, self._since = (math.nan, math.nan), 0.0

    def __len__(self):
        return len(self.time)

    def drag_lift(self, model: str):
        """(t, drag, lift) arrays: force along and across the relative wind (NaN where absent;
        app/model/readouts.py decomposes)."""
        n = len(self.time)
        series = self.forces.get(model, [])
        f = np.full((n, 2), np.nan)
        if series:
            f[n - len(series):] = np.asarray(series[-n:], float)
        drag, lift = readouts.drag_lift(f, np.asarray(self.wind, float).reshape(n, 2))
        return np.asarray(self.time, float), drag, lift

    def settled_drag(self, model: str):
        """(relative wind speed, drag) arrays of the settled samples only (`settled`): drag
        while the wind or the body's speed is changing carries the acceleration's force and is
        not the steady drag the drag-against-speed law describes (app/model/power_law.py)."""
        _, drag, _ = self.drag_lift(model)
        wind = np.asarray(self.wind, float).reshape(-1, 2)
        settled = np.asarray(self.settled, bool)
        return np.hypot(wind[settled, 0], wind[settled, 1]), drag[settled]

    def torque(self, model: str):
        """(t, torque) arrays: the model's torque about the body's centre, counter-clockwise
        positive (NaN where absent)."""
        n = len(self.time)
        series = self.torques.get(model, [])
        out = np.full(n, np.nan)
        if series:
            out[n - len(series):] = np.asarray(series[-n:], float)
        return np.asarray(self.time, float), out
