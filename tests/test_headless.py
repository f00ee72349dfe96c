"""The command line's solver factory: a backend that cannot run is one line for the user."""
import pytest

from feelflow.app.errors import UserError
from feelflow.app.headless import make_solver
from feelflow.solver import backend
from feelflow.solver.config import FlowConfig


def test_unknown_backend_is_a_user_error():
    with pytest.raises(UserError, match="--backend: must be one of"):
        make_solver("cuda", FlowConfig(nx=16, ny=16))


def test_backend_module_missing_is_one_clear_line(monkeypatch):
    monkeypatch.setitem(backend.BACKENDS, "future", "feelflow.solver.future_backend:FutureSolver")
    with pytest.raises(UserError) as info:
        make_solver("future", FlowConfig(nx=16, ny=16))
    assert str(info.value) == "--backend future: this backend is not available in this version"


def test_numpy_backend_is_created():
    s = make_solver("numpy", FlowConfig(nx=16, ny=16))
    assert s.name == "numpy"
    s.close()
