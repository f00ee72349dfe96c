"""`feelflow bench streaming` (app/bench/streaming.py): the AA-pattern box kernel
(solver/cpu_kernels.py `make_box_aa`) and the cpu backend's AA pattern (several steps per call)
compute what its two-buffer step (one step per call) does.
The default tier runs both kernels as plain Python (NUMBA_DISABLE_JIT, in a process of its own:
no compile); the compiled kernels run against each other in the slow tier."""
from __future__ import annotations

import os
import subprocess
import sys

import pytest

CHECK = """
import numpy as np
from feelflow.app.bench.streaming import PATTERNS, largest_difference, make_runs
for nx, ny in ((13, 9),):
    runs = make_runs(nx, ny)
    two, aa, solver = (runs[p] for p in PATTERNS)
    aa.advance(2)   # one pair of AA steps ahead: the states differ (the check can fail)
    ahead = float(np.abs(two.state() - aa.state()).max())
    two.advance(2)
    aa_box = float(np.abs(two.state() - aa.state()).max())
    solver.advance(3)   # the solver's AA pattern with an odd number of steps: one step ahead
    ahead_solver = float(np.abs(two.state() - solver.state()).max())
    two.advance(1)
    aa_solver = float(np.abs(two.state() - solver.state()).max())
    two.advance(1)
    solver.advance(1)
    aa.advance(2)   # all at step 4
    print(nx, ny, ahead, ahead_solver, aa_box, aa_solver, largest_difference(runs, 4))
"""


def test_the_aa_box_kernel_streams_and_collides_as_the_two_buffer_kernel():
    """Two AA steps (even: collide in place, stored reversed; odd: read from the neighbours,
    collide, write to the neighbours) hold the two-buffer kernel's state after two steps,
    streamed, to the last bit, on a box with a random disturbance and an odd width; so do the
    cpu backend's three steps in one call (natural, AA, natural) and its one-step calls."""
    r = subprocess.run([sys.executable, "-c", CHECK], capture_output=True, text=True, timeout=120,
                       env={**os.environ, "NUMBA_DISABLE_JIT": "1"})
    assert r.returncode == 0, r.stderr
    for line in r.stdout.splitlines():
        nx, ny, ahead, ahead_solver, aa_box, aa_solver, after_four = line.split()
        assert float(ahead) > 1e-5 and float(ahead_solver) > 1e-5, line
        assert float(aa_box) == 0.0 and float(aa_solver) == 0.0 and float(after_four) == 0.0, line


@pytest.mark.slow
def test_the_compiled_aa_box_kernel_equals_the_two_buffer_kernel():
    from feelflow.app.bench.streaming import largest_difference, make_runs

    runs = make_runs(64, 32)
    assert largest_difference(runs, 100) < 1e-6
