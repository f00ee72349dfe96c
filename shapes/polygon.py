"""Simple polygons and the parametric bodies built from them (plate, wedge, half airfoil).

Vertices are given in body-local coordinates about the reference point (x, y) and turned by
`angle` (radians, counter-clockwise). Internally they are kept counter-clockwise, so the outward
normal of the edge a -> b is (b - a) rotated by -90 degrees. Cut fractions are exact: the link
p + t d is intersected with every edge and the smallest t in (0, 1] wins.
Parametric bodies put their reference point at the area centroid (rotation about it).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from feelflow.shapes.base import Shape, ShapeError
from feelflow.shapes.validation import (MAX_SIZE, check_extent, check_in_domain, check_pose, finite_number, positive_number,
                               unit_direction)

#: points closer than this to an edge count as on the boundary (and so inside)
BOUNDARY_TOLERANCE = 1e-9
#: slack on the edge parameter so a link through a vertex is not missed by round-off
EDGE_SLACK = 1e-12


def polygon_area_centroid(vertices: np.ndarray) -> tuple[float, float, float]:
    """Signed area (positive when counter-clockwise) and area centroid (shoelace formula)."""
    x, y = vertices[:, 0], vertices[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = 0.5 * float(cross.sum())
    if area == 0.0:
        return 0.0, float(x.mean()), float(y.mean())
    cx = float(((x + xn) * cross).sum()) / (6.0 * area)
    cy = float(((y + yn) * cross).sum()) / (6.0 * area)
    return area, cx, cy


def _segments_intersect(a, b, c, d) -> np.ndarray:
    """Do closed segments a-b and c-d (arrays (..., 2)) share a point?"""
    def cross(o, p, q):
        return (p[..., 0] - o[..., 0]) * (q[..., 1] - o[..., 1]) - (p[..., 1] - o[..., 1]) * (q[..., 0] - o[..., 0])

    def on_segment(o, p, q):  # q collinear with o-p: within its box?
        return ((np.minimum(o[..., 0], p[..., 0]) <= q[..., 0]) & (q[..., 0] <= np.maximum(o[..., 0], p[..., 0]))
                & (np.minimum(o[..., 1], p[..., 1]) <= q[..., 1]) & (q[..., 1] <= np.maximum(o[..., 1], p[..., 1])))

    d1, d2 = cross(c, d, a), cross(c, d, b)
    d3, d4 = cross(a, b, c), cross(a, b, d)
    proper = (((d1 > 0) & (d2 < 0)) | ((d1 < 0) & (d2 > 0))) & (((d3 > 0) & (d4 < 0)) | ((d3 < 0) & (d4 > 0)))
    touch = (((d1 == 0) & on_segment(c, d, a)) | ((d2 == 0) & on_segment(c, d, b))
             | ((d3 == 0) & on_segment(a, b, c)) | ((d4 == 0) & on_segment(a, b, d)))
    return proper | touch


def _flat_points(px, py):
    """Points as (N, 1) columns for broadcasting against edges, and their original shape."""
    px, py = np.broadcast_arrays(np.asarray(px, dtype=np.float64), np.asarray(py, dtype=np.float64))
    return px.reshape(-1, 1), py.reshape(-1, 1), px.shape


def edge_distance(qx, qy, ax, ay, ex, ey):
    """Distance from points q to edges a -> a + e (element-wise, broadcasting)."""
    len2 = ex * ex + ey * ey
    wx, wy = qx - ax, qy - ay
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.clip((wx * ex + wy * ey) / len2, 0.0, 1.0)
    t = np.where(len2 > 0.0, t, 0.0)
    return np.hypot(wx - t * ex, wy - t * ey)


def edge_crossing_x(qy, ax, ay, ex, ey):
    """For the horizontal line y = qy: does edge a -> a + e straddle it (half-open rule), and at
    which x (element-wise, broadcasting; x meaningless where it does not straddle)."""
    straddle = (ay > qy) != ((ay + ey) > qy)
    with np.errstate(invalid="ignore", divide="ignore"):
        xcross = ax + (qy - ay) * ex / ey
    return straddle, xcross


def link_edge_hit(px, py, dx, dy, ax, ay, ex, ey):
    """Parameter t in (0, 1] where segment p -> p + d crosses edge a -> a + e, inf if it does not
    (element-wise, broadcasting; parallel segments never cross)."""
    denom = dx * ey - dy * ex
    wx, wy = ax - px, ay - py
    with np.errstate(invalid="ignore", divide="ignore"):
        t = (wx * ey - wy * ex) / denom
        s = (wx * dy - wy * dx) / denom
    hit = ((denom != 0.0) & (t > 0.0) & (t <= 1.0 + EDGE_SLACK)
           & (s >= -EDGE_SLACK) & (s <= 1.0 + EDGE_SLACK))
    return np.where(hit, t, np.inf)


@lru_cache(maxsize=256)
def _polygon_problem(kind: str, vertices: tuple) -> str | None:
    """What makes the polygon invalid (too few vertices, repeated vertex, zero area,
    self-intersection), or None. O(n^2); cached, as the vertices do not change with the pose."""
    v = np.array(vertices, dtype=np.float64)
    n = len(v)
    if n < 3:
        return f"{kind} needs at least 3 vertices, got {n}"
    e = np.roll(v, -1, axis=0) - v
    length = np.hypot(e[:, 0], e[:, 1])
    if np.any(length == 0.0):
        i = int(np.argmax(length == 0.0))
        return f"{kind} has a repeated vertex ({v[i, 0]:g}, {v[i, 1]:g})"
    scale = float(np.ptp(v, axis=0).max())
    rel = v - v[0]
    far = rel[np.argmax(np.hypot(rel[:, 0], rel[:, 1]))]
    spread = np.abs(rel[:, 0] * far[1] - rel[:, 1] * far[0]).max()  # all on one line: 0
    if spread <= 1e-12 * scale * scale:
        return f"{kind} has zero area (its vertices are collinear)"
    # neighbouring edges meet at their shared vertex; they must not fold back onto each other
    en = np.roll(e, -1, axis=0)
    folded = (e[:, 0] * en[:, 1] - e[:, 1] * en[:, 0] == 0.0) & ((e * en).sum(axis=1) < 0.0)
    if np.any(folded):
        k = int(np.argmax(folded))
        return f"{kind} is self-intersecting (edges {k} and {(k + 1) % n} fold back)"
    # other edge pairs must not meet at all; in blocks of edges to bound memory
    b = np.roll(v, -1, axis=0)
    block = max(1, 1_000_000 // n)
    for start in range(0, n, block):
        i, j = np.meshgrid(np.arange(start, min(n, start + block)), np.arange(n), indexing="ij")
        keep = (j >= i + 2) & ~((i == 0) & (j == n - 1))  # first and last edges are neighbours
        i, j = i[keep], j[keep]
        crossing = _segments_intersect(v[i], b[i], v[j], b[j])
        if np.any(crossing):
            k = int(np.argmax(crossing))
            return f"{kind} is self-intersecting (edges {i[k]} and {j[k]} cross)"
    if abs(polygon_area_centroid(v)[0]) <= 1e-12 * scale * scale:
        return f"{kind} has zero area"
    return None


@dataclass(frozen=True, init=False)
class PolygonalShape(Shape):
    """Geometry shared by every body whose boundary is a polygon; subclasses give local vertices."""

    kind = "polygonal"

    def _set_geometry(self, local: np.ndarray) -> None:
        """Store counter-clockwise local vertices and their world positions (called by __init__)."""
        for name in ("x", "y", "angle"):
            object.__setattr__(self, name, finite_number(f"{self.kind} {name}", getattr(self, name)))
        local = np.asarray(local, dtype=np.float64)
        if polygon_area_centroid(local)[0] < 0.0:
            local = local[::-1]
        c, s = math.cos(self.angle), math.sin(self.angle)
        world = local @ np.array([[c, s], [-s, c]]) + np.array([self.x, self.y])
        object.__setattr__(self, "_local", local)
        object.__setattr__(self, "_world", world)
        edges = np.roll(world, -1, axis=0) - world
        object.__setattr__(self, "_edges", edges)

    @property
    def world_edges(self) -> tuple[np.ndarray, np.ndarray]:
        """(vertices, edge vectors), each (n, 2), world coordinates, read-only views (no copy:
        the rasteriser reads them for every node row)."""
        return self._world, self._edges

    @property
    def world_vertices(self) -> np.ndarray:
        """(n, 2) counter-clockwise vertices in world coordinates."""
        return self._world.copy()

    @property
    def local_vertices(self) -> np.ndarray:
        """(n, 2) counter-clockwise vertices about the reference point, before rotation."""
        return self._local.copy()

    @property
    def area(self) -> float:
        return abs(polygon_area_centroid(self._local)[0])

    # --- point and segment queries (vectorised over points x edges) -------------------------
    def boundary_distance(self, px, py):
        """Unsigned distance from points to the nearest edge."""
        qx, qy, shape = _flat_points(px, py)
        a, e = self._world, self._edges
        dist = edge_distance(qx, qy, a[:, 0], a[:, 1], e[:, 0], e[:, 1]).min(axis=1)
        return dist.reshape(shape)

    def contains(self, px, py):
        """Even-odd crossing test, with points within BOUNDARY_TOLERANCE of an edge inside."""
        qx, qy, shape = _flat_points(px, py)
        a, e = self._world, self._edges
        straddle, xcross = edge_crossing_x(qy, a[:, 0], a[:, 1], e[:, 0], e[:, 1])
        inside = (np.count_nonzero(straddle & (qx < xcross), axis=1) % 2) == 1
        near = edge_distance(qx, qy, a[:, 0], a[:, 1], e[:, 0], e[:, 1]).min(axis=1) <= BOUNDARY_TOLERANCE
        return (inside | near).reshape(shape)

    def segment_hit(self, px, py, dx, dy):
        px, py, dx, dy = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in (px, py, dx, dy)))
        shape = px.shape
        a, e = self._world, self._edges
        t = link_edge_hit(px.reshape(-1, 1), py.reshape(-1, 1), dx.reshape(-1, 1), dy.reshape(-1, 1),
                          a[:, 0], a[:, 1], e[:, 0], e[:, 1])
        first = t.min(axis=1)
        first = np.where(np.isfinite(first), np.minimum(first, 1.0), 0.0)
        return first.reshape(shape)

    def edge_pieces(self, max_length: float = 1.0):
        """Edges cut into equal pieces no longer than `max_length`: (edge index (k,), piece
        midpoints (k, 2), piece lengths (k,)); zero-length edges are skipped."""
        e = self._edges
        length = np.hypot(e[:, 0], e[:, 1])
        pieces = np.where(length > 0.0, np.maximum(1, np.ceil(length / max_length)), 0).astype(np.int64)
        edge = np.repeat(np.arange(len(length)), pieces)
        k = np.arange(edge.size) - np.repeat(np.cumsum(pieces) - pieces, pieces)
        frac = (k + 0.5) / pieces[edge]
        return edge, self._world[edge] + frac[:, None] * e[edge], (length[edge] / pieces[edge])

    # --- geometry for drawing and forces ------------------------------------------------------
    def outline(self) -> np.ndarray:
        return np.vstack([self._world, self._world[:1]])

    def frontal_area(self, flow_direction) -> float:
        d = unit_direction(flow_direction)
        proj = self._world @ np.array([-d[1], d[0]])
        return float(proj.max() - proj.min())

    def surface_elements(self, spacing: float = 0.5):
        """Each edge cut into ceil(length/spacing) equal pieces: midpoints, outward normals, lengths."""
        edge, points, lengths = self.edge_pieces(positive_number("surface element spacing", spacing))
        e = self._edges[edge]
        normals = np.column_stack([e[:, 1], -e[:, 0]]) / np.hypot(e[:, 0], e[:, 1])[:, None]
        return points, normals, lengths

    def bounding_box(self):
        lo = self._world.min(axis=0)
        hi = self._world.max(axis=0)
        return (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))

    # --- validation ---------------------------------------------------------------------------
    def check_polygon(self) -> None:
        """Enough distinct vertices, non-zero area, no self-intersection (cached per vertex list)."""
        vertices = self.vertices if self.user_vertices else tuple(map(tuple, self._local.tolist()))
        problem = _polygon_problem(self.kind, vertices)
        if problem:
            raise ShapeError(problem)

    def validate(self, nx=None, ny=None):
        check_pose(self)
        if self.user_vertices:
            self.check_polygon()
        check_extent(self)
        check_in_domain(self, nx, ny)
        return self

    #: True when the vertices come from the user (checked by validate); parametric bodies are
    #: simple polygons by construction once their parameters passed the constructor's checks
    user_vertices = False


#: most vertices a polygon may have: the simplicity check is O(n^2) and the rasteriser walks
#: every edge for every link, so 1000 vertices (finer than any 2D lattice body needs) stay fast
MAX_VERTICES = 1000


def _is_real(c) -> bool:
    return isinstance(c, (int, float, np.integer, np.floating)) and not isinstance(c, (bool, np.bool_))


def _vertex_tuple(vertices) -> tuple[tuple[float, float], ...]:
    if isinstance(vertices, (list, tuple)):
        if len(vertices) > MAX_VERTICES:
            raise ShapeError(f"polygon has {len(vertices)} vertices, at most {MAX_VERTICES}")
        if not all(isinstance(v, (list, tuple)) and len(v) == 2 and all(map(_is_real, v)) for v in vertices):
            raise ShapeError("polygon vertices must be a list of (x, y) number pairs (not text or true/false)")
    elif isinstance(vertices, np.ndarray) and vertices.dtype.kind not in "iuf":
        raise ShapeError("polygon vertices must be a list of (x, y) number pairs")
    try:
        arr = np.asarray(vertices, dtype=np.float64)
    except (TypeError, ValueError):
        raise ShapeError("polygon vertices must be a list of (x, y) number pairs") from None
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise ShapeError("polygon vertices must be a list of (x, y) number pairs")
    if arr.shape[0] > MAX_VERTICES:
        raise ShapeError(f"polygon has {arr.shape[0]} vertices, at most {MAX_VERTICES}")
    if arr.shape[0] < 3:
        raise ShapeError(f"polygon needs at least 3 vertices, got {arr.shape[0]}")
    if not np.all(np.isfinite(arr)):
        k = int(np.argmax(~np.all(np.isfinite(arr), axis=1)))
        raise ShapeError(f"polygon vertex {k} is not finite: ({arr[k, 0]}, {arr[k, 1]})")
    if np.abs(arr).max() > MAX_SIZE:   # body-local: such a body fits no grid (and overflows the area sums)
        k = int(np.argmax(np.abs(arr).max(axis=1)))
        raise ShapeError(f"polygon vertex {k} lies {np.abs(arr[k]).max():.3g} cells from the body's reference "
                         f"point, more than {MAX_SIZE:g} (the largest grid)")
    return tuple((float(px), float(py)) for px, py in arr)


@dataclass(frozen=True, init=False)
class Polygon(PolygonalShape):
    """Any simple polygon; `vertices` are body-local, about the reference point (x, y)."""

    vertices: tuple = ()

    kind = "polygon"
    user_vertices = True

    def __init__(self, vertices, x=0.0, y=0.0, angle=0.0):
        object.__setattr__(self, "vertices", _vertex_tuple(vertices))
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "y", y)
        object.__setattr__(self, "angle", angle)
        self._set_geometry(np.array(self.vertices))

    @classmethod
    def from_world(cls, points, angle: float = 0.0) -> "Polygon":
        """A polygon from world-coordinate points, with its reference point at the area centroid."""
        pts = np.array(_vertex_tuple(points))
        _, cx, cy = polygon_area_centroid(pts)
        c, s = math.cos(angle), math.sin(angle)
        local = (pts - [cx, cy]) @ np.array([[c, -s], [s, c]])  # undo the rotation
        return cls(local, x=cx, y=cy, angle=angle)

    def to_dict(self) -> dict:
        return {"kind": self.kind, "vertices": [list(v) for v in self.vertices],
                "x": self.x, "y": self.y, "angle": self.angle}


def _centred(points: np.ndarray) -> np.ndarray:
    _, cx, cy = polygon_area_centroid(points)
    return points - np.array([cx, cy])


@lru_cache(maxsize=64)
def _plate_vertices(length: float, thickness: float) -> np.ndarray:
    h, t = 0.5 * length, 0.5 * thickness
    return np.array([[-t, -h], [t, -h], [t, h], [-t, h]])


@dataclass(frozen=True, init=False)
class FlatPlate(PolygonalShape):
    """Rectangle `length` x `thickness`. At angle 0 the long side lies along y, so the plate
    stands normal to a flow along +x (the seed's "|"); angle = pi/2 lays it along the flow.
    `thickness` may be far below one cell: links across it are still cut from both sides."""

    length: float = 1.0
    thickness: float = 1.0

    kind = "plate"

    def reference_length(self) -> float:
        return float(self.length)

    def __init__(self, length, thickness, x=0.0, y=0.0, angle=0.0):
        object.__setattr__(self, "length", positive_number("plate length", length))
        object.__setattr__(self, "thickness", positive_number("plate thickness", thickness))
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "y", y)
        object.__setattr__(self, "angle", angle)
        self._set_geometry(_plate_vertices(self.length, self.thickness))

    def to_dict(self) -> dict:
        return {"kind": self.kind, "length": self.length, "thickness": self.thickness,
                "x": self.x, "y": self.y, "angle": self.angle}


WEDGE_POINTING = ("upstream", "downstream")


@lru_cache(maxsize=64)
def _wedge_vertices(length: float, apex_angle: float, pointing: str) -> np.ndarray:
    h = length * math.tan(0.5 * apex_angle)
    pts = np.array([[0.0, 0.0], [length, -h], [length, h]])  # apex at the left: "<"
    if pointing == "downstream":
        pts = np.array([[length, 0.0], [0.0, h], [0.0, -h]])  # apex at the right: ">"
    return _centred(pts)


@dataclass(frozen=True, init=False)
class Wedge(PolygonalShape):
    """Isosceles triangle: apex, then a base `length` further along x, opening `apex_angle`
    (radians, strictly between 0 and pi). "upstream": apex towards -x (the seed's "<"),
    "downstream": apex towards +x (">"). Base width = 2 length tan(apex_angle / 2)."""

    length: float = 1.0
    apex_angle: float = 1.0
    pointing: str = "upstream"

    kind = "wedge"

    def reference_length(self) -> float:
        return float(self.length)

    def __init__(self, length, apex_angle, pointing="upstream", x=0.0, y=0.0, angle=0.0):
        object.__setattr__(self, "length", positive_number("wedge length", length))
        apex = finite_number("wedge apex_angle", apex_angle)
        if not 0.0 < apex < math.pi:
            raise ShapeError(f"wedge apex_angle must be between 0 and pi radians (exclusive), got {apex:g}")
        object.__setattr__(self, "apex_angle", apex)
        if pointing not in WEDGE_POINTING:
            raise ShapeError(f"wedge pointing must be 'upstream' or 'downstream', got {pointing!r}")
        object.__setattr__(self, "pointing", pointing)
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "y", y)
        object.__setattr__(self, "angle", angle)
        self._set_geometry(_wedge_vertices(self.length, self.apex_angle, self.pointing))

    def to_dict(self) -> dict:
        return {"kind": self.kind, "length": self.length, "apex_angle": self.apex_angle,
                "pointing": self.pointing, "x": self.x, "y": self.y, "angle": self.angle}


def naca_half_thickness(s: np.ndarray) -> np.ndarray:
    """NACA 4-digit symmetric thickness distribution per unit thickness ratio, closed trailing
    edge (coefficient -0.1036): y_t / (t c) at s = x / c (Abbott & von Doenhoff 1959, sec. 6.4)."""
    return 5.0 * (0.2969 * np.sqrt(s) - 0.1260 * s - 0.3516 * s**2 + 0.2843 * s**3 - 0.1036 * s**4)


@lru_cache(maxsize=64)
def _half_airfoil_vertices(chord: float, thickness: float) -> np.ndarray:
    m = max(32, int(math.ceil(2.0 * chord)))                 # upper-surface points
    beta = np.linspace(0.0, math.pi, m + 1)[1:-1]            # cosine spacing, ends excluded
    s = 0.5 * (1.0 - np.cos(beta))[::-1]                     # from trailing to leading edge
    fine = naca_half_thickness(np.linspace(0.0, 1.0, 2001))
    upper = np.column_stack([chord * s, thickness * naca_half_thickness(s) / fine.max()])
    pts = np.vstack([[[0.0, 0.0], [chord, 0.0]], upper])     # lower side LE -> TE, upper TE -> LE
    return _centred(pts)


@dataclass(frozen=True, init=False)
class HalfAirfoil(PolygonalShape):
    """Upper half of a NACA 00xx section: flat lower side along +x from the leading edge (at -x,
    upstream) to the trailing edge, curved upper side of maximum height `thickness` (at 30 %
    chord); the seed's lift body. Upper side sampled with max(32, 2 chord) cosine-spaced points."""

    chord: float = 1.0
    thickness: float = 1.0

    kind = "half_airfoil"

    def reference_length(self) -> float:
        return float(self.chord)

    def __init__(self, chord, thickness, x=0.0, y=0.0, angle=0.0):
        object.__setattr__(self, "chord", positive_number("half_airfoil chord", chord))
        object.__setattr__(self, "thickness", positive_number("half_airfoil thickness", thickness))
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "y", y)
        object.__setattr__(self, "angle", angle)
        self._set_geometry(_half_airfoil_vertices(self.chord, self.thickness))

    def to_dict(self) -> dict:
        return {"kind": self.kind, "chord": self.chord, "thickness": self.thickness,
                "x": self.x, "y": self.y, "angle": self.angle}
