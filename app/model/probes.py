"""Probes: the flow's velocity and pressure at points the user places, read against time (the
sensor of Schroeder's LBM applet). Qt-free: the window places and draws them and plots their
series (app/gui/probe_plot.py); they sample the field the window already has each frame.

A probe at lattice position (x, y) (cell centres at integers, as the body's coordinates) reads
the macroscopic field (rho, ux, uy) interpolated bilinearly between the four nodes around it;
its pressure is the lattice equation of state's p - p_ref = c_s^2 (rho - rho_ref)
(solver/units.py `pressure`), with rho_ref the free stream's density, so that p is the gauge
pressure the pressure view colours. A probe inside the body reads NaN (there is no flow).
Series are in lattice units (cells per step, lattice pressure); app/model/readouts.py's units
convert them for display.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from feelflow.solver import units

#: at most this many probes (each is a line in the plot and four CSV columns)
MAX_PROBES = 4
#: samples kept per probe (as the force history)
MAX_SAMPLES = 20000


@dataclass
class Probe:
    x: float
    y: float
    time: list = field(default_factory=list)
    ux: list = field(default_factory=list)
    uy: list = field(default_factory=list)
    p: list = field(default_factory=list)

    @property
    def speed(self) -> np.ndarray:
        return np.hypot(np.asarray(self.ux, float), np.asarray(self.uy, float))

    def at(self, step) -> tuple | None:
        """(ux, uy, p) sampled at `step`, or None."""
        try:
            i = len(self.time) - 1 - self.time[::-1].index(step)
        except ValueError:
            return None
        return self.ux[i], self.uy[i], self.p[i]


def bilinear(field: np.ndarray, x: float, y: float, solid=None) -> np.ndarray:
    """(..., C) values of `field` (ny, nx, C) at lattice point (x, y); NaN where a node of the
    four is solid (`solid` (ny, nx) bool) or outside the grid."""
    ny, nx = field.shape[:2]
    if not (0.0 <= x <= nx - 1 and 0.0 <= y <= ny - 1):
        return np.full(field.shape[2:], np.nan)
    i0, j0 = min(int(math.floor(x)), nx - 2), min(int(math.floor(y)), ny - 2)
    fx, fy = x - i0, y - j0
    corners = field[j0:j0 + 2, i0:i0 + 2].astype(np.float64)
    if solid is not None and np.any(solid[j0:j0 + 2, i0:i0 + 2]):
        return np.full(field.shape[2:], np.nan)
    w = np.array([[(1 - fx) * (1 - fy), fx * (1 - fy)], [(1 - fx) * fy, fx * fy]])
    return np.tensordot(w, corners, axes=([0, 1], [0, 1]))


class Probes:
    """The probes placed in one tunnel, and their series."""

    def __init__(self):
        self.items: list[Probe] = []

    def __len__(self):
        return len(self.items)

    def __iter__(self):
        return iter(self.items)

    def add(self, x: float, y: float, nx: int, ny: int) -> Probe:
        """A probe at (x, y); ValueError (one line) outside the grid or past MAX_PROBES."""
        if len(self.items) >= MAX_PROBES:
            raise ValueError(f"at most {MAX_PROBES} probes; remove one first (right-click it)")
        if not (0.0 <= x <= nx - 1 and 0.0 <= y <= ny - 1):
            raise ValueError(f"a probe must lie in the tunnel (0 - {nx - 1} x 0 - {ny - 1} cells), not at ({x:.1f}, {y:.1f})")
        probe = Probe(float(x), float(y))
        self.items.append(probe)
        return probe

    def remove_near(self, x: float, y: float, radius: float = 2.0) -> bool:
        """Remove the probe nearest (x, y) within `radius` cells; True if one was."""
        if not self.items:
            return False
        d = [math.hypot(p.x - x, p.y - y) for p in self.items]
        i = int(np.argmin(d))
        if d[i] > radius:
            return False
        del self.items[i]
        return True

    def clear(self):
        self.items.clear()

    def clear_series(self):
        for p in self.items:
            p.time.clear(), p.ux.clear(), p.uy.clear(), p.p.clear()

    def sample(self, step: int, rgba: np.ndarray, rho_ref: float, solid=None) -> None:
        """Add a sample at `step` from the field (ny, nx, 4) (rho, ux, uy, vorticity) to every
        probe (once per step)."""
        for probe in self.items:
            if probe.time and probe.time[-1] == step:
                continue
            rho, ux, uy = bilinear(rgba[..., :3], probe.x, probe.y, solid)
            probe.time.append(step)
            probe.ux.append(float(ux))
            probe.uy.append(float(uy))
            probe.p.append(float(units.pressure(rho) - units.pressure(rho_ref)))
            if len(probe.time) > MAX_SAMPLES:
                del probe.time[0], probe.ux[0], probe.uy[0], probe.p[0]

    # --- files ------------------------------------------------------------------------------
    def columns(self) -> list[str]:
        """CSV column names: per probe, its position in the name, ux, uy, speed, p."""
        out = []
        for k, p in enumerate(self.items, 1):
            out += [f"probe{k}_{q}" for q in ("ux", "uy", "speed", "p")]
        return out

    def values_at(self, step) -> list[str]:
        """The CSV cells of every probe at `step` (blank where it has no sample there)."""
        out = []
        for p in self.items:
            v = p.at(step)
            out += ["", "", "", ""] if v is None else [f"{v[0]:.8g}", f"{v[1]:.8g}", f"{math.hypot(v[0], v[1]):.8g}",
                                                      f"{v[2]:.8g}"]
        return out

    def positions_text(self) -> str:
        return "; ".join(f"probe {k} at ({p.x:.1f}, {p.y:.1f}) cells" for k, p in enumerate(self.items, 1))

    def to_arrays(self) -> dict:
        """numpy arrays for a session file: positions (k, 2) and, per probe, (n, 4) rows of
        (step, ux, uy, p)."""
        out = {"positions": np.array([(p.x, p.y) for p in self.items], np.float64).reshape(-1, 2)}
        for k, p in enumerate(self.items):
            out[f"probe{k}"] = np.c_[np.asarray(p.time, np.float64), p.ux, p.uy, p.p].reshape(-1, 4)
        return out

    @classmethod
    def from_arrays(cls, arrays: dict) -> "Probes":
        probes = cls()
        for k, (x, y) in enumerate(np.asarray(arrays["positions"], float).reshape(-1, 2)[:MAX_PROBES]):
            probe = Probe(float(x), float(y))
            rows = np.asarray(arrays.get(f"probe{k}", np.zeros((0, 4))), float).reshape(-1, 4)
            probe.time = [int(t) for t in rows[:, 0]]
            probe.ux, probe.uy, probe.p = rows[:, 1].tolist(), rows[:, 2].tolist(), rows[:, 3].tolist()
            probes.items.append(probe)
        return probes
