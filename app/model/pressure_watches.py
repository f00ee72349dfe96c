"""The surface-pressure sampling switched on in the live tunnel (Qt-free): the C_p view's
watch and the live polar (app/model/live_polar.py), one probe serving both
(solver/forces/surface_pressure.py). The `Simulation` (app/model/simulation.py) holds one,
adds its probes beside the force models and feeds it after every frame.
"""
from __future__ import annotations

from feelflow.app.model.live_polar import LivePolar, SurfacePressureWatch


class PressureWatches:
    """C_p along the surface for the plot's C_p view (`surface_watch`) and an angle-of-attack
    sweep in the tunnel (`polar`), each None while off."""

    def __init__(self):
        self.polar: LivePolar | None = None
        self.surface_watch: SurfacePressureWatch | None = None

    def probes(self) -> list:
        """The surface-pressure probes switched on: the polar's serves the C_p view too."""
        watch = self.polar or self.surface_watch
        return [] if watch is None else [watch.probe]

    def watch_surface(self, on: bool = True):
        """The C_p view's wall sampling on or off."""
        if on and self.surface_watch is None:
            self.surface_watch = SurfacePressureWatch()
        elif not on:
            self.surface_watch = None

    def start_polar(self, sim, angles, sample_steps: int = 25, **settling) -> LivePolar:
        """A new angle-of-attack sweep on `sim`'s body (LivePolar: `settling` its tolerances)."""
        self.polar = LivePolar(sim, angles, sample_steps=sample_steps, **settling)
        return self.polar

    def stop_polar(self):
        self.polar = None

    def surface_pressure(self, sim):
        """C_p along the surface now: at the polar's angle being held, else its last settled
        angle's, else the C_p view's own sampling (averaged since the last look); None where
        nothing is sampled."""
        polar = self.polar
        if polar is not None and not polar.done:
            return polar.live_cp(sim)
        if polar is not None and polar.cp:
            return polar.cp[-1][1]
        return self.surface_watch.take(sim) if self.surface_watch is not None else None

    def after_advance(self, sim, forces: dict, n: int):
        """Take the probes' rows out of `forces` (a probe's force is the pressure model's, not a
        model of its own) and feed the polar the last `n` steps."""
        for probe in self.probes():
            forces.pop(probe.name, None)
        if self.polar is not None:
            self.polar.after_advance(sim, forces, n)
