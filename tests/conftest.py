"""Shared fixtures: a real EGL (llvmpipe) GL context, backend parametrisation, temp caches."""
from __future__ import annotations

import os
import tempfile

import pytest

pytest_plugins = ["gui_fixtures"]   # the GUI tests' window fixture; imports Qt only in a gui run

# Mesa's shader cache and Qt's caches go to a temp dir, never the user's home.
_cache = tempfile.mkdtemp(prefix="feelflow-test-cache-")
os.environ.setdefault("MESA_SHADER_CACHE_DIR", _cache)
os.environ.setdefault("XDG_CACHE_HOME", _cache)


@pytest.fixture(scope="session")
def gl_context():
    """The process's standalone EGL OpenGL 3.3 core context (app.headless.gl_context: llvmpipe
    where there is no GPU), the one the CLI's gl solvers get too."""
    from feelflow.app.errors import UserError
    from feelflow.app.headless import gl_context as egl_context

    try:
        ctx = egl_context()
    except UserError as exc:  # no EGL on this machine: the gl tier cannot run
        pytest.fail(f"EGL standalone context unavailable: {exc}")
    yield ctx
    ctx.release()   # at the end of the session: nothing in this process draws after it


def make_solver(backend: str, config, request=None):
    """Create a solver of the named backend; gl gets the session EGL context."""
    from feelflow.solver.backend import create_solver

    if backend == "gl":
        ctx = request.getfixturevalue("gl_context")
        return create_solver("gl", config, ctx=ctx)
    return create_solver(backend, config)


# --- GUI tests need a process of their own -----------------------------------------------
# Measured here (libglvnd, Mesa 22.3): once an EGL standalone context has existed in a process,
# Qt's GLX context can no longer be made current ("QOpenGLWidget: Failed to make context
# current"), even after the EGL context is released; glcontext cannot attach moderngl to a
# Qt EGL context either. So a run that selects both GUI and other tests keeps the GUI ones for
# a second process: installer/run-tests.sh runs `pytest -m gui` after the rest.
@pytest.hookimpl(trylast=True)  # after -m/-k have deselected what they will
def pytest_collection_modifyitems(config, items):
    gui = [item for item in items if item.get_closest_marker("gui")]
    if gui and len(gui) < len(items):
        config.hook.pytest_deselected(items=gui)
        items[:] = [item for item in items if not item.get_closest_marker("gui")]
        config._feelflow_gui_deferred = len(gui)


def pytest_terminal_summary(terminalreporter, config):
    n = getattr(config, "_feelflow_gui_deferred", 0)
    if n:
        terminalreporter.write_line(
            f"{n} gui tests deferred: they need a process of their own; run them with "
            "`pytest -m gui` (installer/run-tests.sh without arguments runs both).")
