"""The polar and the surface pressure in the live tunnel (Qt-free; the window only draws them).

`SurfacePressureWatch` keeps the pressure model's wall sampling switched on
(solver/forces/surface_pressure.py) and hands out C_p along the surface averaged since the last
look. `LivePolar` runs an angle-of-attack sweep (app/model/polar.py) in the tunnel: the body is
held still at each angle until its forces settle, then turned to the next; the polar builds up
point by point and each angle's C_p is kept. Both are fed by `Simulation.advance`.
"""
from __future__ import annotations

import math

from feelflow.app.model.polar import PolarSweep, chord_of, naca_zero_lift_angle
from feelflow.solver.forces.surface_pressure import SurfacePressureProbe, distribution, free_stream_density


class SurfacePressureWatch:
    """C_p along the body's surface in the live tunnel, averaged over the steps between looks."""

    def __init__(self):
        self.probe = SurfacePressureProbe()
        self.latest = None   # the last SurfacePressure handed out

    def take(self, sim):
        """C_p averaged since the last call (None before a step), referred to the wind now and
        the free stream's density (half-way between the inlet and the body)."""
        steps = self.probe.steps
        taken = self.probe.take()
        if taken is None:
            return self.latest
        body, pts, normals, _, rho, valid = taken
        speed = math.hypot(*sim.relative_wind()) or sim.params.wind
        rho_ref = free_stream_density(sim.solver.macroscopic()[0], body)
        self.latest = distribution(body, pts, normals, rho, valid, rho_ref, speed, steps=steps)
        return self.latest


class LivePolar:
    """An angle sweep in the live tunnel: `after_advance` after every `Simulation.advance`."""

    def __init__(self, sim, angles, sample_steps: int = 25, **settling):
        """`settling`: PolarSweep's tolerance, window_chords, min_chords, max_chords."""
        self.chord = chord_of(sim.shape)
        self.sweep = PolarSweep(tuple(angles), sim.params.wind, self.chord, sample_steps=sample_steps, **settling)
        self.watch = SurfacePressureWatch()
        self.cp = []   # (alpha, SurfacePressure) of every settled angle
        shape = sim.shape
        self.zero_lift_alpha = (naca_zero_lift_angle(shape.camber, shape.camber_position)
                                if shape.kind == "naca" else 0.0)
        self._acc = [0.0, 0.0, 0]

    @property
    def probe(self):
        return self.watch.probe

    @property
    def done(self) -> bool:
        return self.sweep.done

    def start(self, sim):
        """Hold the body still and turn it to the first angle."""
        sim.hold_still = True
        self._turn(sim)

    def _turn(self, sim):
        if self.sweep.angle is not None:
            sim.set_shape(angle_deg=-self.sweep.angle)   # pose angle -alpha: nose up for alpha > 0
            self.probe.take()                             # C_p of this angle only

    def after_advance(self, sim, forces, n: int):
        """Feed the sweep the force of the last `n` steps; turn the body when an angle is done."""
        if self.sweep.done:
            return
        model = "momentum_exchange" if "momentum_exchange" in forces else sim.params.force_model
        if model not in forces:
            return
        fx, fy = forces[model]
        acc = self._acc
        acc[0] += fx * n
        acc[1] += fy * n
        acc[2] += n
        if acc[2] < self.sweep.sample_steps:
            return
        finished = self.sweep.add_sample(acc[0] / acc[2], acc[1] / acc[2], acc[2])
        self._acc = [0.0, 0.0, 0]
        if finished:
            cp = self.watch.take(sim)
            if cp is not None:
                self.cp.append((self.sweep.points[-1].alpha, cp))
            self._turn(sim)

    def live_cp(self, sim):
        """C_p at the angle being held, averaged since it was turned to (for a live view)."""
        taken = self.probe.peek()
        if taken is None:
            return self.watch.latest
        body, pts, normals, _, rho, valid = taken
        return distribution(body, pts, normals, rho, valid,
                            free_stream_density(sim.solver.macroscopic()[0], body), self.sweep.speed,
                            steps=self.probe.steps)
