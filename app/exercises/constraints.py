"""What a shape must satisfy before it is scored, checked in words a student understands.

A shape is scored where the exercise puts it: its area centroid at `scene.body_position`, its
angle its own (docs/reference/exercise-format.md, [constraints]). Every check returns a sentence
naming the quantity, its value and the allowed range; `check_shape` returns them all (an empty
list means the shape may be scored). Lengths in cells at the exercise's resolution.
"""
from __future__ import annotations

import math

import numpy as np

from feelflow.shapes.base import Shape, ShapeError
from feelflow.shapes.io import from_dict
from feelflow.shapes.polygon import Polygon, PolygonalShape, polygon_area_centroid

#: shape-dict keys that are lengths (scaled with the resolution); angles are not
LENGTH_KEYS = ("diameter", "length", "thickness", "chord", "x", "y")
#: cells the body keeps from the tunnel's walls, inlet and outlet sponge
WALL_MARGIN = 3.0


def centroid(shape: Shape) -> tuple[float, float]:
    """Area centroid in world coordinates (a cylinder's centre)."""
    if isinstance(shape, PolygonalShape):
        _, cx, cy = polygon_area_centroid(shape.world_vertices)
        return cx, cy
    return float(shape.x), float(shape.y)


def area(shape: Shape) -> float:
    if isinstance(shape, PolygonalShape):
        return float(shape.area)
    return math.pi * shape.radius ** 2


def posed(exercise, shape: Shape, scale: int = 1) -> Shape:
    """The shape as the scoring run sees it: every length times `scale` (the same body at
    `scale` times the resolution), its area centroid at the (scaled) body position. Placed from
    the shape's own description, not from where it was drawn or saved, so the same shape gives
    the same digits wherever it came from."""
    if scale != 1:
        d = shape.to_dict()
        for key in LENGTH_KEYS:
            if key in d:
                d[key] = d[key] * scale
        if "vertices" in d:
            d["vertices"] = [[vx * scale, vy * scale] for vx, vy in d["vertices"]]
        shape = from_dict(d)
    scene = exercise.scene.scaled(scale)
    cx, cy = centroid(shape.moved(x=0.0, y=0.0))
    return shape.moved(x=scene.body_x - cx, y=scene.body_y - cy)


def frontal_height(shape: Shape) -> float:
    """Extent across the stream (the stream runs along +x)."""
    return float(shape.frontal_area((1.0, 0.0)))


def streamwise_length(shape: Shape) -> float:
    return float(shape.frontal_area((0.0, 1.0)))


def thickness(shape: Shape, spacing: float = 0.25) -> float:
    """Diameter of the largest circle inside the body (on a `spacing` sample grid): a plate's
    thickness, an airfoil's largest thickness, a cylinder's diameter."""
    x0, y0, x1, y1 = shape.bounding_box()
    xs = np.arange(x0, x1 + spacing, spacing)
    ys = np.arange(y0, y1 + spacing, spacing)
    px, py = np.meshgrid(xs, ys)
    inside = shape.contains(px, py)
    if not inside.any():
        return 0.0
    d = shape.boundary_distance(px[inside], py[inside])
    k = int(np.argmax(d))
    # refine around the best sample: the largest circle's centre lies within a sample spacing
    fine = np.linspace(-spacing, spacing, 21)
    fx, fy = np.meshgrid(px[inside][k] + fine, py[inside][k] + fine)
    keep = shape.contains(fx, fy)
    return 2.0 * max(float(d[k]), float(shape.boundary_distance(fx[keep], fy[keep]).max()))


#: solid pieces smaller than this many nodes do not count (a sharp tip leaves a lone node)
MIN_PIECE_NODES = 4


def solid_pieces(shape: Shape, nx: int, ny: int) -> int:
    """How many separate pieces of at least MIN_PIECE_NODES solid nodes the body forms on the
    scoring grid (8-connected flood fill): 1 for a body the lattice resolves, more where a
    part of it (a neck, not a sharp tip) is thinner than a cell."""
    from feelflow.shapes.raster import rasterise

    raster = rasterise(shape, nx, ny)
    solid = raster.box_solid.copy()
    pieces = 0
    h, w = solid.shape
    while solid.any():
        stack = [tuple(np.argwhere(solid)[0])]
        solid[stack[0]] = False
        size = 0
        while stack:
            j, i = stack.pop()
            size += 1
            for dj in (-1, 0, 1):
                for di in (-1, 0, 1):
                    a, b = j + dj, i + di
                    if 0 <= a < h and 0 <= b < w and solid[a, b]:
                        solid[a, b] = False
                        stack.append((a, b))
        pieces += size >= MIN_PIECE_NODES
    return pieces


def _outside(name: str, value: float, rng, unit: str, digits: int = 1) -> str | None:
    lo, hi = rng
    if value < lo - 1e-9:
        return f"{name} is {value:.{digits}f}{unit}, below the smallest allowed {lo:g}{unit}"
    if value > hi + 1e-9:
        return f"{name} is {value:.{digits}f}{unit}, above the largest allowed {hi:g}{unit}"
    return None


def check_shape(exercise, shape: Shape) -> list[str]:
    """Every constraint the shape breaks, in words (empty: it may be scored)."""
    c = exercise.constraints
    problems = []
    if shape.kind not in exercise.kinds:
        return [f"this exercise edits {' or '.join(exercise.kinds)} shapes, not a {shape.kind}"]
    try:
        shape.validate()
    except ShapeError as exc:
        return [str(exc).splitlines()[0]]
    angle = math.degrees(shape.angle)
    if c.angle is not None:
        lo, hi = c.angle
        if lo == hi and abs(angle - lo) > 1e-6:
            problems.append(f"the angle is fixed at {lo:g} degrees; this shape is turned to {angle:.1f}")
        elif lo != hi:
            problems.append(_outside("the angle", angle, c.angle, " degrees"))
    if c.area is not None:
        problems.append(_outside("the area", area(shape), c.area, " cells\u00b2"))
    if c.frontal_height is not None:
        problems.append(_outside("the frontal height (across the stream)", frontal_height(shape),
                                 c.frontal_height, " cells", 2))
    if c.length is not None:
        problems.append(_outside("the length (along the stream)", streamwise_length(shape), c.length, " cells"))
    if c.vertices is not None and isinstance(shape, Polygon):
        n = len(shape.vertices)
        lo, hi = c.vertices
        if n < lo:
            problems.append(f"the polygon has {n} vertices, fewer than the {lo} required")
        elif n > hi:
            problems.append(f"the polygon has {n} vertices, more than the {hi} allowed")
    if c.min_thickness is not None:
        t = thickness(shape)
        if t < c.min_thickness:
            problems.append(f"the body is at most {t:.1f} cells thick, thinner than {c.min_thickness:g} cells: "
                            f"the lattice does not resolve it")
    problems = [p for p in problems if p]
    s = exercise.scene
    body = posed(exercise, shape)
    x0, y0, x1, y1 = body.bounding_box()
    outlet = s.nx - 1 - s.sponge_cells
    if x0 < WALL_MARGIN or y0 < WALL_MARGIN or x1 > outlet - WALL_MARGIN or y1 > s.ny - 1 - WALL_MARGIN:
        problems.append(f"the body does not fit the tunnel: placed at ({s.body_x:g}, {s.body_y:g}) it spans "
                        f"x {x0:.0f}..{x1:.0f}, y {y0:.0f}..{y1:.0f}; it must keep {WALL_MARGIN:g} cells from "
                        f"the walls and the outlet layer (x < {outlet - WALL_MARGIN:g}, y {WALL_MARGIN:g}.."
                        f"{s.ny - 1 - WALL_MARGIN:g})")
    elif not problems:
        pieces = solid_pieces(body, s.nx, s.ny)
        if pieces > 1:
            problems.append(f"on the lattice the body falls into {pieces} separate pieces: a part of it is "
                            f"thinner than a cell")
    return problems


def shape_problems(exercise, shape: Shape | None) -> list[str]:
    """What keeps the student's shape from being scored now, in words: `check_shape`'s list,
    "no shape yet" without one, or the first line of the error of a shape that cannot even be
    measured (empty: it may be scored)."""
    if shape is None:
        return ["no shape yet"]
    try:
        return check_shape(exercise, shape)
    except (ShapeError, ValueError) as exc:
        return [str(exc).splitlines()[0]]
