"""Backend parametrisation for solver physics tests: numpy, the compiled cpu backend, and gl
(EGL standalone) where it has landed."""
from __future__ import annotations

from pathlib import Path

import pytest

GL_LANDED = (Path(__file__).resolve().parents[1] / "solver" / "gl_backend.py").exists()

#: use as @pytest.mark.parametrize("backend", BACKENDS)
BACKENDS = [
    "numpy",
    "cpu",
    pytest.param("gl", marks=[pytest.mark.gl,
                              pytest.mark.skipif(not GL_LANDED, reason="solver/gl_backend.py not landed yet")]),
]
