"""One solver interface, three backends (`numpy`, `gl`, `cpu`), chosen by an explicit registry.

A backend implements docs/science/algorithm.md. Physics tests are parametrised over `BACKENDS`.
"""
from __future__ import annotations

import importlib
from abc import ABC, abstractmethod
from typing import Any, Protocol, runtime_checkable

import numpy as np

from feelflow.solver.config import FlowConfig

#: backend name -> "module:Class"; no silent fallback from one to the other
BACKENDS: dict[str, str] = {
    "numpy": "feelflow.solver.numpy_backend:NumpySolver",
    "gl": "feelflow.solver.gl_backend:GLSolver",
    "cpu": "feelflow.solver.cpu_backend:CpuSolver",
}


class BackendError(RuntimeError):
    """The backend cannot run here (no GL context, unsupported feature); the message says why."""


class SolverDiverged(RuntimeError):
    """The flow blew up (NaN/inf density): the state is lost; reset it. `step` is where."""

    def __init__(self, step: int, detail: str = ""):
        super().__init__(f"the flow diverged at step {step}{': ' + detail if detail else ''}"
                         " (lower the speed or raise the viscosity/resolution, then reset)")
        self.step = step


#: the flow has left the lattice's physical range (and will blow up) when any node moves faster
#: than SPEED_FACTOR times the Mach limit's speed (c_s Ma_max; the flow near a body reaches about
#: twice the stream's) or its density is further than DENSITY_DEVIATION from rho_0 = 1 (a
#: compressibility error of order Ma^2, a few per cent inside the Mach limit): Krueger et al.,
#: "The Lattice Boltzmann Method" (2017), sec. 4.5 and 7.1 (Mach number and stability)
SPEED_FACTOR = 4.0
MAX_PHYSICAL_SPEED = 0.8
DENSITY_DEVIATION = 0.5


def physical_speed_limit(config: FlowConfig) -> float:
    """The largest |u| a physical flow of `config` reaches (SPEED_FACTOR x its Mach limit)."""
    return min(SPEED_FACTOR * config.max_speed, MAX_PHYSICAL_SPEED)


def physical_density_deviation(config: FlowConfig) -> float:
    """The largest |rho - 1| of a physical flow of `config`: DENSITY_DEVIATION, or twice the Mach
    limit where that is more (a body started at Ma sends out a pulse of about Ma, rho u / c_s),
    never beyond 0.9."""
    return min(0.9, max(DENSITY_DEVIATION, 2.0 * config.mach_limit))


@runtime_checkable
class FlowSolver(Protocol):
    """What the app needs of a flow, whoever runs it: every backend (`Solver`) and the app's
    driver (app/sessions/driver.py `SessionSolver`) implement it, member by member
    (tests/test_solver_interface.py checks the signatures). Lattice units."""

    config: FlowConfig       # the flow's configuration (grid, Mach limit, collision)
    name: str                # the backend's registry name
    time: int                # steps done
    speed_capped: bool       # the last body motion or inflow was reduced to config.max_speed
    max_speed_seen: float    # the largest |u| the last physical-range check read (solver/local_guard.py)
    max_speed_at: int | None  # the step of that check (None: no check yet)

    @property
    def gl_context(self) -> Any:
        """The moderngl.Context the flow runs on, or None (a CPU backend)."""
        ...

    def step(self, n: int = 1) -> None:
        """Advance n steps; raise SolverDiverged when the flow blows up."""
        ...

    def forces(self) -> dict[str, tuple[float, float]]:
        """Mean force per enabled model over the last `step(n)` call."""
        ...

    def torques(self) -> dict[str, float]:
        """Mean torque on the body about its centre per enabled model over the last `step(n)`
        call (counter-clockwise positive)."""
        ...

    def set_body(self, shape, velocity=(0.0, 0.0), omega: float = 0.0) -> None:
        """Place the body (a `shapes` shape at its pose, or None) moving at `velocity`."""
        ...

    def enable_force_models(self, names) -> None:
        """Compute only these force models (solver/forces)."""
        ...

    def add_force_model(self, model) -> None:
        """Enable an already-built model instance too, keyed by its name (solver/forces)."""
        ...

    def set_inflow_speed(self, speed: float) -> None:
        """The inlet's speed from the next step on (capped at config.max_speed)."""
        ...

    def macroscopic(self):
        """(rho, ux, uy), each (ny, nx) float64."""
        ...

    def distributions(self) -> np.ndarray:
        """Full post-collision populations (9, ny, nx) float64."""
        ...

    def inlet_reference(self) -> np.ndarray | None:
        """The quiet inlet's reference (ny,), or None without a quiet inlet."""
        ...

    def field_rgba(self) -> np.ndarray:
        """(ny, nx, 4) float32: rho, ux, uy, vorticity, for drawing on the CPU side."""
        ...

    def field_texture(self, vorticity: bool = True) -> Any:
        """The same field as a texture on `gl_context` (computed on the GPU), or None where the
        flow has no texture (draw `field_rgba` instead)."""
        ...

    def check_physical(self) -> None:
        """Raise SolverDiverged when the flow has left the physical range."""
        ...

    def total_mass(self) -> float:
        """sum f over the grid (a run's check that the flow is still finite)."""
        ...

    def finish(self) -> None:
        """Return once every step asked for has been computed (a GPU backend queues its work):
        what a timing waits for."""
        ...

    def close(self) -> None:
        """Release what the flow holds; unusable after."""
        ...


class Solver(ABC):
    """A D2Q9 lattice with at most one rigid body (docs/science/algorithm.md); a `FlowSolver`."""

    name: str = "abstract"
    config: FlowConfig    # set in __init__, validated
    time: int             # steps done
    #: True when the last set_body motion (or the inflow) was reduced to config.max_speed
    speed_capped: bool = False

    #: True when the last set_inflow_speed asked for more than config.max_speed
    inflow_capped: bool = False

    #: the largest |u| the last physical-range check read, and the step it read it at (None: none yet)
    max_speed_seen: float = 0.0
    max_speed_at: int | None = None

    def __init__(self, config: FlowConfig):
        self.config = config.validate()
        self.time = 0  # steps done
        self.inflow_speed = float(self.config.inflow_speed)  # U of the tunnel inlet, in use
        self.body = None      # solver.body.BodyState of the body, or None
        self._models = {}     # enabled force models by name
        self._forces: dict[str, tuple[float, float]] = {}  # their means over the last step(n)
        self._torques: dict[str, float] = {}  # and their torques' means
        from feelflow.solver.body import DEFAULT_IMPULSE, DEFAULT_REFILL

        self.body_refill, self.body_impulse = DEFAULT_REFILL, DEFAULT_IMPULSE   # set_body_schemes

    @property
    def gl_context(self):
        """The moderngl.Context the backend draws on (None: it runs on the CPU)."""
        return None

    # --- inflow ---------------------------------------------------------------
    def set_inflow_speed(self, speed: float) -> None:
        """Change the inlet speed U (tunnel) from the next step on, capped at config.max_speed
        (solver/speed_limit.py); `inflow_capped` and `speed_capped` say when the cap bit."""
        from feelflow.solver.speed_limit import cap_speed

        u, _, capped = cap_speed(float(speed), 0.0, self.config.max_speed)
        self.inflow_speed, self.inflow_capped = u, capped
        self.speed_capped = capped or bool(self.body is not None and self.body.capped)

    # --- body -----------------------------------------------------------------
    @abstractmethod
    def set_body(self, shape, velocity=(0.0, 0.0), omega: float = 0.0) -> None:
        """Place the body (a `shapes` shape at its pose, or None) moving at `velocity`,
        rotating at `omega`; covers/uncovers nodes and books their momentum (algorithm.md)."""

    def set_body_schemes(self, refill: str | None = None, impulse: str | None = None) -> None:
        """How a moving body refills the nodes it uncovers and books the momentum of the nodes it
        covers and uncovers (solver/body.py REFILL_SCHEMES, IMPULSE_SCHEMES); None keeps one."""
        from feelflow.solver.body import check_schemes

        refill = self.body_refill if refill is None else refill
        impulse = self.body_impulse if impulse is None else impulse
        check_schemes(refill, impulse)
        self.body_refill, self.body_impulse = refill, impulse

    #: build a moved body's raster and links compiled (solver/body_compiled.py, the same numbers);
    #: the numpy backend, the reference, builds them with its own readable code
    compiled_moves: bool = False

    def _body_state(self, shape, velocity, omega, raster=None):
        """The rasterised, speed-capped body state for `set_body` (None without a body), with a
        force window wide enough for every enabled model (solver/body.py)."""
        if shape is None:
            return None
        from feelflow.solver.body import make_body_state, window_margin

        builders = {}
        if self.compiled_moves:
            from feelflow.solver import body_compiled

            builders = dict(links=body_compiled.build_links, rasteriser=body_compiled.compiled_raster(shape))
        return make_body_state(shape, velocity, omega, self.config,
                               window_margin(self._models.values()), raster, **builders)

    # --- stepping -------------------------------------------------------------
    @abstractmethod
    def step(self, n: int = 1) -> None:
        """Advance n steps; evaluate the enabled force models on each."""

    @property
    def nodes_per_step(self) -> int:
        """Node updates per step (what MLUPS count): the lattice's nodes."""
        return self.config.nx * self.config.ny

    # --- forces ---------------------------------------------------------------
    def enable_force_models(self, names) -> None:
        """Compute only these models (names from `feelflow.solver.forces.MODELS`)."""
        from feelflow.solver.forces import create_model

        self._models = {name: create_model(name) for name in names}
        self._forces = {}
        self._torques = {}
        self._rebuild_body_window()

    def add_force_model(self, model) -> None:
        """Enable an already-built model instance (e.g. with options), keyed by its name."""
        self._models[model.name] = model
        self._rebuild_body_window()

    def _rebuild_body_window(self) -> None:
        """The body's force window for the margin the enabled models need (solver/body.py)."""
        b = self.body
        if b is not None:
            from feelflow.solver.body import make_body_state, window_margin

            self.body = make_body_state(b.shape, b.velocity, b.omega, self.config,
                                        window_margin(self._models.values()), b.raster)

    def forces(self) -> dict[str, tuple[float, float]]:
        """Mean force per model over the last `step(n)` call, lattice units."""
        return dict(self._forces)

    def torques(self) -> dict[str, float]:
        """Mean torque per model about the body's centre over the last `step(n)` call,
        counter-clockwise positive, lattice units (ForceModel.torque)."""
        return dict(self._torques)

    @property
    def force_models(self) -> dict:
        """The enabled force models (solver/forces instances) by name."""
        return dict(self._models)

    # --- fields ---------------------------------------------------------------
    @abstractmethod
    def shifted_distributions(self) -> np.ndarray:
        """The stored state g = f* - w_i RHO0 (9, ny, nx), in the backend's storage precision
        (docs/science/algorithm.md, 'Lattice, storage'); a view or a fresh read-back, never modified."""

    def distributions(self) -> np.ndarray:
        """Full (unshifted) post-collision populations f*, float64 array (9, ny, nx)."""
        from feelflow.solver.lattice import RHO0, W

        return self.shifted_distributions().astype(np.float64) + (W * RHO0)[:, None, None]

    @abstractmethod
    def set_distributions(self, f: np.ndarray) -> None:
        """Replace the state with full populations f (9, ny, nx); the quiet inlet's reference
        restarts at 0 (set it afterwards with set_inlet_reference)."""

    @property
    def has_quiet_inlet(self) -> bool:
        """Whether the flow's state holds the quiet inlet's reference (solver/quiet_inlet.py)."""
        return self.config.x_boundary == "tunnel" and self.config.inlet_nonreflecting > 0

    def inlet_reference(self) -> np.ndarray | None:
        """The quiet inlet's per-row reference density fluctuation (ny,) float64, part of the
        flow's state beside the populations (sessions and carried flows keep it); None without
        a quiet inlet."""
        return None

    def set_inlet_reference(self, row) -> None:
        """Set the quiet inlet's reference (ny,) (after set_distributions, which restarts it)."""
        raise ValueError(f"the {self.name} backend holds no quiet inlet reference")

    def macroscopic(self):
        """(rho, ux, uy), each (ny, nx) float64, from the stored post-collision populations,
        summed on the shifted storage in float64 (no cancellation against RHO0).

        With a body force F (Guo et al. 2002) the collision adds F to the momentum, so the
        fluid velocity of the step is u = (sum_i c_i f*_i - F/2) / rho (sum_i c_i w_i = 0).
        With the incompressible equilibrium (He & Luo 1997) the velocity is j / RHO0."""
        from feelflow.solver.lattice import C, RHO0

        g = self.shifted_distributions()
        rho = g.sum(axis=0, dtype=np.float64) + RHO0
        fx, fy = self.config.body_force
        jx = np.tensordot(C[:, 0].astype(np.float64), g, axes=1) - 0.5 * fx
        jy = np.tensordot(C[:, 1].astype(np.float64), g, axes=1) - 0.5 * fy
        per = self.config.velocity_divisor(rho)
        return rho, jx / per, jy / per

    def field_rgba(self) -> np.ndarray:
        """(ny, nx, 4) float32: rho, ux, uy and the vorticity d uy/dx - d ux/dy (central
        differences), from `macroscopic`."""
        rho, ux, uy = self.macroscopic()
        out = np.empty(rho.shape + (4,), np.float32)
        out[..., 0], out[..., 1], out[..., 2] = rho, ux, uy
        out[..., 3] = np.gradient(uy, axis=1) - np.gradient(ux, axis=0)
        return out

    def field_texture(self, vorticity: bool = True):
        """No texture on a CPU backend: draw `field_rgba` (the gl backend returns its texture)."""
        return None

    def total_mass(self) -> float:
        """sum f over the grid, accumulated in float64 on the shifted storage."""
        from feelflow.solver.lattice import RHO0

        return float(self.shifted_distributions().sum(dtype=np.float64)) + RHO0 * self.config.nx * self.config.ny

    def check_physical(self) -> None:
        """Raise SolverDiverged when the flow has left the physical range (max |u| above
        `physical_speed_limit`, |rho - 1| above `physical_density_deviation`), long before NaN.
        Reads the whole field (one read-back on the gl backend); checked once per solver step."""
        if getattr(self, "_physical_checked_at", None) == self.time:
            return
        rho, ux, uy = self.macroscopic()
        limit = physical_speed_limit(self.config)
        speed2 = ux * ux + uy * uy
        u_max = float(np.sqrt(np.max(speed2))) if speed2.size else 0.0
        dev = float(np.max(np.abs(rho - 1.0))) if rho.size else 0.0
        if not (np.isfinite(u_max) and np.isfinite(dev)):
            raise SolverDiverged(self.time, "density is no longer finite")
        if u_max > limit:
            raise SolverDiverged(self.time, f"max |u| = {u_max:.3g} is far above the Mach limit "
                                            f"(physical range |u| <= {limit:.3g})")
        self.max_speed_seen, self.max_speed_at = u_max, self.time   # for the local guard (solver/local_guard.py)
        allowed = physical_density_deviation(self.config)
        if dev > allowed:
            lo, hi = float(np.min(rho)), float(np.max(rho))
            raise SolverDiverged(self.time, f"the density reaches {hi if hi - 1.0 >= 1.0 - lo else lo:.3g}, "
                                            f"far from 1 (physical range 1 +- {allowed:g})")
        self._physical_checked_at = self.time

    def finish(self) -> None:
        """Return once every step asked for has been computed: at once on the CPU backends,
        whose steps have returned by then; the gl backend waits for its GPU."""

    def close(self) -> None:
        """Release resources (GL objects); the solver is unusable after."""


#: the backends that draw on a GL context handed to them (`create_solver`'s `ctx`)
GL_CONTEXT_BACKENDS = frozenset({"gl"})


def needs_gl_context(backend: str) -> bool:
    """Whether `backend` runs on a moderngl.Context the caller hands to `create_solver`."""
    return backend in GL_CONTEXT_BACKENDS


#: collision operators kept for the comparison in docs/science/collision-operators.md, not for
#: scenes, and the backends that run them (solver/kbc.py: entropic KBC, numpy and compiled cpu)
COMPARISON_COLLISIONS = {"kbc": ("numpy", "cpu")}


def create_solver(backend: str, config: FlowConfig, ctx=None) -> Solver:
    """Instantiate a backend by name. Every caller passes the GL context it has (or None) the
    same way: a backend that draws on one (`needs_gl_context`) gets it and refuses None, the
    others ignore it."""
    if backend not in BACKENDS:
        raise BackendError(f"unknown backend {backend!r}; choose one of {sorted(BACKENDS)}")
    runs_on = COMPARISON_COLLISIONS.get(config.collision)
    if runs_on is not None and backend not in runs_on:
        raise BackendError(f"the {config.collision} collision runs on the {' and '.join(runs_on)} backends only, "
                           f"not {backend!r}")
    module_name, cls_name = BACKENDS[backend].split(":")
    cls = getattr(importlib.import_module(module_name), cls_name)
    return cls(config, ctx=ctx) if needs_gl_context(backend) else cls(config)
