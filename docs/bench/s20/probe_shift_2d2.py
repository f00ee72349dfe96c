"""Probe (twentieth session, not product code): Schaefer-Turek 2D-2 (or 2D-1) on the uniform
lattice with the cylinder moved by DX, DY cells (the front and back points with it). From the
repository root:

    python docs/bench/s20/probe_shift_2d2.py DX DY D BACKEND [2d1]

A shift of half a cell puts the cylinder's centre on a node instead of between nodes (and moves
it by half a cell in the channel).
"""
import os
import sys

sys.path.insert(0, os.getcwd())

from app.headless import make_solver  # noqa: E402
from solver.validation import schaefer_turek_2d1, schaefer_turek_2d2  # noqa: E402
from solver.validation.schaefer_turek import Geometry  # noqa: E402

sx, sy, d, backend = float(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
case = schaefer_turek_2d1 if sys.argv[5:] == ["2d1"] else schaefer_turek_2d2
_init = Geometry.__init__


def _shifted(self, *a, **k):
    _init(self, *a, **k)
    self.centre, self.front, self.back = ((x + sx, y + sy) for x, y in (self.centre, self.front, self.back))


Geometry.__init__ = _shifted
r = case.run(lambda cfg: make_solver(backend, cfg), resolution=d, backend=backend)
print(case.NAME, d, backend, "shift", sx, sy, {k: round(float(v), 5) for k, v in r.quantities.items()}, flush=True)
