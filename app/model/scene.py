"""Scene files: a TOML description of a wind-tunnel run, loaded into a validated `Scene`.

Every key is documented in docs/reference/scenes.md. Every bad value, missing required key or unknown key
raises `feelflow.app.cli.main.UserError` with one line: `FILE: KEY: what is wrong`.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

from feelflow.app.errors import UserError, shown
from feelflow.app.inputs import MAX_STEPS, check_work
from feelflow.solver.motion import MOVES, MotionScript, Phase, phase_velocity
from feelflow.solver import units
from feelflow.solver.backend import BACKENDS
from feelflow.solver.backend import COMPARISON_COLLISIONS
from feelflow.solver.config import COLLISIONS, DTYPES, EQUILIBRIA, PROFILES, X_BOUNDARIES, Y_BOUNDARIES, ConfigError, FlowConfig
from feelflow.solver.forces import MODELS

#: FlowConfig field -> scene key (for messages from FlowConfig.validate)
CONFIG_KEYS = {
    "nx": "grid.nx", "ny": "grid.ny", "nu": "flow.nu", "collision": "flow.collision",
    "smagorinsky": "flow.smagorinsky",
    "trt_magic": "flow.trt_magic", "equilibrium": "flow.equilibrium", "dtype": "flow.dtype",
    "x_boundary": "flow.x_boundary",
    "y_boundary": "flow.walls", "inflow_speed": "flow.inflow_speed",
    "inflow_profile": "flow.inflow_profile", "inflow_ramp_steps": "flow.inflow_ramp_steps",
    "body_force": "flow.body_force", "sponge_cells": "flow.sponge_cells",
    "sponge_strength": "flow.sponge_strength", "sponge_absorb": "flow.sponge_absorb",
    "inlet_nonreflecting": "flow.inlet_nonreflecting", "initial_velocity": "flow.initial_velocity",
    "mach_limit": "flow.mach_limit",
}
#: the direction of the stream in a tunnel (the inlet is at x = -1/2)
STREAM_DIRECTION = (1.0, 0.0)
#: a body keeps this many cells away from the domain edges (its force window lies inside)
EDGE_MARGIN = 2.0


@dataclass(frozen=True)
class Scene:
    """A validated scene: flow, body, motion script, what to compute and record."""

    source: str
    config: FlowConfig
    body: object  # a shapes.Shape at its start pose
    motion: MotionScript
    force_models: tuple[str, ...]
    output_interval: int
    steps: int
    backend: str
    reference_length: float  # frontal size of the body across the stream
    reference_speed: float   # inflow speed (or the fastest motion phase in fluid at rest)
    operator_named: str | None = None   # flow.collision as the scene names it (None: chosen)
    operator_reason: str = ""           # which operator runs and why (solver/operator_choice.py)

    @property
    def reynolds(self) -> float:
        return units.reynolds(self.reference_speed, self.reference_length, self.config.nu)

    @property
    def mach(self) -> float:
        return units.mach(self.reference_speed)


class _Missing:
    pass


MISSING = _Missing()


class _Table:
    """One TOML table being read: remembers which keys were used, reports the rest as unknown."""

    def __init__(self, reader: "_Reader", data, name: str):
        self.reader = reader
        self.name = name
        if not isinstance(data, dict):
            reader.fail(name, f"must be a table, got {_show(data)}")
        self.data = data
        self.used: set[str] = set()

    def key(self, key: str) -> str:
        return f"{self.name}.{key}" if self.name else key

    def has(self, key: str) -> bool:
        return key in self.data

    def raw(self, key: str, default=MISSING):
        self.used.add(key)
        if key not in self.data:
            if default is MISSING:
                self.reader.fail(self.key(key), "missing (required)")
            return default
        return self.data[key]

    def integer(self, key, default=MISSING, lo=None, hi=None):
        v = self.raw(key, default)
        if v is default and key not in self.data:
            return v
        if isinstance(v, bool) or not isinstance(v, int):
            self.reader.fail(self.key(key), f"must be an integer, got {_show(v)}")
        if (lo is not None and v < lo) or (hi is not None and v > hi):
            if lo is not None and hi is not None and hi < 1_000_000:
                rng = f"in {lo}..{hi}"
            else:
                rng = f">= {lo}" if lo is not None and v < lo else f"<= {hi}"
            self.reader.fail(self.key(key), f"must be an integer {rng}, got {v}")
        return v

    def number(self, key, default=MISSING, positive=False, nonnegative=False):
        v = self.raw(key, default)
        if v is default and key not in self.data:
            return v
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            self.reader.fail(self.key(key), f"must be a finite number, got {_show(v)}")
        if positive and v <= 0:
            self.reader.fail(self.key(key), f"must be a positive number, got {v:g}")
        if nonnegative and v < 0:
            self.reader.fail(self.key(key), f"must be zero or positive, got {v:g}")
        return float(v)

    def choice(self, key, choices, default=MISSING):
        v = self.raw(key, default)
        if v is default and key not in self.data:
            return v
        if v not in choices:
            self.reader.fail(self.key(key), f"must be one of {', '.join(map(str, choices))}; got {_show(v)}")
        return v

    def pair(self, key, default=MISSING):
        v = self.raw(key, default)
        if v is default and key not in self.data:
            return v
        if (not isinstance(v, list) or len(v) != 2
                or any(isinstance(c, bool) or not isinstance(c, (int, float)) or not math.isfinite(c) for c in v)):
            self.reader.fail(self.key(key), f"must be two finite numbers [x, y], got {_show(v)}")
        return (float(v[0]), float(v[1]))

    def table(self, key, required=False):
        v = self.raw(key, MISSING if required else {})
        return _Table(self.reader, v, self.key(key))

    def done(self):
        unknown = [k for k in self.data if k not in self.used]
        if unknown:
            self.reader.fail(self.key(unknown[0]), "unknown key (see docs/reference/scenes.md)")


class _Reader:
    def __init__(self, source: str):
        self.source = source

    def fail(self, key: str, message: str):
        raise UserError(f"{self.source}: {shown(key)}: {message}")


def _show(value) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


#: the tunnel's boundary keys: a scene that names none of them gets the window's quiet tunnel
BOUNDARY_KEYS = ("sponge_cells", "sponge_strength", "sponge_absorb", "inlet_nonreflecting")


def quiet_defaults(nx: int, ramp: int) -> dict:
    """The window's quiet tunnel (app/model/simulation.py default_base_config) for a scene that
    names no boundary key: the outlet sponge (32 cells, at most a quarter of the tunnel) with its
    absorbing layer, and the quiet inlet where the inflow ramp allows it (none, or at least
    `shortest_ramp(nx)` steps; docs/science/quiet-tunnel.md). Naming any boundary key (e.g.
    `sponge_cells = 0`) gives the bare tunnel instead."""
    from feelflow.app.model.simulation import QUIET_INLET_RATE, default_base_config
    from feelflow.solver.quiet_inlet import shortest_ramp

    base = default_base_config((nx, 8))
    out = {"sponge_cells": min(base.sponge_cells, nx // 4), "sponge_absorb": base.sponge_absorb}
    if ramp == 0 or ramp >= shortest_ramp(nx):
        out["inlet_nonreflecting"] = QUIET_INLET_RATE
    return out


def load_scene(path) -> Scene:
    """Read and validate a scene file; UserError (one line) on any problem."""
    from feelflow.app.inputs import load_toml

    path = Path(path)
    data = load_toml(path, "scene file")   # regular file, size, depth and number bounds first
    return scene_from_dict(data, str(path))


def scene_from_dict(data: dict, source: str = "scene") -> Scene:
    """Validate a scene given as nested dicts (the parsed TOML)."""
    reader = _Reader(source)
    top = _Table(reader, data, "")

    grid = top.table("grid", required=True)
    nx = grid.integer("nx", lo=8, hi=8192)
    ny = grid.integer("ny", lo=8, hi=8192)
    grid.done()

    flow = top.table("flow")
    # None: solver/operator_choice.py picks; the numpy-only operators (KBC) are not for scenes
    named_operator = flow.choice("collision", tuple(c for c in COLLISIONS if c not in COMPARISON_COLLISIONS), None)
    smagorinsky = flow.number("smagorinsky", 0.0, nonnegative=True)
    trt_magic = flow.number("trt_magic", 3.0 / 16.0, positive=True)
    equilibrium = flow.choice("equilibrium", EQUILIBRIA, "compressible")
    dtype = flow.choice("dtype", DTYPES, "float64")
    x_boundary = flow.choice("x_boundary", X_BOUNDARIES, "tunnel")
    walls = flow.choice("walls", Y_BOUNDARIES, "no_slip")
    if x_boundary == "periodic":   # a periodic domain has no inlet: its settings would be ignored
        for key in ("inflow_speed", "inflow_profile", "inflow_ramp_steps", "sponge_cells",
                    "sponge_strength", "sponge_absorb"):
            if flow.has(key):
                reader.fail(f"flow.{key}", "has no effect with flow.x_boundary = \"periodic\" (no inlet); "
                                           "remove it, or drive the flow with flow.body_force")
    if not flow.data.get("sponge_cells"):   # no absorbing layer: its settings would be ignored
        for key in ("sponge_strength", "sponge_absorb"):
            if flow.has(key) and x_boundary != "periodic":
                reader.fail(f"flow.{key}", "has no effect without an absorbing layer (flow.sponge_cells > 0)")
    if named_operator in ("bgk", "rr") and flow.has("trt_magic"):
        reader.fail("flow.trt_magic", f"has no effect with flow.collision = \"{named_operator}\" (it is TRT's parameter)")
    inflow_speed = flow.number("inflow_speed", 0.05 if x_boundary == "tunnel" else 0.0, nonnegative=True)
    inflow_profile = flow.choice("inflow_profile", PROFILES, "uniform")
    ramp = flow.integer("inflow_ramp_steps", 1000, lo=0, hi=MAX_STEPS)
    quiet = quiet_defaults(nx, ramp) if (x_boundary == "tunnel" and not any(flow.has(k) for k in BOUNDARY_KEYS)) \
        else {}
    sponge_cells = flow.integer("sponge_cells", quiet.get("sponge_cells", 0), lo=0)
    sponge_strength = flow.number("sponge_strength", 10.0, positive=True)
    sponge_absorb = flow.number("sponge_absorb", quiet.get("sponge_absorb", 0.0), nonnegative=True)
    inlet_nonreflecting = flow.number("inlet_nonreflecting", quiet.get("inlet_nonreflecting", 0.0), nonnegative=True)
    mach_limit = flow.number("mach_limit", 0.17, positive=True)
    initial_velocity = flow.pair("initial_velocity", (0.0, 0.0))
    body_force = flow.pair("body_force", (0.0, 0.0))
    if flow.has("nu") and flow.has("reynolds"):
        reader.fail("flow.reynolds", "give either flow.nu or flow.reynolds, not both")
    nu = flow.number("nu", None, positive=True)
    re_number = flow.number("reynolds", None, positive=True)
    flow.done()

    body_table = top.table("body", required=True)
    body = _body(reader, body_table, nx, ny)

    # reference length and speed (stated in docs/reference/scenes.md): frontal size across the stream,
    # inflow speed; without inflow, the fastest phase of the motion script
    motion_list = top.raw("motion", [])
    phases = _phases(reader, motion_list, inflow_speed)
    script = MotionScript(phases)
    length = float(body.frontal_area(STREAM_DIRECTION))
    speed = inflow_speed if inflow_speed > 0 else max((p.peak_speed for p in phases), default=0.0)
    if re_number is not None:
        if speed <= 0:
            reader.fail("flow.reynolds", "needs a reference speed (flow.inflow_speed > 0 or a moving "
                                         "motion phase); give flow.nu instead")
        nu = units.viscosity_for_reynolds(re_number, speed, length)
    elif nu is None:
        nu = 0.02
    from feelflow.solver.operator_choice import choose

    choice = choose(speed, nu, length, named=named_operator, smagorinsky=smagorinsky)
    collision = choice.collision
    if smagorinsky and collision != "rr":
        reader.fail("flow.smagorinsky", f"only the rr collision takes a Smagorinsky constant "
                                        f"(the scene runs {collision}); add flow.collision = \"rr\"")

    output = top.table("output")
    models = output.raw("forces", ["momentum_exchange"])
    if (not isinstance(models, list) or not models or not all(isinstance(m, str) for m in models)):
        reader.fail("output.forces", f"must be a non-empty list of force model names, got {_show(models)}")
    for m in models:
        if m not in MODELS:
            reader.fail("output.forces", f"unknown force model {m!r}; choose from {', '.join(MODELS)}")
    if len(set(models)) != len(models):
        reader.fail("output.forces", "names a force model twice")
    interval = output.integer("interval", 100, lo=1, hi=MAX_STEPS)
    output.done()

    run = top.table("run")
    default_steps = script.total_steps if script.total_steps > 0 else None
    steps = run.integer("steps", default_steps if default_steps else MISSING, lo=1, hi=MAX_STEPS)
    backend = run.choice("backend", sorted(BACKENDS) + ["auto"], "auto")
    run.done()
    top.done()

    try:
        config = FlowConfig(
            nx=nx, ny=ny, nu=nu, collision=collision, smagorinsky=choice.smagorinsky, trt_magic=trt_magic,
            equilibrium=equilibrium,
            dtype=dtype,
            x_boundary=x_boundary, y_boundary=walls, inflow_speed=inflow_speed,
            inflow_profile=inflow_profile, inflow_ramp_steps=ramp, body_force=body_force,
            sponge_cells=sponge_cells, sponge_strength=sponge_strength, sponge_absorb=sponge_absorb,
            inlet_nonreflecting=inlet_nonreflecting, initial_velocity=initial_velocity, mach_limit=mach_limit,
        ).validate()
    except ConfigError as exc:
        key = CONFIG_KEYS.get(exc.key, exc.key)
        if exc.key == "nu" and re_number is not None:
            key = "flow.reynolds"
        message = str(exc)[len(exc.key) + 2:]
        if key == "flow.reynolds":
            message = f"gives nu = {nu:.4g}, which is {message}"
        reader.fail(key, message)

    check_work(nx, ny, steps, source, "run.steps")
    for i, phase in enumerate(phases):
        if phase.peak_speed > config.max_speed:
            reader.fail(f"motion[{i}]", f"body speed {phase.peak_speed:.4g} exceeds the Mach limit "
                                        f"{config.max_speed:.4f} (Ma {config.mach_limit})")
    check_path_inside(source, body, script, steps, nx, ny)

    return Scene(source=source, config=config, body=body, motion=script, force_models=tuple(models),
                 output_interval=interval, steps=steps, backend=backend,
                 reference_length=length, reference_speed=speed, operator_named=named_operator,
                 operator_reason=choice.reason)


#: shape parameters that are angles: radians in `shapes`, degrees in scene files
ANGLE_KEYS = ("angle", "apex_angle")
#: body parameters that may be zero (a NACA section without camber)
NONNEGATIVE_KEYS = ("camber",)


def _body(reader: _Reader, table: _Table, nx: int, ny: int):
    from feelflow.shapes.base import ShapeError
    from feelflow.shapes.io import KINDS, from_dict

    kind = table.choice("kind", list(KINDS))
    _, required, optional = KINDS[kind]
    description = {"kind": kind, "x": table.number("x"), "y": table.number("y"),
                   "angle": math.radians(table.number("angle", 0.0))}
    for key in required + tuple(optional):
        if key == "vertices":
            value = table.raw(key)
            if not isinstance(value, list) or not all(
                    isinstance(v, list) and len(v) == 2
                    and all(not isinstance(c, bool) and isinstance(c, (int, float)) for c in v) for v in value):
                reader.fail("body.vertices", f"must be a list of [x, y] number pairs, got {_show(value)}")
            description[key] = [[float(c) for c in v] for v in value]
        elif key in optional and isinstance(optional[key], str):
            description[key] = table.choice(key, _string_choices(kind, key), optional[key])
        elif key in ANGLE_KEYS:
            description[key] = math.radians(table.number(key, optional.get(key, MISSING), positive=True))
        elif key in NONNEGATIVE_KEYS:
            description[key] = table.number(key, optional.get(key, MISSING), nonnegative=True)
        else:
            description[key] = table.number(key, optional.get(key, MISSING), positive=True)
    table.done()
    try:
        shape = from_dict(description)
        shape.validate(nx, ny)
    except ShapeError as exc:
        message = str(exc).splitlines()[0]
        reader.fail(_shape_key(description, message), message)
    return shape


def _string_choices(kind: str, key: str) -> tuple[str, ...]:
    from feelflow.shapes import polygon

    return {("wedge", "pointing"): polygon.WEDGE_POINTING}[(kind, key)]


def _shape_key(description: dict, message: str) -> str:
    """The scene key a shape error is about (its message names the parameter)."""
    for name in sorted(description, key=len, reverse=True):
        if name != "kind" and re.search(rf"\b{re.escape(name)}\b", message):
            return f"body.{name}"
    if "vertices" in description and re.search(r"vert|edge|self-intersect|area", message):
        return "body.vertices"
    return "body"


def _phases(reader: _Reader, motion, inflow_speed: float) -> list[Phase]:
    if not isinstance(motion, list):
        reader.fail("motion", "must be a list of phases ([[motion]] tables)")
    phases = []
    for i, item in enumerate(motion):
        t = _Table(reader, item, f"motion[{i}]")
        steps = t.integer("steps", lo=1, hi=MAX_STEPS)
        if t.has("velocity") and t.has("move"):
            reader.fail(t.key("move"), "give either move or velocity, not both")
        if t.has("velocity"):
            velocity = t.pair("velocity")
        elif t.has("amplitude") and not t.has("move"):   # an oscillation about a resting pose
            velocity = (0.0, 0.0)
        else:
            move = t.choice("move", MOVES)
            speed = t.number("speed", inflow_speed, nonnegative=True)
            if move != "stop" and speed == 0:
                reader.fail(t.key("speed"), f"a '{move}' phase needs a speed (flow.inflow_speed is 0)")
            velocity = phase_velocity(move, speed, STREAM_DIRECTION)
        amplitude, period = (0.0, 0.0), 0.0
        if t.has("amplitude") or t.has("period"):   # a sinusoidal oscillation on top
            if not (t.has("amplitude") and t.has("period")):
                reader.fail(t.key("period" if t.has("amplitude") else "amplitude"),
                            "an oscillating phase needs both amplitude (cells) and period (steps)")
            amplitude = t.pair("amplitude")
            period = t.number("period", positive=True)
            if period < 4:
                reader.fail(t.key("period"), f"must be at least 4 steps, got {period:g}")
        t.done()
        phases.append(Phase(steps=steps, velocity=velocity, amplitude=amplitude, period=period))
    return phases


def check_path_inside(source: str, body, script: MotionScript, steps: int, nx: int, ny: int) -> None:
    """The body must stay inside the domain (with a margin) for the whole run of `steps` steps
    (the scene's, or a command line's --steps); UserError naming `source` otherwise."""
    reader = _Reader(source)
    xmin, ymin, xmax, ymax = body.bounding_box()
    for t, (dx, dy) in script.extreme_displacements(steps):
        if (xmin + dx < EDGE_MARGIN or ymin + dy < EDGE_MARGIN
                or xmax + dx > nx - 1 - EDGE_MARGIN or ymax + dy > ny - 1 - EDGE_MARGIN):
            reader.fail("motion", f"the body leaves the domain by step {t} "
                                  f"(centre at x = {body.x + dx:.1f}, y = {body.y + dy:.1f}; "
                                  f"grid {nx} x {ny}, margin {EDGE_MARGIN:g} cells)")
