"""Checks shared by every shape: finite numbers, positive sizes, minimum size, inside the domain,
flow directions.

Each raises `ShapeError` with one line naming the offending quantity.
"""
from __future__ import annotations

import math

import numpy as np

from feelflow.shapes.base import Shape, ShapeError

#: smallest allowed extent of a body, in lattice cells (a body smaller than 2 cells is not resolved by the lattice)
MIN_EXTENT = 2.0


def _kind_of(value) -> str:
    """What a wrong value is, for a message (never its possibly huge text)."""
    if isinstance(value, (bool, np.bool_)):
        return "true/false"
    if isinstance(value, str):
        return f"text {value[:20]!r}"
    return f"a {type(value).__name__}"


def finite_number(name: str, value) -> float:
    """`value` as a float; ShapeError if it is not a finite real number."""
    if isinstance(value, (bool, np.bool_, str, bytes)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ShapeError(f"{name} must be a number, got {_kind_of(value)}")
    try:
        number = float(value)
    except (TypeError, ValueError, OverflowError):
        raise ShapeError(f"{name} must be a finite number, got one too large") from None
    if not math.isfinite(number):
        raise ShapeError(f"{name} must be a finite number, got {number}")
    return number


#: largest size of a body, cells: the largest grid side (solver/config.py); a larger body could
#: never be placed, and a parametric outline sampled per cell would take minutes to build
MAX_SIZE = 8192.0


def positive_number(name: str, value) -> float:
    """A finite number in (0, MAX_SIZE]."""
    number = finite_number(name, value)
    if number <= 0.0:
        raise ShapeError(f"{name} must be positive, got {number:g}")
    if number > MAX_SIZE:
        raise ShapeError(f"{name} must be at most {MAX_SIZE:g} cells (the largest grid), got {number:g}")
    return number


def check_pose(shape: Shape) -> None:
    """Position and angle are finite."""
    for name in ("x", "y", "angle"):
        finite_number(f"{shape.kind} {name}", getattr(shape, name))


def check_extent(shape: Shape) -> None:
    """The body spans at least MIN_EXTENT cells in its largest dimension."""
    xmin, ymin, xmax, ymax = shape.bounding_box()
    extent = max(xmax - xmin, ymax - ymin)
    if extent < MIN_EXTENT:
        raise ShapeError(f"{shape.kind} is smaller than {MIN_EXTENT:g} cells "
                         f"(largest extent {extent:.3g})")


def check_in_domain(shape: Shape, nx: int | None, ny: int | None) -> None:
    """The body's bounding box lies within the lattice nodes [0, nx-1] x [0, ny-1]."""
    if nx is None or ny is None:
        return
    xmin, ymin, xmax, ymax = shape.bounding_box()
    if xmin < 0 or ymin < 0 or xmax > nx - 1 or ymax > ny - 1:
        raise ShapeError(
            f"{shape.kind} at ({shape.x:g}, {shape.y:g}) is not inside the domain "
            f"{nx}x{ny}: it spans x {xmin:.3g}..{xmax:.3g}, y {ymin:.3g}..{ymax:.3g}, "
            f"allowed x 0..{nx - 1}, y 0..{ny - 1}")


def unit_direction(flow_direction) -> np.ndarray:
    """A unit 2-vector from a direction given as (dx, dy) or as an angle in radians."""
    try:
        d = np.asarray(flow_direction, dtype=np.float64)
    except (TypeError, ValueError):
        raise ShapeError(f"flow direction must be (dx, dy) or an angle, got {flow_direction!r}") from None
    if d.ndim == 0:
        d = np.array([math.cos(float(d)), math.sin(float(d))])
    if d.shape != (2,) or not np.all(np.isfinite(d)):
        raise ShapeError(f"flow direction must be (dx, dy) or an angle, got {flow_direction!r}")
    norm = math.hypot(d[0], d[1])
    if norm == 0.0:
        raise ShapeError("flow direction must not be the zero vector")
    return d / norm
