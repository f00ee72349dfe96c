"""Solvers for the command line: a backend by name; `gl` gets its own EGL context
(docs/developer/architecture.md, rule 2: the CLI hands the shader backend `create_context(standalone=True, backend='egl')`).
"""
from __future__ import annotations

from feelflow.app.errors import UserError
from feelflow.solver.backend import BACKENDS, BackendError, create_solver

_gl_context = None


def gl_context():
    """One standalone EGL OpenGL 3.3 context per process (llvmpipe where there is no GPU)."""
    global _gl_context
    if _gl_context is None:
        import moderngl

        try:
            _gl_context = moderngl.create_context(standalone=True, backend="egl", require=330)
        except Exception as exc:  # noqa: BLE001 - any EGL failure is one line for the user
            raise UserError(f"--backend gl: no OpenGL 3.3 context through EGL ({str(exc).splitlines()[0]})") from None
    return _gl_context


def release_gl_context() -> None:
    """Release the process's EGL context (the next gl_context() makes a new one)."""
    global _gl_context
    if _gl_context is not None:
        _gl_context.release()
        _gl_context = None


def make_solver(backend: str, config):
    """Create the named backend for `config`; UserError (one line) when it cannot run here."""
    if backend not in BACKENDS:
        raise UserError(f"--backend: must be one of {', '.join(sorted(BACKENDS))}, got {backend!r}")
    kwargs = {"ctx": gl_context()} if backend == "gl" else {}
    try:
        return create_solver(backend, config, **kwargs)
    except ModuleNotFoundError as exc:
        module = BACKENDS[backend].split(":")[0]
        if exc.name != module:
            raise
        raise UserError(f"--backend {backend}: this backend is not available in this version") from None
    except BackendError as exc:
        raise UserError(f"--backend {backend}: {str(exc).splitlines()[0]}") from None
