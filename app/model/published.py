"""Published values for a circular cylinder, shown beside what the tunnel measures.

Each series names its source. Where the numbers were taken from a public transcription rather
than read off the paper's own table, the series says where they came from.

Drag coefficient C_D(Re) of the steady or time-mean two-dimensional flow (simulations):
- Dennis, S. C. R. & Chang, G.-Z. 1970, Numerical solutions for steady flow past a circular
  cylinder at Reynolds numbers up to 100, J. Fluid Mech. 42, 471-489: C_D 2.045 at Re 20 and
  1.522 at Re 40 (steady, unconfined; as quoted in public validation suites).
- Posdziech, O. & Grundmann, R. 2007, A systematic approach to the numerical calculation of
  fundamental quantities of the two-dimensional flow over a circular cylinder, J. Fluids Struct.
  23, 479-499: time-mean C_D 1.325 and St 0.1644 at Re 100 (domain-independent limit; as quoted
  in public validation suites).

Strouhal number St(Re) of the laminar vortex street:
- Williamson, C. H. K. 1989, Oblique and parallel modes of vortex shedding in the wake of a
  circular cylinder at low Reynolds numbers, J. Fluid Mech. 206, 579-627: measured St against Re,
  set 2 of the transcription in A. Trettel's `sheardata` (data/E1989001/set_2.csv, CC-BY-4.0;
  cylinder of diameter 0.061, length 200 D, end disks 20.7 D).
- Roshko, A. 1954, On the development of turbulent wakes from vortex streets, NACA Report 1191:
  St = 0.212 (1 - 21.2 / Re) for 50 < Re < 150 (its measurements, fitted to about 1 %).

All are for an unconfined cylinder; the tunnel has walls (blockage D / H), which raise both C_D
and St, and a lattice of a few cells per diameter. Above Re about 190 the real wake turns
three-dimensional and the experiments leave the two-dimensional simulations (Williamson 1996,
Annu. Rev. Fluid Mech. 28, 477): a 2D tunnel follows the simulations.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Series:
    """One published series: points (Re, value), what it is and where it comes from."""

    quantity: str      # "cd" or "st"
    kind: str          # "2D simulation" or "experiment" or "fit to experiments"
    label: str         # short, for a plot legend
    source: str        # the citation
    re: tuple
    value: tuple

    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        return np.asarray(self.re, dtype=np.float64), np.asarray(self.value, dtype=np.float64)


DENNIS_CHANG_1970 = Series(
    "cd", "2D simulation", "Dennis & Chang 1970 (2D, steady)",
    "Dennis & Chang 1970, J. Fluid Mech. 42, 471", (20.0, 40.0), (2.045, 1.522))

POSDZIECH_GRUNDMANN_2007_CD = Series(
    "cd", "2D simulation", "Posdziech & Grundmann 2007 (2D, time mean)",
    "Posdziech & Grundmann 2007, J. Fluids Struct. 23, 479", (100.0,), (1.325,))

POSDZIECH_GRUNDMANN_2007_ST = Series(
    "st", "2D simulation", "Posdziech & Grundmann 2007 (2D)",
    "Posdziech & Grundmann 2007, J. Fluids Struct. 23, 479", (100.0,), (0.1644,))

WILLIAMSON_1989 = Series(
    "st", "experiment", "Williamson 1989 (experiment)",
    "Williamson 1989, J. Fluid Mech. 206, 579; sheardata E1989001 set 2 (CC-BY-4.0)",
    (49.0, 49.3, 51.2, 52.9, 55.2, 57.1, 59.1, 61.2, 63.0, 65.0, 66.9, 69.5, 72.4, 75.1, 77.8, 80.1,
     82.6, 85.2, 87.5, 90.1, 92.8, 95.1, 97.7, 100.1, 102.6, 104.9, 107.3, 110.1, 112.3, 115.1, 117.7,
     120.2, 122.3, 125.2, 127.4, 130.1, 132.5, 135.0, 137.6, 139.8, 142.6, 145.3, 147.5, 149.9, 152.5,
     155.2, 157.6, 160.2, 162.8, 165.0, 167.6, 170.0, 172.3, 174.4, 175.0, 176.1, 177.9),
    (0.1183, 0.1189, 0.1226, 0.1243, 0.1280, 0.1307, 0.1333, 0.1351, 0.1368, 0.1389, 0.1369, 0.1395,
     0.1416, 0.1438, 0.1463, 0.1481, 0.1497, 0.1514, 0.1529, 0.1547, 0.1561, 0.1577, 0.1591, 0.1604,
     0.1617, 0.1629, 0.1644, 0.1655, 0.1668, 0.1680, 0.1691, 0.1701, 0.1711, 0.1723, 0.1731, 0.1740,
     0.1749, 0.1758, 0.1765, 0.1770, 0.1776, 0.1785, 0.1792, 0.1798, 0.1804, 0.1809, 0.1816, 0.1822,
     0.1829, 0.1834, 0.1841, 0.1847, 0.1853, 0.1856, 0.1858, 0.1860, 0.1865))

#: Roshko's fit and where it holds
ROSHKO_RANGE = (50.0, 150.0)


def roshko_strouhal(re):
    """St = 0.212 (1 - 21.2 / Re) (Roshko 1954, NACA Report 1191; 50 < Re < 150)."""
    re = np.asarray(re, dtype=np.float64)
    return 0.212 * (1.0 - 21.2 / re)


DRAG = (DENNIS_CHANG_1970, POSDZIECH_GRUNDMANN_2007_CD)
STROUHAL = (WILLIAMSON_1989, POSDZIECH_GRUNDMANN_2007_ST)


def published_drag(re: float):
    """(C_D, source) of the 2D simulations at `re`, interpolated log-log between their points
    (Re 20 - 100), or None outside that range."""
    pts = sorted((r, v, s.source) for s in DRAG for r, v in zip(s.re, s.value))
    res = np.array([p[0] for p in pts])
    if not (res[0] <= re <= res[-1]):
        return None
    cd = float(np.exp(np.interp(np.log(re), np.log(res), np.log([p[1] for p in pts]))))
    k = int(np.searchsorted(res, re))
    lo, hi = pts[max(0, k - 1)], pts[min(len(pts) - 1, k)]
    sources = lo[2] if lo[2] == hi[2] else f"{lo[2]}; {hi[2]}"
    return cd, sources


def published_drag_force(speeds, diameter: float, nu: float):
    """(speeds, F_x) of the published 2D C_D(Re) at Re = U D / nu, per unit span in lattice units
    (F = C_D rho U^2 D / 2), for the speeds whose Re the series cover; for the drag-against-speed
    plot."""
    us, fs = [], []
    for u in np.asarray(speeds, dtype=np.float64):
        got = published_drag(u * diameter / nu)
        if got is not None:
            us.append(u)
            fs.append(0.5 * got[0] * u * u * diameter)
    return np.array(us), np.array(fs)


def published_strouhal(re: float):
    """(St, source) at `re`: Williamson's measurements interpolated (Re 49 - 178), else None."""
    res, st = WILLIAMSON_1989.arrays()
    if not (res[0] <= re <= res[-1]):
        return None
    return float(np.interp(re, res, st)), "Williamson 1989"


def measured_strouhal(time, lift, diameter: float, speed: float, periods: int = 3):
    """St = f D / U of the lift's swing over the history (time in steps, lift per sample), from
    the upward zero crossings of lift - mean over its last half (interpolated, as
    solver/validation/strouhal.py does); None until `periods` full periods are in it."""
    from feelflow.solver.validation.strouhal import shedding_period

    t, cl = np.asarray(time, dtype=np.float64), np.asarray(lift, dtype=np.float64)
    ok = np.isfinite(cl)
    t, cl = t[ok], cl[ok]
    if len(t) < 8 or speed <= 0:
        return None
    half = len(t) // 2
    swing = cl[half:] - cl[half:].mean()
    if np.abs(swing).max() < 1e-9:
        return None
    got = shedding_period(t[half:], cl[half:])
    if len(got) < periods:
        return None
    return diameter / (float(np.median(got)) * speed)


def strouhal_text(time, lift, diameter: float, speed: float, re: float) -> str:
    """The readout beside a cylinder's coefficients: the measured St and, where the published
    measurements cover Re, theirs ("" until the lift swings)."""
    st = measured_strouhal(time, lift, diameter, speed)
    if st is None:
        return ""
    ref = published_strouhal(re)
    return f"St {st:.3f}" + (f" (measured at Re {re:.0f}: {ref[0]:.3f}, {ref[1]})" if ref is not None else "")
