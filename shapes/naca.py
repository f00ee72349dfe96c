"""NACA 4-digit airfoil sections (Abbott & von Doenhoff 1959, *Theory of Wing Sections*, sec. 6.4).

With s = x / c along the chord, t the maximum thickness, m the maximum camber and p its chordwise
position (all fractions of the chord c; "NACA mpxx" is m = m/100, p = p/10, t = xx/100):

  thickness   y_t / c = 5 t (0.2969 sqrt(s) - 0.1260 s - 0.3516 s^2 + 0.2843 s^3 - 0.1036 s^4)
              (the closed trailing edge variant: -0.1036 instead of the tabulated -0.1015, so
              both sides meet in one point at s = 1)
  mean line   y_c / c = m / p^2 (2 p s - s^2)                  for s < p,
              y_c / c = m / (1 - p)^2 ((1 - 2p) + 2 p s - s^2)  for s >= p
  surface     the thickness laid off normal to the mean line: with theta = atan(dy_c / dx),
              upper (x - y_t sin theta, y_c + y_t cos theta), lower (x + y_t sin theta, y_c - y_t cos theta).

The section is a polygon (`PolygonalShape`) with `max(48, 2 chord)` cosine-spaced stations per
side (dense at the nose and the tail, where the surface turns fastest). At angle 0 the chord
lies along +x with the leading edge upstream (at -x); the reference point is the area centroid,
as for the other parametric bodies. The pose angle is counter-clockwise, so a positive angle of
attack alpha (nose up in a flow along +x) is `angle = -alpha`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from feelflow.shapes.base import ShapeError
from feelflow.shapes.polygon import PolygonalShape, _centred, naca_half_thickness
from feelflow.shapes.validation import finite_number, positive_number

#: accepted ranges (fractions of the chord): the 4-digit series spans camber 0 - 9.5 %, position
#: 10 - 90 %, thickness up to 40 % (thicker sections are no longer airfoil-like)
MAX_THICKNESS = 0.4
MIN_THICKNESS = 0.01
MAX_CAMBER = 0.095
CAMBER_POSITION_RANGE = (0.1, 0.9)


def camber_line(s, camber: float, position: float):
    """(y_c / c, dy_c / dx) of the 4-digit mean line at s = x / c (module docstring)."""
    s = np.asarray(s, dtype=np.float64)
    if camber == 0.0:
        return np.zeros_like(s), np.zeros_like(s)
    m, p = camber, position
    front = s < p
    yc = np.where(front, m / p**2 * (2 * p * s - s**2), m / (1 - p) ** 2 * ((1 - 2 * p) + 2 * p * s - s**2))
    slope = np.where(front, 2 * m / p**2 * (p - s), 2 * m / (1 - p) ** 2 * (p - s))
    return yc, slope


def stations(chord: float) -> np.ndarray:
    """Cosine-spaced s = x / c from 0 to 1 (both ends included), `max(48, 2 chord)` intervals."""
    n = max(48, int(math.ceil(2.0 * chord)))
    return 0.5 * (1.0 - np.cos(np.linspace(0.0, math.pi, n + 1)))


def surface(s, thickness: float, camber: float, position: float):
    """((x_u, y_u), (x_l, y_l)) per unit chord at the stations s (module docstring)."""
    yt = thickness * naca_half_thickness(np.asarray(s, dtype=np.float64))
    yc, slope = camber_line(s, camber, position)
    theta = np.arctan(slope)
    upper = (s - yt * np.sin(theta), yc + yt * np.cos(theta))
    lower = (s + yt * np.sin(theta), yc - yt * np.cos(theta))
    return upper, lower


@lru_cache(maxsize=64)
def _naca_vertices(chord: float, thickness: float, camber: float, position: float) -> np.ndarray:
    s = stations(chord)
    (xu, yu), (xl, yl) = surface(s, thickness, camber, position)
    # counter-clockwise: trailing edge, upper side to the nose, lower side back (nose and tail once)
    x = np.concatenate([xu[::-1], xl[1:-1]])
    y = np.concatenate([yu[::-1], yl[1:-1]])
    return _centred(chord * np.column_stack([x, y]))


def _fraction(name: str, value, lo: float, hi: float) -> float:
    v = finite_number(name, value)
    if not lo <= v <= hi:
        raise ShapeError(f"{name} must be between {lo:g} and {hi:g} (a fraction of the chord), got {v:g}")
    return v


@dataclass(frozen=True, init=False)
class NacaAirfoil(PolygonalShape):
    """NACA 4-digit section: `chord` in cells, `thickness`, `camber`, `camber_position` as
    fractions of the chord (NACA 4412: 0.12, 0.04, 0.4). Closed trailing edge."""

    chord: float = 1.0
    thickness: float = 0.12
    camber: float = 0.0
    camber_position: float = 0.4

    kind = "naca"

    def reference_length(self) -> float:
        return float(self.chord)

    def __init__(self, chord, thickness=0.12, camber=0.0, camber_position=0.4, x=0.0, y=0.0, angle=0.0):
        object.__setattr__(self, "chord", positive_number("naca chord", chord))
        object.__setattr__(self, "thickness", _fraction("naca thickness", thickness, MIN_THICKNESS, MAX_THICKNESS))
        object.__setattr__(self, "camber", _fraction("naca camber", camber, 0.0, MAX_CAMBER))
        object.__setattr__(self, "camber_position", _fraction("naca camber_position", camber_position,
                                                              *CAMBER_POSITION_RANGE))
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "y", y)
        object.__setattr__(self, "angle", angle)
        self._set_geometry(_naca_vertices(self.chord, self.thickness, self.camber, self.camber_position))

    @classmethod
    def from_digits(cls, digits: str, chord: float, x=0.0, y=0.0, angle=0.0) -> "NacaAirfoil":
        """"4412" -> camber 0.04 at 0.4 chord, thickness 0.12; ShapeError for anything else."""
        text = str(digits).strip().upper().removeprefix("NACA").strip()
        if len(text) != 4 or not text.isdigit():
            raise ShapeError(f"a NACA 4-digit designation is four digits such as 0012 or 4412, got {str(digits)[:20]!r}")
        m, p, t = int(text[0]) / 100.0, int(text[1]) / 10.0, int(text[2:]) / 100.0
        if m > 0 and p == 0:
            raise ShapeError(f"NACA {text}: a cambered section needs the camber position (second digit) 1 - 9")
        return cls(chord, t, m, p if m > 0 else 0.4, x, y, angle)

    @property
    def digits(self) -> str | None:
        """The 4-digit designation when the parameters are whole digits ("0012"), else None."""
        m, p, t = self.camber * 100, self.camber_position * 10, self.thickness * 100
        whole = all(abs(v - round(v)) < 1e-9 for v in (m, t)) and (self.camber == 0 or abs(p - round(p)) < 1e-9)
        if not whole or round(m) > 9 or round(t) > 99:
            return None
        return f"{round(m)}{round(p) if self.camber else 0}{round(t):02d}"

    def leading_trailing_edges(self) -> tuple[np.ndarray, np.ndarray]:
        """World positions of the leading edge (nose) and the trailing edge."""
        local = _naca_vertices(self.chord, self.thickness, self.camber, self.camber_position)
        n = len(stations(self.chord)) - 1
        c, s = math.cos(self.angle), math.sin(self.angle)
        rot = np.array([[c, s], [-s, c]])
        nose, tail = local[n], local[0]
        return nose @ rot + [self.x, self.y], tail @ rot + [self.x, self.y]

    def to_dict(self) -> dict:
        return {"kind": self.kind, "chord": self.chord, "thickness": self.thickness, "camber": self.camber,
                "camber_position": self.camber_position, "x": self.x, "y": self.y, "angle": self.angle}
