"""Probe (twentieth session, not product code): Schaefer-Turek 2D-2 on the numpy reference with a
refined patch of any size and any U_m, numpy float32. From the repository root:

    python docs/bench/s20/probe_refine_2d2.py D U_M UP DOWN HALF

runs `solver.validation.schaefer_turek_2d2.run` with `RefinedSolver` on the patch from UP diameters
ahead of the cylinder's centre to DOWN behind it and HALF to each side (the product's
`Geometry.refined_patch` is 1 / 3 / 1), and prints the case's quantities. Set FF_ABSORB to change
the outlet sponge's absorbing strength (the case's 0.1), FF_SHIFT=DX,DY to move the cylinder by
DX, DY coarse cells (the patch stays where it was), and FF_VARIANT to try a variant of the level
coupling (patched here, not in the product):
  ring-t1   the fine ring's second step takes the coarse border at t + 1, not the mean of t, t + 1;
  margin3   the restriction keeps 3 coarse cells inside the border, not 1;
  odd-even  the odd non-equilibrium scaled with the even part's ratio;
  odd-half  the odd non-equilibrium scaled by 0.5.
"""
import dataclasses
import math
import os
import sys
import time

sys.path.insert(0, os.getcwd())

import numpy as np  # noqa: E402

from solver.body import shifted, unshifted  # noqa: E402
from solver.refinement import RefinedSolver  # noqa: E402
from solver.validation import schaefer_turek as st  # noqa: E402
from solver.validation import schaefer_turek_2d2 as case  # noqa: E402

d, u, up, down, half = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
st.Geometry.__init__.__defaults__ = (u,)
if os.environ.get("FF_ABSORB"):
    case.SPONGE_ABSORB = float(os.environ["FF_ABSORB"])
shift_x, shift_y = (float(v) for v in os.environ.get("FF_SHIFT", "0,0").split(","))
if shift_x or shift_y:  # move the cylinder (and the front and back points) by whole or partial cells
    _init = st.Geometry.__init__

    def _shifted(self, *a, **k):
        _init(self, *a, **k)
        self.centre, self.front, self.back = ((x + shift_x, y + shift_y) for x, y in (self.centre, self.front, self.back))

    st.Geometry.__init__ = _shifted
variant = os.environ.get("FF_VARIANT", "")
if variant == "ring-t1":
    RefinedSolver._ring_between = staticmethod(lambda ring_t, ring_t1: ring_t1)
elif variant == "margin3":
    def _restrict3(self):
        x0, y0, x1, y1 = self.patch
        f = unshifted(self.fine.g[:, 6:-6:2, 6:-6:2].astype(np.float64))
        self.coarse.g[:, y0 + 3:y1 - 2, x0 + 3:x1 - 2] = shifted(self._rescaled(f, self._to_coarse)).astype(self.coarse.g.dtype)

    RefinedSolver._restrict = _restrict3
elif variant in ("odd-even", "odd-half"):
    _init_solver = RefinedSolver.__init__

    def _init_odd(self, *a, **k):
        _init_solver(self, *a, **k)
        odd = self._to_fine[0] if variant == "odd-even" else 0.5
        self._to_fine = (self._to_fine[0], odd)
        self._to_coarse = (1.0 / self._to_fine[0], 1.0 / odd)

    RefinedSolver.__init__ = _init_odd
cx = cy = 2 * d - 0.5
patch = (math.floor(cx - up * d), math.floor(cy - half * d), math.ceil(cx + down * d), math.ceil(cy + half * d))
t = time.time()
r = case.run(lambda cfg: RefinedSolver(dataclasses.replace(cfg, dtype="float32"), patch), resolution=d)
print("refined 2D-2 d", d, "U_m", u, "patch", patch, {k: round(float(v), 5) for k, v in r.quantities.items()},
      "steps", r.steps, "wall", round(time.time() - t, 1), flush=True)
