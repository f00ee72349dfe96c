"""The exercise panel's words, Qt-free: the exercise's text as paragraphs, its goal and its
reference solutions' scores (to the digits the grid uncertainty supports,
app/exercises/uncertainty.py), the constraints as they stand, the live tunnel's C_D and C_L with
their reference (app/model/readouts.py), and the attempts list's lines. The scoring run's lines
are app/exercises/score_text.py's; app/gui/exercise_panel.py shows both."""
from __future__ import annotations

from pathlib import Path

from feelflow.app.exercises.uncertainty import fmt, tied
from feelflow.app.model import readouts

BAD = "#d03030"
GOOD = "#208040"


def reflow(text: str) -> str:
    """An exercise's text as paragraphs: the file's line breaks inside a paragraph become
    spaces (the panel wraps to its own width), blank lines stay paragraph breaks."""
    paragraphs = [" ".join(line.strip() for line in block.splitlines() if line.strip())
                  for block in text.strip().split("\n\n")]
    return "\n\n".join(p for p in paragraphs if p)


def breakable_path(path: str) -> str:
    """A file path that a word-wrapped label may break after each separator (a zero-width
    space there), with the home folder written as ~."""
    home = str(Path.home())
    if home not in ("", "/") and path.startswith(home):
        path = "~" + path[len(home):]
    return path.replace("/", "/\u200b").replace("\\", "\\\u200b")


def goal_text(exercise) -> str:
    """The objective in one sentence: what is scored, which way is better, a target's
    tolerance and the grid uncertainty within which scores tie."""
    o = exercise.objective
    goal = f"Goal: {o.kind.replace('_', ' ')}; score = {o.quantity}, {o.better} is better"
    if o.target is not None:
        goal += f" (a hit is within {o.tolerance:g} of {o.target:g})"
    u = o.uncertainty
    if u is not None:
        goal += f". Scores are good to \u00b1{u:g} (the grid uncertainty); closer than that is a tie"
    return goal + "."


def references_text(exercise) -> str:
    """The reference solutions' scores, to the digits the uncertainty supports."""
    u = exercise.objective.uncertainty
    refs = "; ".join(f"{r.label}: {fmt(r.score, u)}" for r in exercise.references)
    return f"Reference solution{'s' if len(exercise.references) > 1 else ''}: {refs}."


def problems_text(problems: list[str]) -> str:
    """What the shape breaks now (rich text, red), or that it is ready to score (green)."""
    if problems:
        items = "".join(f"<li>{p}</li>" for p in problems)
        return f"<span style='color:{BAD}'><b>Not ready to score:</b><ul>{items}</ul></span>"
    return f"<span style='color:{GOOD}'><b>All constraints met</b>: ready to score.</span>"


def live_text(readout: "readouts.Readout") -> str:
    """The live tunnel's C_D and C_L with the reference they use (rich text)."""
    f = readouts.format_coefficient
    return (f"In the tunnel now: C<sub>D</sub> {f(readout.cd)}, C<sub>L</sub> {f(readout.cl)} "
            f"<small>({readout.reference_text()}; the window's flow, float32)</small>")


def attempts_heading(where: str) -> str:
    """The attempts list's heading: the best framed in gold, and the file they are saved in."""
    return f"Attempts, the best framed in gold; saved in {breakable_path(where)}"


def attempt_line(attempt, best, uncertainty: float | None = None) -> str:
    """One attempt (app/exercises/attempts.py) in the list: number, score or status, when and
    how long, and whether it is the best or ties it."""
    a = attempt
    text = f"#{a.number}  {fmt(a.score, uncertainty)}" if a.score is not None else f"#{a.number}  {a.status}"
    text += f"   {a.time.replace('T', ' ')[:19]}, {a.seconds:.1f} s"
    if best is not None and a.number == best.number:
        text += "   \u2605 best"
    elif best is not None and a.score is not None and tied(a.score, best.score, uncertainty):
        text += "   = ties the best"
    return text


def attempt_tip(attempt) -> str | None:
    """An attempt's tooltip: why it has no score, else its C_D and C_L."""
    a = attempt
    if a.cd is None:
        return a.reason
    return a.reason or f"C_D {a.cd:.4f}, C_L {a.cl:.4f}"
