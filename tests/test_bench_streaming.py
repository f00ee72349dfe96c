"""`feelflow bench streaming` (app/bench/streaming.py): the AA-pattern box kernel
(solver/cpu_kernels.py `make_box_aa`) computes what the cpu backend's two-buffer kernel does.
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
    two, aa = runs[PATTERNS[0]], runs[PATTERNS[1]]
    aa.advance(2)   # one pair of AA steps ahead: the states differ (the check can fail)
    ahead = float(np.abs(two.state() - aa.state()).max())
    two.advance(2)
    print(nx, ny, ahead, float(np.abs(two.state() - aa.state()).max()), largest_difference(runs, 4))
"""


def test_the_aa_box_kernel_streams_and_collides_as_the_two_buffer_kernel():
    """Two AA steps (even: collide in place, stored reversed; odd: read from the neighbours,
    collide, write to the neighbours) hold the two-buffer kernel's state after two steps,
    streamed, to the last bit, on a box with a random disturbance and an odd width."""
    r = subprocess.run([sys.executable, "-c", CHECK], capture_output=True, text=True, timeout=120,
                       env={**os.environ, "NUMBA_DISABLE_JIT": "1"})
    assert r.returncode == 0, r.stderr
    for line in r.stdout.splitlines():
        nx, ny, ahead, after_two, after_four = line.split()
        assert float(ahead) > 1e-5 and float(after_two) == 0.0 and float(after_four) == 0.0, line


@pytest.mark.slow
def test_the_compiled_aa_box_kernel_equals_the_two_buffer_kernel():
    from feelflow.app.bench.streaming import largest_difference, make_runs

    runs = make_runs(64, 32)
    assert largest_difference(runs, 100) < 1e-6
