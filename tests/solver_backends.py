"""Backend parametrisation for solver physics tests: numpy, the compiled cpu backend, and gl
(EGL standalone).

The cpu backend's runs of these physics tests are in the `slow` tier (`pytest -m slow`): each
compiles its own kernel variants with numba on a fresh machine (20 - 60 s apiece), which would
push the default run past its 10 minutes; a cpu case therefore gets 20 minutes instead of the
default 600 s (one compiled three variants and ran 275 s on a loaded 2-core machine). The default run still checks the cpu backend against
numpy case by case (tests/test_cpu_vs_numpy.py) and through the backend choice."""
from __future__ import annotations

import pytest

#: use as @pytest.mark.parametrize("backend", BACKENDS)
BACKENDS = [
    "numpy",
    pytest.param("cpu", marks=[pytest.mark.slow, pytest.mark.timeout(1200)]),
    pytest.param("gl", marks=pytest.mark.gl),
]
