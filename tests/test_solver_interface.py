"""The flow interface the app uses (solver/backend.py `FlowSolver`): every registered backend and
the app's driver (`SessionSolver`) implement each member with the Protocol's call signature, the
driver without forwarding unknown names, and the registry takes a GL context the same way for
every backend."""
from __future__ import annotations

import importlib
import inspect

import pytest

from feelflow.app.sessions import SessionSolver
from feelflow.solver.backend import BACKENDS, FlowSolver, Solver, create_solver, needs_gl_context
from feelflow.solver.config import FlowConfig


def backend_class(name):
    module, cls = BACKENDS[name].split(":")
    return getattr(importlib.import_module(module), cls)


def mismatches(cls) -> list[str]:
    out = []
    for name in FlowSolver.__annotations__:
        if not any(name in vars(k) or name in getattr(k, "__annotations__", {}) for k in cls.__mro__):
            out.append(f"{name}: missing")
    for name, want in vars(FlowSolver).items():
        if name.startswith("_") or not (callable(want) or isinstance(want, property)):
            continue
        have = getattr(cls, name, None)
        if have is None:
            out.append(f"{name}: missing")
            continue
        if isinstance(want, property):
            if not isinstance(have, property):
                out.append(f"{name}: not a property")
            continue
        w = list(inspect.signature(want).parameters.values())[1:]
        h = list(inspect.signature(have).parameters.values())[1:]
        if [(p.name, p.kind, p.default) for p in h[:len(w)]] != [(p.name, p.kind, p.default) for p in w]:
            out.append(f"{name}{inspect.signature(have)} is not the Protocol's {inspect.signature(want)}")
        elif any(p.default is inspect.Parameter.empty for p in h[len(w):]):
            out.append(f"{name}: extra parameters without defaults")
    return out


@pytest.mark.parametrize("name", sorted(BACKENDS))
def test_every_backend_is_a_flow_solver(name):
    cls = backend_class(name)
    assert issubclass(cls, Solver)
    assert mismatches(cls) == []


def test_the_session_driver_is_a_flow_solver_without_forwarding():
    assert mismatches(SessionSolver) == []
    assert "__getattr__" not in vars(SessionSolver)
    driver = SessionSolver(create_solver("numpy", FlowConfig(nx=16, ny=8)))
    assert isinstance(driver, FlowSolver)
    with pytest.raises(AttributeError):
        driver.shifted_distributions     # not part of the interface: reach the backend by `.solver`


def test_the_registry_takes_a_context_the_same_way_for_every_backend():
    config = FlowConfig(nx=16, ny=8)
    for name in BACKENDS:
        if not needs_gl_context(name):
            solver = create_solver(name, config, ctx=None)
            assert solver.gl_context is None and solver.field_texture() is None
            assert solver.field_rgba().shape == (8, 16, 4)
            solver.close()
    assert needs_gl_context("gl")
    with pytest.raises(Exception, match="moderngl.Context"):
        create_solver("gl", config, ctx=None)
