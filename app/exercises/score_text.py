"""What the window says about a scoring run, in the exercise panel's words (rich text): while it
chooses the solver, while it runs, and its verdict: the score to the digits the exercise's grid
uncertainty supports (app/exercises/uncertainty.py), C_D and C_L with the reference length and
speed they are made dimensionless with (C = 2 F / (rho U^2 L), app/model/readouts.py), the
solver it ran on, the standing against each reference solution and how the force was averaged
(app/exercises/scoring.py). Qt-free; app/gui/exercise_controller.py puts the text in the panel.
"""
from __future__ import annotations

from feelflow.app.exercises.uncertainty import fmt, standing
from feelflow.app.model.readouts import EXERCISE_LENGTH

#: the scoring thread's message when the student pressed Cancel
CANCELLED = "cancelled"

CHOOSING = ("Scoring: choosing the solver (numpy or the compiled cpu backend, float64: the same scores; "
            "timed once for this grid)\u2026")


def running_text(backend: str) -> str:
    """The panel's line while the scoring simulation runs on `backend`."""
    text = f"Scoring: the tunnel runs the exercise's scoring simulation ({backend}, float64)\u2026"
    if backend == "cpu":
        text += "<br><small>The first run on this machine compiles the solver (20 - 60 s).</small>"
    return text


def failed_text(message: str) -> str:
    """The panel's line for a run that stopped without a result (`message`: CANCELLED or the
    error's one line)."""
    return "Scoring cancelled." if message == CANCELLED else f"Scoring failed: {message}"


def result_html(exercise, result, backend: str | None) -> str:
    """The verdict of `result` (a scoring.Result) for `exercise`, scored on `backend`."""
    if not result.ok:
        return f"<b>Not settled</b>: {result.reason}. No score is given for this run."
    o = exercise.objective
    u = o.uncertainty
    s = exercise.scene
    lines = [f"<b>Score {fmt(result.score, u, with_uncertainty=True)}</b> ({o.quantity}; "
             f"C_D {fmt(result.cd, u)}, C_L {fmt(result.cl, u)} "
             f"with L = {s.reference_length:g} cells ({EXERCISE_LENGTH}), U = {s.inflow_speed:.3f}; "
             f"{result.steps} steps, {result.seconds:.1f} s on {backend})"]
    if result.hit is not None:
        lines.append("A hit: within the tolerance." if result.hit else "Not a hit yet: outside the tolerance.")
    for ref in exercise.references:
        word = standing(result.score, ref.score, o.better, u)
        lines.append(f"{word} the reference \u201c{ref.label}\u201d ({fmt(ref.score, u)})")
    lines.append(f"<small>{result.averaging}</small>")
    return "<br>".join(lines)
