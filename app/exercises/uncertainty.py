"""How far a score can be trusted: an exercise's grid uncertainty, the digits it supports, and
ties.

An exercise states the grid uncertainty of its scores (`[objective] grid_uncertainty`, in the
score's own units): the largest change of a reference or check shape's score when the tunnel is
refined twofold (every length and the step count doubled, Re and Ma kept), as
`feelflow exercise check --convergence` measures it, rounded up at the digit scores are printed
to (below). The
change between two grids is the usual estimate of the coarser grid's discretisation error (for
a method of second order the error itself is about 4/3 of the change, Richardson extrapolation;
Roache, *Verification and Validation in Computational Science and Engineering*, 1998): an
estimate from the shapes measured, not a bound for every shape a student draws.

- Digits (`decimals`): a score is printed to the decimal place of its uncertainty's leading
  digit, one place more when that digit is 1 or 2 (the usual convention for quoting a result
  with its uncertainty, GUM 7.2.6): 2.24 ± 0.10, 0.78 ± 0.05, 0.791 ± 0.020.
- Ties (`tied_ranks`): two scores closer than the uncertainty are not ordered. A shape's rank is
  one more than the number of shapes better than it by more than the uncertainty, so shapes
  within it share a rank (competition ranking: 1, 2=, 2=, 4).
- Same ranking on two grids (`order_changes`): every pair ordered on one grid (further apart
  than the uncertainty) is ordered the same way on the other.
"""
from __future__ import annotations

import math


def decimals(uncertainty: float | None, default: int = 4) -> int:
    """Decimal places a score with this uncertainty is printed to (`default` without one)."""
    if uncertainty is None or not uncertainty > 0 or not math.isfinite(uncertainty):
        return default
    exponent = math.floor(math.log10(uncertainty))
    leading = int(round(uncertainty / 10 ** exponent, 6))
    places = -exponent + (1 if leading <= 2 else 0)
    return max(0, places)


def fmt(score: float | None, uncertainty: float | None, with_uncertainty: bool = False) -> str:
    """The score to the digits its uncertainty supports ('-' for None), with ' ± u' if asked."""
    if score is None:
        return "-"
    d = decimals(uncertainty)
    text = f"{score:.{d}f}"
    if with_uncertainty and uncertainty:
        text += f" \u00b1 {uncertainty:.{d}f}"
    return text


def declared(measured: float) -> float:
    """The uncertainty to declare for a measured largest change: rounded up at the decimal place
    a score is printed to (`decimals`): 0.0978 -> 0.10, 0.0445 -> 0.05, 0.1076 -> 0.11."""
    if not measured > 0:
        return 0.0
    d = decimals(measured)
    value = math.ceil(round(measured * 10 ** d, 9)) / 10 ** d
    return round(value, decimals(value))


def better_by(a: float, b: float, better: str, uncertainty: float | None) -> bool:
    """Is score `a` better than `b` by more than the uncertainty?"""
    u = uncertainty or 0.0
    return (b - a > u) if better == "lower" else (a - b > u)


def tied(a: float, b: float, uncertainty: float | None) -> bool:
    """Are the two scores within the uncertainty of each other (not ordered)?"""
    return uncertainty is not None and abs(a - b) <= uncertainty


def standing(score: float, reference: float, better: str, uncertainty: float | None) -> str:
    """How `score` stands against a reference's, in the words the exercise panel puts before
    the reference: tied within the uncertainty, the same to four decimals (no uncertainty
    given), better, or behind."""
    if uncertainty is not None and tied(score, reference, uncertainty):
        return "tied (within the grid uncertainty) with"
    if uncertainty is None and round(score, 4) == round(reference, 4):
        return "the same as"
    return "better than" if better_by(score, reference, better, None) else "behind"


def tied_ranks(scores: list[float], better: str, uncertainty: float | None) -> list[int]:
    """Each score's rank: 1 + the number of scores better than it by more than the uncertainty."""
    return [1 + sum(better_by(other, s, better, uncertainty) for other in scores) for s in scores]


def rank_labels(ranks: list[int]) -> list[str]:
    """'2=' for a rank that others share, else '2'."""
    return [f"{r}=" if ranks.count(r) > 1 else str(r) for r in ranks]


def order_changes(coarse: dict, fine: dict, better: str, uncertainty: float | None) -> list[tuple]:
    """Pairs (a, b) of keys in both dicts (key -> score) where one grid puts a ahead of b by more
    than the uncertainty and the other grid puts b ahead of a (by any margin). Empty when the
    two rankings agree, ties declared by the uncertainty allowed."""
    keys = [k for k in coarse if k in fine]
    out = []
    for a in keys:
        for b in keys:
            if a == b:
                continue
            for one, other in ((coarse, fine), (fine, coarse)):
                if better_by(one[a], one[b], better, uncertainty) and \
                        better_by(other[b], other[a], better, 0.0):
                    out.append((a, b))
                    break
    return out


def largest_change(coarse: dict, fine: dict) -> float:
    """The largest |fine - coarse| over the keys in both (the measured grid uncertainty)."""
    changes = [abs(fine[k] - coarse[k]) for k in coarse if k in fine]
    return max(changes) if changes else 0.0
