"""How the window moves its body between frames: the one Qt-free loop that advances the pose
and steps the solver (app/model/simulation.py calls it; solver/motion.py's MotionRunner does the
same for scripted motion, `feelflow run` and the validation cases).

While the body moves or turns its pose advances every step: it is placed (`set_body`) before
each step at the pose of that step, as MotionRunner does. Placing it once per chunk of steps
(the window did so, in chunks of up to half a cell, at the chunk's end pose) makes the drag of
the first step after each placement carry the whole chunk's catching up: measured on a towed
cylinder (`feelflow report towed`, docs/science/force-models.md), placing every 12 steps
(half a cell at U = 0.04) leaves a noise of 58 % of the drag per step and 18 % for 5-step means,
against 9 % and 6 % when the pose advances every step. At rest the solver runs the whole frame
in one call.
"""
from __future__ import annotations

import math

from feelflow.solver.force_average import StepWeightedMean

#: a body slower than this (cells per step) and nearer its target than REST_DISTANCE (cells) is
#: at rest: a critically damped spring creeps towards its target for ever, and a creep of 1e-5
#: cells per step is a hundredth of a cell in a thousand steps
REST_SPEED = 1e-5
REST_DISTANCE = 1e-3
#: the same for the angle: radians per step, radians
REST_RATE = 1e-6
REST_ANGLE = 1e-4


def is_moving(vel, rate: float, pos=None, target=None, angle: float = 0.0, angle_target: float = 0.0) -> bool:
    """Whether the body moves or turns during the next step: it has a speed or turn rate, or a
    target (of the position or angle) it has not reached."""
    if math.hypot(*vel) > REST_SPEED or abs(rate) > REST_RATE or abs(angle_target - angle) > REST_ANGLE:
        return True
    return target is not None and pos is not None and math.hypot(target[0] - pos[0], target[1] - pos[1]) > REST_DISTANCE


def advance_with_motion(solver, n: int, move, moving, torques: dict | None = None) -> dict[str, tuple[float, float]]:
    """Run n steps of `solver`, calling `move(k)` before each run of k steps to advance the pose
    by k steps and place the body: k = 1 while `moving()` says the body moves, else the rest of
    the n steps in one run. Returns each force model's force summed over the steps (weight:
    steps), and fills `torques` (where given) with each model's torque summed the same way;
    SolverDiverged propagates from the solver."""
    done = 0
    total = StepWeightedMean()
    while done < n:
        k = 1 if moving() else n - done
        move(k)
        solver.step(k)
        total.add(solver.forces(), k, solver.torques() if torques is not None else None)
        done += k
    if torques is not None:
        torques.update(total.torque_totals())
    return total.totals()
