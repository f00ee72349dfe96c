"""Solvers for the command line: a backend by name; `gl` gets its own EGL context
(docs/developer/architecture.md, rule 2: the CLI hands the shader backend `create_context(standalone=True, backend='egl')`).
"""
from __future__ import annotations

from feelflow.app.errors import UserError
from feelflow.solver.backend import BACKENDS, BackendError, create_solver, needs_gl_context

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


def make_solver(backend: str, config):
    """Create the named backend for `config`; UserError (one line) when it cannot run here."""
    if backend not in BACKENDS:
        raise UserError(f"--backend: must be one of {', '.join(sorted(BACKENDS))}, got {backend!r}")
    try:
        return create_solver(backend, config, ctx=gl_context() if needs_gl_context(backend) else None)
    except ModuleNotFoundError as exc:
        module = BACKENDS[backend].split(":")[0]
        if exc.name != module:
            raise
        raise UserError(f"--backend {backend}: this backend is not available in this version") from None
    except BackendError as exc:
        raise UserError(f"--backend {backend}: {str(exc).splitlines()[0]}") from None


def gl_renderer() -> str:
    """The GL renderer this process's gl backend would run on, or "no GL" where there is none."""
    try:
        return str(gl_context().info.get("GL_RENDERER", "unknown"))
    except UserError:
        return "no GL"


def resolve_backend(backend: str, config, store=None) -> str:
    """`backend` as given, or for "auto" the fastest backend on this machine for `config`'s grid
    (app/model/backend_choice.py), remembered per (GL renderer, grid) in the user's cache; prints
    the choice in one line."""
    if backend != "auto":
        return backend
    from feelflow.app.model.backend_choice import JsonFileStore, choose_backend, default_store_path

    store = store if store is not None else JsonFileStore(default_store_path())
    try:
        choice = choose_backend(config, make_solver, store, renderer=gl_renderer())
    except RuntimeError as exc:
        raise UserError(f"--backend auto: {exc}") from None
    print(f"feelflow: {choice.describe(config.nx, config.ny)}", flush=True)
    return choice.backend
