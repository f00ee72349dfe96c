"""Exercise files: a TOML design task (instructions, scoring scene, what may be edited,
constraints, objective, reference solutions), loaded into a validated `Exercise`.

Every key is documented in docs/reference/exercise-format.md. Every bad value, missing required
key or unknown key raises `UserError` with one line `FILE: KEY: what is wrong`, as scene files
do (app/model/scene.py, whose table reader this module shares).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

from feelflow.app.errors import UserError, shown, shown_path
from feelflow.app.inputs import MAX_STEPS, check_memory, check_work
from feelflow.app.model.scene import MISSING, _Reader, _show, _Table
from feelflow.solver import units
from feelflow.solver.config import ConfigError, FlowConfig

#: objective kind -> (what is scored, better is "lower" or "higher")
OBJECTIVES = {
    "least_cd": ("C_D", "lower"),
    "largest_cl": ("C_L", "higher"),
    "largest_ld": ("C_L / C_D", "higher"),
    "target_cd": ("|C_D - target|", "lower"),
    "target_cl": ("|C_L - target|", "lower"),
}
#: shape kinds a student may edit (shapes/io.py KINDS)
EDIT_KINDS = ("polygon", "cylinder", "plate", "wedge", "half_airfoil", "naca")
WALLS = ("free_slip", "no_slip")
DOC = "docs/reference/exercise-format.md"


class _ExerciseTable(_Table):
    """A scene-file table reader whose unknown-key message points at the exercise format."""

    def table(self, key, required=False):
        v = self.raw(key, MISSING if required else {})
        return _ExerciseTable(self.reader, v, self.key(key))

    def text(self, key, default=...):
        v = self.raw(key) if default is ... else self.raw(key, default)
        if not isinstance(v, str) or not v.strip():
            self.reader.fail(self.key(key), f"must be a non-empty text, got {_show(v)}")
        return v.strip()

    def range_pair(self, key, lo_bound=None, integer=False):
        """An optional [min, max] pair with min <= max (None when absent)."""
        if not self.has(key):
            self.used.add(key)
            return None
        v = self.raw(key)
        kind = int if integer else (int, float)
        if (not isinstance(v, list) or len(v) != 2
                or any(isinstance(c, bool) or not isinstance(c, kind) for c in v)
                or any(not math.isfinite(c) for c in v)):
            what = "two integers" if integer else "two finite numbers"
            self.reader.fail(self.key(key), f"must be {what} [min, max], got {_show(v)}")
        lo, hi = v
        if lo > hi:
            self.reader.fail(self.key(key), f"min {lo:g} is larger than max {hi:g}")
        if lo_bound is not None and lo < lo_bound:
            self.reader.fail(self.key(key), f"min must be >= {lo_bound:g}, got {lo:g}")
        return (int(lo), int(hi)) if integer else (float(lo), float(hi))

    def done(self):
        unknown = [k for k in self.data if k not in self.used]
        if unknown:
            self.reader.fail(self.key(unknown[0]), f"unknown key (see {DOC})")


@dataclass(frozen=True)
class ScoringScene:
    """The tunnel a shape is scored in, at the exercise's own resolution (scale 1).

    Lengths in cells, times in steps. `scaled(s)` gives the same flow at s times the resolution:
    lengths (positions measured from the walls) and steps times s, the inflow speed kept, so Re and Ma are the same and the viscosity
    grows by s (diffusive time grows like s: the flow needs s times the steps to the same state).
    """

    nx: int
    ny: int
    reynolds: float
    inflow_speed: float
    walls: str
    body_x: float
    body_y: float
    reference_length: float
    steps: int
    average_steps: int
    sample_interval: int
    settle_tolerance: float
    sponge_cells: int
    why: str
    scale: int = 1

    @property
    def nu(self) -> float:
        return units.viscosity_for_reynolds(self.reynolds, self.inflow_speed, self.reference_length)

    def scaled(self, s: int) -> "ScoringScene":
        # node i sits at (i + 1/2) cells from the wall at -1/2: a position scales about that wall,
        # so a body centred in the tunnel stays centred (and symmetric on the lattice)
        return replace(self, nx=self.nx * s, ny=self.ny * s, body_x=(self.body_x + 0.5) * s - 0.5,
                       body_y=(self.body_y + 0.5) * s - 0.5,
                       reference_length=self.reference_length * s, steps=self.steps * s,
                       average_steps=self.average_steps * s, sample_interval=self.sample_interval * s,
                       sponge_cells=self.sponge_cells * s, scale=self.scale * s)

    def live_scene(self) -> dict:
        """The scene, in a scene file's form (app/model/scene.py `scene_from_dict`), that the
        window's live tunnel shows while the exercise is open: the same flow in float32, with a
        cylinder of the reference length where the body goes until the student's shape is put
        in."""
        return {"grid": {"nx": self.nx, "ny": self.ny},
                "flow": {"nu": self.nu, "inflow_speed": self.inflow_speed, "walls": self.walls, "dtype": "float32",
                         "inflow_ramp_steps": 0, "initial_velocity": [self.inflow_speed, 0.0],
                         "sponge_cells": self.sponge_cells, "sponge_absorb": 0.1},
                "body": {"kind": "cylinder", "diameter": self.reference_length, "x": self.body_x, "y": self.body_y},
                "run": {"steps": self.steps}}

    def flow_config(self) -> FlowConfig:
        """numpy float64, TRT, the wind blowing from the first step with an absorbing outlet
        sponge (the window's base configuration, app/model/flow_choice.py)."""
        return FlowConfig(nx=self.nx, ny=self.ny, nu=self.nu, collision="trt", dtype="float64",
                          x_boundary="tunnel", y_boundary=self.walls, inflow_speed=self.inflow_speed,
                          inflow_ramp_steps=0, initial_velocity=(self.inflow_speed, 0.0),
                          sponge_cells=self.sponge_cells, sponge_absorb=0.1).validate()


@dataclass(frozen=True)
class Constraints:
    """What a shape must satisfy before it is scored (all optional; lengths in cells at the
    exercise's resolution, area in cells^2, angles in degrees)."""

    area: tuple | None = None
    frontal_height: tuple | None = None
    length: tuple | None = None
    vertices: tuple | None = None
    angle: tuple | None = None
    min_thickness: float | None = None


@dataclass(frozen=True)
class Objective:
    kind: str
    target: float | None = None
    tolerance: float | None = None
    #: the grid uncertainty of a score, in the score's units (app/exercises/uncertainty.py)
    uncertainty: float | None = None

    @property
    def quantity(self) -> str:
        return OBJECTIVES[self.kind][0]

    @property
    def better(self) -> str:
        return OBJECTIVES[self.kind][1]


@dataclass(frozen=True)
class Reference:
    path: Path
    label: str
    score: float


@dataclass(frozen=True)
class Exercise:
    source: str
    path: Path | None
    title: str
    instructions: str
    teacher_note: str
    scene: ScoringScene
    kinds: tuple[str, ...]
    start: Path
    constraints: Constraints
    objective: Objective
    references: tuple[Reference, ...] = field(default_factory=tuple)
    check_shapes: tuple[Path, ...] = field(default_factory=tuple)

    @property
    def folder(self) -> Path:
        return self.path.parent if self.path else Path(".")

    def input_files(self) -> tuple[Path, ...]:
        """Every shape file the exercise names (start, references, check shapes)."""
        return (self.start, *(r.path for r in self.references), *self.check_shapes)


def load_exercise(path) -> Exercise:
    """Read and validate an exercise file through the one reader (app/inputs.py: a regular file
    of at most 1 MiB, bounded depth and numbers); UserError (one line) on any problem."""
    from feelflow.app.inputs import load_toml

    path = Path(path)
    data = load_toml(path, "exercise file")
    return exercise_from_dict(data, shown_path(path), path)


def exercise_from_dict(data: dict, source: str = "exercise", path: Path | None = None) -> Exercise:
    """Validate an exercise given as nested dicts (the parsed TOML); file names in it are
    relative to `path`'s folder."""
    reader = _Reader(source)
    top = _ExerciseTable(reader, data, "")
    folder = path.parent if path else Path(".")
    title = top.text("title")
    instructions = top.text("instructions")
    teacher_note = top.text("teacher_note")

    s = top.table("scene", required=True)
    nx = s.integer("nx", lo=32, hi=2048)
    ny = s.integer("ny", lo=16, hi=2048)
    reynolds = s.number("reynolds", positive=True)
    speed = s.number("inflow_speed", positive=True)
    walls = s.choice("walls", WALLS, "free_slip")
    body_x, body_y = s.pair("body_position")
    reference_length = s.number("reference_length", positive=True)
    steps = s.integer("steps", lo=100, hi=MAX_STEPS)
    average_steps = s.integer("average_steps", lo=10)
    sample_interval = s.integer("sample_interval", 10, lo=1)
    settle = s.number("settle_tolerance", 0.005, positive=True)
    sponge = s.integer("sponge_cells", nx // 8, lo=0, hi=nx // 2)
    why = s.text("why")
    s.done()
    try:   # the work one scoring run asks for, before anything is run (app/inputs.py)
        check_work(nx, ny, steps, source, "scene.steps")
        check_memory(nx, ny, source, "scene.nx, scene.ny")
    except UserError as exc:
        raise UserError(str(exc)) from None
    if reference_length > max(nx, ny):
        reader.fail("scene.reference_length", f"must be at most the grid's size ({max(nx, ny)} cells), "
                                              f"got {shown(reference_length)}")
    if settle > 1:
        reader.fail("scene.settle_tolerance", f"must be at most 1 (a fraction of the score), got {shown(settle)}")
    if average_steps > steps:
        reader.fail("scene.average_steps", f"must not exceed scene.steps ({steps}), got {average_steps}")
    if average_steps % sample_interval:
        reader.fail("scene.average_steps", f"must be a multiple of scene.sample_interval ({sample_interval})")
    if steps % sample_interval:
        reader.fail("scene.steps", f"must be a multiple of scene.sample_interval ({sample_interval})")
    if not (0 < body_x < nx - 1 and 0 < body_y < ny - 1):
        reader.fail("scene.body_position", f"({body_x:g}, {body_y:g}) lies outside the grid {nx} x {ny}")
    scene = ScoringScene(nx=nx, ny=ny, reynolds=reynolds, inflow_speed=speed, walls=walls, body_x=body_x,
                         body_y=body_y, reference_length=reference_length, steps=steps,
                         average_steps=average_steps, sample_interval=sample_interval,
                         settle_tolerance=settle, sponge_cells=sponge, why=why)
    try:
        scene.flow_config()
    except ConfigError as exc:
        key = {"nu": "scene.reynolds", "inflow_speed": "scene.inflow_speed",
               "sponge_cells": "scene.sponge_cells"}.get(exc.key, "scene")
        reader.fail(key, str(exc)[len(exc.key) + 2:])

    e = top.table("edit", required=True)
    kinds = e.raw("kinds")
    if (not isinstance(kinds, list) or not kinds or any(k not in EDIT_KINDS for k in kinds)
            or len(set(kinds)) != len(kinds)):
        reader.fail("edit.kinds", f"must be a list of distinct shape kinds from {', '.join(EDIT_KINDS)}; "
                                  f"got {_show(kinds)}")
    start = _file(reader, "edit.start", e.text("start"), folder)
    e.done()

    c = top.table("constraints")
    constraints = Constraints(
        area=c.range_pair("area", lo_bound=0),
        frontal_height=c.range_pair("frontal_height", lo_bound=0),
        length=c.range_pair("length", lo_bound=0),
        vertices=c.range_pair("vertices", lo_bound=3, integer=True),
        angle=c.range_pair("angle"),
        min_thickness=c.number("min_thickness", None, positive=True),
    )
    c.done()
    if constraints.angle and not (-90 <= constraints.angle[0] and constraints.angle[1] <= 90):
        reader.fail("constraints.angle", f"must lie within [-90, 90] degrees, got {list(constraints.angle)}")

    o = top.table("objective", required=True)
    kind = o.choice("kind", tuple(OBJECTIVES))
    target = tolerance = None
    if kind.startswith("target_"):
        target = o.number("target")
        tolerance = o.number("tolerance", positive=True)
    uncertainty = o.number("grid_uncertainty", None, positive=True)
    o.done()
    objective = Objective(kind, target, tolerance, uncertainty)

    refs = top.raw("reference", [])
    if not isinstance(refs, list) or not refs:
        reader.fail("reference", "must list at least one reference solution ([[reference]] tables)")
    references = []
    for i, item in enumerate(refs):
        t = _ExerciseTable(reader, item, f"reference[{i}]")
        ref_path = _file(reader, t.key("file"), t.text("file"), folder)
        label = t.text("label")
        score = t.number("score")
        t.done()
        references.append(Reference(ref_path, label, score))
    chk = top.table("check")
    names = chk.raw("shapes", [])
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        reader.fail("check.shapes", f"must be a list of shape file names, got {_show(names)}")
    check_shapes = tuple(_file(reader, f"check.shapes[{i}]", n, folder) for i, n in enumerate(names))
    chk.done()
    top.done()

    exercise = Exercise(source=source, path=path, title=title, instructions=instructions,
                        teacher_note=teacher_note, scene=scene, kinds=tuple(kinds), start=start,
                        constraints=constraints, objective=objective, references=tuple(references),
                        check_shapes=check_shapes)
    _check_shapes(reader, exercise)
    return exercise


def _file(reader, key: str, name: str, folder: Path) -> Path:
    """A shape file the exercise names, relative to the exercise file's folder. With every link
    followed it must lie inside that folder or the shipped exercises' folder (a file may not
    reach out to `../../etc/passwd`), and be a regular file of at most a shape file's size."""
    import os

    from feelflow import EXERCISE_DIR
    from feelflow.app.inputs import check_regular_file
    from feelflow.app.shape_files import MAX_FILE_BYTES

    if len(name) > 4096 or "\x00" in name:
        reader.fail(key, f"not a usable file name: {shown(name)!r}")
    p = Path(name)
    p = p if p.is_absolute() else folder / p
    try:
        real = Path(os.path.realpath(p))
        roots = [Path(os.path.realpath(r)) for r in (folder, EXERCISE_DIR)]
    except (OSError, ValueError) as exc:
        reader.fail(key, f"cannot follow {shown(name)!r} ({getattr(exc, 'strerror', None) or exc})")
    if not any(real == root or real.is_relative_to(root) for root in roots):
        reader.fail(key, f"{shown(name)!r} lies outside the exercise file's folder; an exercise may only "
                         f"name shape files in its own folder (or below it)")
    try:
        check_regular_file(p, "shape file", MAX_FILE_BYTES)
    except UserError as exc:
        message = str(exc)
        if "no such shape file" in message:
            message = f"no such shape file {shown(name)!r} (relative to the exercise file's folder)"
        reader.fail(key, message)
    return p


def _check_shapes(reader, exercise: Exercise) -> None:
    """The starting shape must be a valid shape file of an editable kind; every reference
    solution must be a valid shape file that meets the constraints."""
    from feelflow.app.exercises.constraints import check_shape
    from feelflow.shapes.base import ShapeError
    from feelflow.app.shape_files import load_shape

    for key, p, must_pass in [("edit.start", exercise.start, False)] + [
            (f"reference[{i}].file", r.path, True) for i, r in enumerate(exercise.references)]:
        try:
            shape = load_shape(p)
        except ShapeError as exc:
            reader.fail(key, str(exc).splitlines()[0])
        if shape.kind not in exercise.kinds:
            reader.fail(key, f"a {shape.kind} shape, but edit.kinds allows {', '.join(exercise.kinds)}")
        if must_pass:
            problems = check_shape(exercise, shape)
            if problems:
                reader.fail(key, f"breaks a constraint: {problems[0]}")
