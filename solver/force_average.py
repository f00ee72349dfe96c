"""The mean force of several solver calls, each weighted by its steps: what a force row, a
window frame or a motion phase reports when it ran as several `step(k)` calls (a body moved
between them, a row run in parts). `Solver.forces()` is already the mean over the steps of one
call, so the mean over calls of k_1, k_2, ... steps is sum(k_i F_i) / sum(k_i). Lattice units."""
from __future__ import annotations


class StepWeightedMean:
    """Forces per model, accumulated call by call (`add`) and averaged over all steps added
    (`mean`); a model absent from some calls counts as zero there, so that its mean is its
    impulse over the whole span divided by the span."""

    def __init__(self):
        self._sums: dict[str, list[float]] = {}
        self._torques: dict[str, float] = {}
        self.steps = 0

    def add(self, forces: dict, steps: int, torques: dict | None = None) -> None:
        """The mean forces {model: (Fx, Fy)} of a call of `steps` steps, and its mean torques
        {model: T} (Solver.torques) where given."""
        for name, (fx, fy) in forces.items():
            acc = self._sums.setdefault(name, [0.0, 0.0])
            acc[0] += steps * fx
            acc[1] += steps * fy
        for name, torque in (torques or {}).items():
            self._torques[name] = self._torques.get(name, 0.0) + steps * torque
        self.steps += steps

    def torque_totals(self) -> dict[str, float]:
        """{model: sum k T}: each torque summed over the steps."""
        return dict(self._torques)

    def torque_mean(self, steps: int | None = None) -> dict[str, float]:
        """{model: T} averaged over `steps` (default: the steps added), as `mean`."""
        n = self.steps if steps is None else steps
        return {name: t / n for name, t in self._torques.items()} if n else {}

    def totals(self) -> dict[str, tuple[float, float]]:
        """{model: (sum k Fx, sum k Fy)}: each force summed over the steps (an impulse per unit span)."""
        return {name: (sx, sy) for name, (sx, sy) in self._sums.items()}

    def mean(self, steps: int | None = None) -> dict[str, tuple[float, float]]:
        """{model: (Fx, Fy)} averaged over `steps` (default: the steps added)."""
        n = self.steps if steps is None else steps
        return {name: (sx / n, sy / n) for name, (sx, sy) in self._sums.items()} if n else {}
