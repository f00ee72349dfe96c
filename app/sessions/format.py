"""The session file: a versioned zip, read and written here and nowhere else.

Format (docs/reference/session-format.md): a zip with `manifest.json` (format, version, FeelFlow version,
backend, renderer, created time, the scene, counts), `parameters.json` (parameter changes) and
`inputs.npz` / `forces.npz` (arrays, read with `allow_pickle=False`; never pickle), plus
`state.npz` when the recording began on a running flow. Every event carries its *session step*
(steps simulated since recording began; it never decreases, a reset does not rewind it) and a
global sequence number `seq` fixing the order of events within one step.

`load_session` validates everything before a caller sees it: a bad file is one `SessionError`
line naming the member and the value. Qt-free.
"""
from __future__ import annotations

import dataclasses
import io
import json
import math
import zipfile
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from feelflow.app.errors import shown
from feelflow.app.sessions import versions
from feelflow.app.sessions import bounds
from feelflow.app.sessions.bounds import MAX_FILE_BYTES, check_npz, member_limits
from feelflow.solver.config import ConfigError, FlowConfig

FORMAT = "feelflow-session"
#: the format version written; bumped whenever an older reader would misread a file, with a
#: loader for the new version (app/sessions/versions.py; docs/reference/session-format.md, "Versioning")
VERSION = versions.VERSION
SUFFIX = ".ffsession"

MANIFEST = "manifest.json"
PARAMETERS = "parameters.json"
INPUTS = "inputs.npz"
FORCES = "forces.npz"
STATE = "state.npz"  # only when the recording started on a running flow (manifest "start")
#: optional: the probes placed in the window while it recorded (app/model/probes.py `to_arrays`):
#: `positions` (k, 2) lattice cells, `probe0`..`probe3` (n, 4) rows of step, ux, uy, p. A reader
#: without probes ignores it, so it needs no new format version.
PROBES = "probes.npz"
PROBES_MAX_BYTES = 16 << 20
PROBE_NAMES = ("positions", "probe0", "probe1", "probe2", "probe3")
#: optional manifest key: the units the window showed while it recorded (View > Units;
#: app/model/display_units.py): {"fluid": "lattice" or a solver/units.py FLUIDS key, "size_m",
#: "span_m"}. Only what is shown depends on it, never the replay, and a reader that does not know
#: it ignores it, so it needs no new format version.
UNITS = "units"
MEMBERS = (MANIFEST, PARAMETERS, INPUTS, FORCES)
#: largest uncompressed member we read (a zip bomb is refused before it is inflated); the
#: array members are bounded tighter, by the rows and grid the manifest declares
MAX_MEMBER_BYTES = 1 << 30

#: parameter name -> what its value is (docs/reference/session-format.md, "Parameter changes")
PARAMETER_NAMES = ("body", "inflow_speed", "nu", "force_models", "pause", "resume", "reset", "rebuild")
#: array name -> (dtype, trailing shape) in each .npz member
INPUT_ARRAYS = {"seq": ("int64", ()), "step": ("int64", ()), "pose": ("float64", (3,)),
                "velocity": ("float64", (3,))}
FORCE_ARRAYS = {"seq": ("int64", ()), "step": ("int64", ()), "n": ("int64", ()),
                "body": ("float64", (4,)), "values": ("float64", None)}
#: forces.npz's arrays that only some versions hold (versions.py says which must be there)
FORCE_ARRAYS_SINCE = {"torques": ("float64", None)}
STATE_ARRAYS = {"f": ("float64", None)}
#: state.npz's optional array: the quiet inlet's reference (ny,) float64 (solver/quiet_inlet.py),
#: present when the flow had one; without it the replay would drift from the recording
INLET_REFERENCE = "inlet_reference"
#: a commanded body or inflow speed beyond this (one cell per step) is not a lattice velocity
MAX_LATTICE_SPEED = 1.0


def feelflow_version() -> str:
    """The installed FeelFlow's version (pyproject.toml), or "unknown" from a bare checkout."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("feelflow")
    except PackageNotFoundError:
        return "unknown"


class SessionError(ValueError):
    """A session file or recording is unusable; the message is one line naming what is wrong."""


# --- the scene as the session stores it -------------------------------------------------------

def config_to_dict(config: FlowConfig) -> dict:
    """FlowConfig -> the current version's JSON-ready dict (app/sessions/versions.py's schema;
    tuples become lists; `extra` is kept if JSON-able)."""
    return versions.config_to_dict(config)


def config_from_dict(d) -> FlowConfig:
    """The inverse of `config_to_dict`, validated; SessionError naming the bad key."""
    if not isinstance(d, dict):
        raise SessionError("scene.config must be an object")
    names = {f.name for f in dataclasses.fields(FlowConfig)}
    unknown = sorted(set(d) - names)
    if unknown:
        raise SessionError(f"scene.config has unknown key {shown(unknown[0])!r}")
    kwargs = {}
    for key, v in d.items():
        if key in ("body_force", "initial_velocity"):
            if not isinstance(v, list) or len(v) != 2 or not all(is_number(c) for c in v):
                raise SessionError(f"scene.config.{key} must be two numbers")
            v = (float(v[0]), float(v[1]))
        kwargs[key] = v
    try:
        config = FlowConfig(**kwargs).validate()
    except ConfigError as exc:
        raise SessionError(f"scene.config.{exc}") from None
    except TypeError as exc:  # a missing nx/ny, or a value of the wrong type
        raise SessionError(f"scene.config: {str(exc).splitlines()[0]}") from None
    from feelflow.app.errors import UserError
    from feelflow.app.inputs import check_work

    try:   # the scene files' grid bound (MAX_NODES), also for a recorded rebuild
        check_work(config.nx, config.ny, 0, "scene.config", "grid")
    except UserError as exc:
        raise SessionError(str(exc)) from None
    return config


def is_number(v) -> bool:
    return not isinstance(v, bool) and isinstance(v, (int, float)) and math.isfinite(v)


def shape_from_dict(d, where: str, config: FlowConfig):
    from feelflow.shapes.base import ShapeError
    from feelflow.shapes.io import from_dict

    try:
        shape = from_dict(d)
        return shape.validate(config.nx, config.ny) if config is not None else shape.validate()
    except (ShapeError, TypeError, ValueError) as exc:
        raise SessionError(f"{where}: {str(exc).splitlines()[0]}") from None


def force_columns(models) -> list[str]:
    """The CSV columns of `feelflow run`: step, x, y, vx, vy, fx_<m>, fy_<m> per model, then
    torque_<m> per model (about the body's centre, counter-clockwise positive)."""
    cols = ["step", "x", "y", "vx", "vy"]
    for m in models:
        cols += [f"fx_{m}", f"fy_{m}"]
    return cols + [f"torque_{m}" for m in models]


# --- a session in memory ----------------------------------------------------------------------

@dataclass
class Session:
    """A recorded session (from `load_session` or `SessionRecorder.session()`).

    inputs: seq, step (k,) int64; pose (k, 3) x, y, angle; velocity (k, 3) vx, vy, omega.
    parameters: [{"seq", "step", "name", "value"}].
    forces: seq, step, n (m,) int64; body (m, 4) x, y, vx, vy; values (m, 2 * len(models))
    fx, fy per model (NaN where a model was not computed); torques (m, len(models)) each
    model's torque about the body's centre (NaN where not computed or not recorded).
    """

    manifest: dict
    config: FlowConfig
    body: object
    backend: str
    force_models: tuple[str, ...]
    inputs: dict
    parameters: list
    forces: dict
    models: tuple[str, ...]
    start: dict | None = None        # manifest "start": recording began on a running flow
    state: np.ndarray | None = None  # then its populations f (9, ny, nx), from state.npz
    inlet_reference: np.ndarray | None = None  # and the quiet inlet's reference (ny,), if it has one
    probes: dict | None = None       # the window's probes, from the optional probes.npz (PROBES)
    units: dict | None = None        # the window's units choice, from the optional manifest key UNITS
    source: str = field(default="session", compare=False)

    @property
    def steps(self) -> int:
        return int(self.forces["step"][-1]) if len(self.forces["step"]) else 0

    def events(self):
        """Every event in recorded order: ("input", step, pose, velocity),
        ("parameter", step, name, value), ("forces", step, n, body, values)."""
        out = []
        for k in range(len(self.inputs["seq"])):
            out.append((int(self.inputs["seq"][k]), ("input", int(self.inputs["step"][k]),
                                                     tuple(self.inputs["pose"][k]), tuple(self.inputs["velocity"][k]))))
        for p in self.parameters:
            out.append((p["seq"], ("parameter", p["step"], p["name"], p["value"])))
        f = self.forces
        for k in range(len(f["seq"])):
            out.append((int(f["seq"][k]), ("forces", int(f["step"][k]), int(f["n"][k]),
                                           tuple(f["body"][k]), f["values"][k])))
        out.sort(key=lambda e: e[0])
        return [e for _, e in out]

    def frames(self):
        """Play the recorded series back without simulating: (step, (x, y, vx, vy),
        {model: (fx, fy)}) per force row, models not computed in that row left out."""
        f = self.forces
        for k in range(len(f["step"])):
            row = f["values"][k]
            forces = {m: (float(row[2 * j]), float(row[2 * j + 1])) for j, m in enumerate(self.models)
                      if not (math.isnan(row[2 * j]) and math.isnan(row[2 * j + 1]))}
            yield int(f["step"][k]), tuple(float(v) for v in f["body"][k]), forces

    def torques(self, row: int) -> dict[str, float]:
        """{model: torque} of force row `row`, models without a torque there left out."""
        t = self.forces["torques"][row]
        return {m: float(t[j]) for j, m in enumerate(self.models) if not math.isnan(t[j])}

    def csv_rows(self, values=None, torques=None):
        """Rows for `force_columns(self.models)` (shortest round-trip decimals; NaN as 'nan')."""
        f = self.forces
        values = f["values"] if values is None else values
        torques = f["torques"] if torques is None else torques
        for k in range(len(f["step"])):
            yield ([str(int(f["step"][k]))] + [_fmt(v) for v in f["body"][k]] + [_fmt(v) for v in values[k]]
                   + [_fmt(v) for v in torques[k]])


def _fmt(v) -> str:
    return "nan" if math.isnan(v) else repr(float(v))


# --- files ------------------------------------------------------------------------------------

def atomic_write_bytes(path, data: bytes, what: str = "file") -> Path:
    """Write `data` through the app's one writer (app/files.py: temp file beside, fsync,
    os.replace; on failure a rescue copy in the temp folder). SessionError naming the path if it
    cannot (the old file is left as it was)."""
    from feelflow.app.files import OutputError, save_bytes

    try:
        return save_bytes(path, data, what)
    except OutputError as exc:
        raise SessionError(str(exc)) from None


def _npz_bytes(arrays: dict) -> bytes:
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def session_bytes(session: Session) -> bytes:
    """The session file's bytes (a zip)."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        zf.writestr(MANIFEST, json.dumps(session.manifest, indent=2, allow_nan=False) + "\n")
        zf.writestr(PARAMETERS, json.dumps(session.parameters, indent=1, allow_nan=False) + "\n")
        zf.writestr(INPUTS, _npz_bytes(session.inputs))
        zf.writestr(FORCES, _npz_bytes(session.forces))
        if session.state is not None:
            arrays = {"f": session.state}
            if session.inlet_reference is not None:
                arrays[INLET_REFERENCE] = np.asarray(session.inlet_reference, dtype=np.float64)
            zf.writestr(STATE, _npz_bytes(arrays))
        if session.probes:
            zf.writestr(PROBES, _npz_bytes(session.probes))
    return buf.getvalue()


def save_session(session: Session, path) -> Path:
    """Write a session file atomically (temp file + os.replace)."""
    return atomic_write_bytes(path, session_bytes(session), "session file")


def load_session(path) -> Session:
    """Read and validate a session file; SessionError with one line naming what is wrong."""
    path = Path(path)
    src = str(path)

    def fail(message):
        raise SessionError(f"{src}: {message}")

    from feelflow.app.errors import UserError
    from feelflow.app.inputs import check_regular_file

    try:   # a regular file of bounded size, checked before opening (a pipe never blocks)
        check_regular_file(path, "session file", MAX_FILE_BYTES)
    except UserError as exc:
        raise SessionError(str(exc)) from None
    try:
        zf = zipfile.ZipFile(path)
    except FileNotFoundError:
        fail("no such session file")
    except PermissionError:
        fail("cannot be read (permission denied)")
    except (zipfile.BadZipFile, EOFError, OSError, ValueError, NotImplementedError, RuntimeError):
        fail("not a FeelFlow session file (not a zip archive; truncated or another kind of file)")
    with zf:
        names = set(zf.namelist())
        missing = [m for m in MEMBERS if m not in names]
        if missing:
            fail(f"not a complete session file: member {missing[0]} is missing")
        data = {}

        def read(member, limit):
            info = zf.getinfo(member)
            if info.file_size > limit:
                fail(f"{member} is {info.file_size} bytes uncompressed, more than this session can hold "
                     f"({limit} bytes, from the rows and grid it declares)")
            try:
                with zf.open(member) as fh:   # never more than the bound, whatever the header says
                    raw = fh.read(limit + 1)
            except (zipfile.BadZipFile, zlib.error, EOFError, OSError, NotImplementedError,
                    RuntimeError) as exc:
                fail(f"{member} is damaged ({str(exc).splitlines()[0] if str(exc) else type(exc).__name__})")
            if len(raw) > limit:
                fail(f"{member} inflates to more than {limit} bytes")
            data[member] = raw

        read(MANIFEST, bounds.MAX_JSON_BYTES)   # the recorder's bound too (bounds.session_problem)
        read(PARAMETERS, bounds.MAX_JSON_BYTES)
        manifest = _json_member(data[MANIFEST], MANIFEST, fail)
        limits = member_limits(manifest, fail, MANIFEST, (INPUTS, FORCES, STATE))
        for member in (INPUTS, FORCES) + ((STATE,) if STATE in names else ()):
            read(member, limits[member])
        if PROBES in names:
            read(PROBES, PROBES_MAX_BYTES)
    parameters = _json_member(data[PARAMETERS], PARAMETERS, fail)
    starts = isinstance(manifest, dict) and manifest.get("start") is not None
    if starts and STATE not in data:
        fail(f"the recording starts on a running flow but member {STATE} is missing")
    state = _npz_member(data[STATE], STATE, STATE_ARRAYS, fail)["f"] if starts else None
    reference = _optional_array(data[STATE], STATE, INLET_REFERENCE, fail) if starts else None
    probes = _probe_arrays(data[PROBES], fail) if PROBES in data else None
    try:
        session = _validate(manifest, parameters, _npz_member(data[INPUTS], INPUTS, INPUT_ARRAYS, fail),
                            _npz_member(data[FORCES], FORCES, FORCE_ARRAYS, fail, FORCE_ARRAYS_SINCE), src,
                            state, reference)
        session.probes = probes
        return session
    except SessionError as exc:
        if str(exc).startswith(src + ": "):
            raise
        fail(str(exc))


def _probe_arrays(raw: bytes, fail) -> dict:
    """The optional probes member: `positions` (k <= 4, 2) finite, `probeK` (n, 4) float64 for
    K < k; nothing else (no pickle)."""
    check_npz(raw, PROBES, fail)
    try:
        with np.load(io.BytesIO(raw), allow_pickle=False) as npz:
            names = set(npz.files)
            if "positions" not in names or not names <= set(PROBE_NAMES):
                fail(f"{PROBES} holds {sorted(names)}; expected positions and probe0..probe3")
            arrays = {k: npz[k] for k in names}
    except (ValueError, OSError, zipfile.BadZipFile, EOFError) as exc:
        fail(f"{PROBES} is not a readable .npz archive ({type(exc).__name__})")
    pos = arrays["positions"]
    if pos.dtype != np.float64 or pos.ndim != 2 or pos.shape[1] != 2 or len(pos) > 4 or not np.isfinite(pos).all():
        fail(f"{PROBES}: positions must be up to 4 finite (x, y) pairs, got {pos.dtype} {pos.shape}")
    for k in range(len(pos)):
        a = arrays.get(f"probe{k}")
        if a is None or a.dtype != np.float64 or a.ndim != 2 or a.shape[1] != 4:
            fail(f"{PROBES}: probe{k} must be (n, 4) float64 rows of step, ux, uy, p")
    return arrays


def _json_member(raw: bytes, member: str, fail):
    """Strict JSON (app/inputs.py: depth, integer size, no NaN)."""
    from feelflow.app.errors import UserError
    from feelflow.app.inputs import loads_json

    try:
        return loads_json(raw, member)
    except UserError as exc:
        fail(str(exc))


def _npz_member(raw: bytes, member: str, spec: dict, fail, optional: dict | None = None) -> dict:
    """The arrays of `spec` (name -> (dtype, trailing shape)), each checked, and those of
    `optional` that the member holds."""
    check_npz(raw, member, fail)
    try:
        with np.load(io.BytesIO(raw), allow_pickle=False) as npz:
            names = set(npz.files)
            missing = [k for k in spec if k not in names]
            if missing:
                fail(f"{member} has no array {missing[0]!r}")
            spec = {**spec, **{k: v for k, v in (optional or {}).items() if k in names}}
            arrays = {k: npz[k] for k in spec}
    except SessionError:
        raise
    except ValueError as exc:
        if "allow_pickle" in str(exc) or "pickle" in str(exc).lower():
            fail(f"{member} contains pickled objects (refused: session files never hold pickle)")
        fail(f"{member} holds a malformed array ({str(exc).splitlines()[0]})")
    except (zipfile.BadZipFile, zlib.error, EOFError, OSError, KeyError) as exc:
        fail(f"{member} is not a readable .npz archive ({type(exc).__name__})")
    rows = None
    for name, (dtype, trailing) in spec.items():
        a = arrays[name]
        if a.dtype != np.dtype(dtype):
            fail(f"{member}: array {name!r} must be {dtype}, got {a.dtype}")
        if trailing is None:
            ok = a.ndim == (3 if member == STATE else 2)
        else:
            ok = a.shape[1:] == trailing and a.ndim == 1 + len(trailing)
        if not ok:
            want = ("(9, ny, nx)" if member == STATE else "(rows, columns)") if trailing is None else str(("rows",) + trailing).replace("'", "")
            fail(f"{member}: array {name!r} has shape {a.shape}, expected {want}")
        if member == STATE:
            continue
        if rows is None:
            rows = a.shape[0]
        elif a.shape[0] != rows:
            fail(f"{member}: array {name!r} has {a.shape[0]} rows, the others {rows}")
    return arrays


def _optional_array(raw: bytes, member: str, name: str, fail):
    """Array `name` of an .npz member already read by _npz_member (so readable, no pickle), as
    a one-dimensional float64 array, or None when the member lacks it."""
    with np.load(io.BytesIO(raw), allow_pickle=False) as npz:
        if name not in npz.files:
            return None
        a = npz[name]
    if a.dtype != np.float64 or a.ndim != 1:
        fail(f"{member}: array {name!r} must be one-dimensional float64, got {a.dtype} with shape {a.shape}")
    return a


def _validate(manifest, parameters, inputs, forces, src, state=None, inlet_reference=None) -> Session:
    if not isinstance(manifest, dict) or manifest.get("format") != FORMAT:
        raise SessionError(f"{MANIFEST}: not a FeelFlow session (expected \"format\": \"{FORMAT}\")")
    try:   # one loader per format version: the file in the current version's form
        loader = versions.loader_for(manifest.get("version"))
        manifest, parameters = loader.upgrade(manifest, parameters)
    except versions.SessionFormatError as exc:
        raise SessionError(f"{MANIFEST}: {exc}") from None
    for key, kind in (("feelflow_version", str), ("created", str), ("backend", str), ("renderer", str),
                      ("scene", dict), ("forces", dict), ("counts", dict)):
        if not isinstance(manifest.get(key), kind):
            raise SessionError(f"{MANIFEST}: {key!r} is missing or not a {kind.__name__}")
    scene = manifest["scene"]
    if "config" not in scene:
        raise SessionError(f"{MANIFEST}: scene.config is missing")
    config = config_from_dict(scene["config"])
    body = None if scene.get("body") is None else shape_from_dict(scene["body"], "scene.body", config)
    from feelflow.solver.forces import MODELS

    initial_models = scene.get("force_models", [])
    if not isinstance(initial_models, list) or not all(isinstance(m, str) and m in MODELS for m in initial_models):
        raise SessionError(f"{MANIFEST}: scene.force_models must list force models ({', '.join(MODELS)})")
    for key in ("toml", "source"):
        if scene.get(key) is not None and not isinstance(scene[key], str):
            raise SessionError(f"{MANIFEST}: scene.{key} must be text")
    models = manifest["forces"].get("models")
    if not isinstance(models, list) or not all(isinstance(m, str) and m in MODELS for m in models) \
            or len(set(models)) != len(models):
        raise SessionError(f"{MANIFEST}: forces.models must list distinct force models ({', '.join(MODELS)})")
    if forces["values"].shape[1] != 2 * len(models):
        raise SessionError(f"{FORCES}: 'values' has {forces['values'].shape[1]} columns, expected "
                           f"{2 * len(models)} (fx, fy for {len(models)} models)")
    try:
        forces = loader.forces(forces, len(models))
    except versions.SessionFormatError as exc:
        raise SessionError(str(exc)) from None
    if forces["torques"].shape != (len(forces["seq"]), len(models)) or np.isinf(forces["torques"]).any():
        raise SessionError(f"{FORCES}: 'torques' must be {len(forces['seq'])} rows of {len(models)} torques "
                           f"(one per model, NaN where not computed), got shape {forces['torques'].shape}")
    counts = manifest["counts"]
    actual = {"inputs": len(inputs["seq"]), "parameters": len(parameters) if isinstance(parameters, list) else -1,
              "forces": len(forces["seq"]), "steps": int(forces["step"][-1]) if len(forces["step"]) else 0}
    for key, n in actual.items():
        if counts.get(key) != n:
            raise SessionError(f"{MANIFEST}: counts.{key} is {counts.get(key)!r} but the file holds {n}")
    start = _validate_start(manifest.get("start"), state, config)
    params = _validate_parameters(parameters, config)
    # the largest grid the session uses (a rebuild may change it)
    grids = [(config.nx, config.ny)] + [(p["value"]["config"]["nx"], p["value"]["config"]["ny"])
                                        for p in params if p["name"] == "rebuild"]
    gx, gy = max(g[0] for g in grids), max(g[1] for g in grids)

    # inputs: finite, in range
    pose, vel = inputs["pose"], inputs["velocity"]
    for name, a in (("pose", pose), ("velocity", vel)):
        bad = ~np.isfinite(a).all(axis=1)
        if bad.any():
            raise SessionError(f"{INPUTS}: input {int(np.argmax(bad))} has a non-finite {name} (NaN or inf)")
    out = (pose[:, 0] < 0) | (pose[:, 0] > gx) | (pose[:, 1] < 0) | (pose[:, 1] > gy)
    if out.any():
        k = int(np.argmax(out))
        raise SessionError(f"{INPUTS}: input {k} puts the body at ({pose[k, 0]:g}, {pose[k, 1]:g}), "
                           f"outside the {gx} x {gy} grid")
    fast = np.hypot(vel[:, 0], vel[:, 1]) > MAX_LATTICE_SPEED
    if fast.any():
        raise SessionError(f"{INPUTS}: input {int(np.argmax(fast))} has a body speed above "
                           f"{MAX_LATTICE_SPEED:g} cell per step")
    # forces: body finite or all NaN (no body); values may be NaN (model not computed)
    fb = forces["body"]
    mixed = np.isnan(fb).any(axis=1) & ~np.isnan(fb).all(axis=1)
    if mixed.any() or np.isinf(fb).any() or np.isinf(forces["values"]).any():
        raise SessionError(f"{FORCES}: malformed 'body' or 'values' (infinite, or partly missing)")
    if (forces["n"] < 1).any():
        raise SessionError(f"{FORCES}: row {int(np.argmax(forces['n'] < 1))} covers fewer than one step")
    ends = forces["step"]
    starts = np.concatenate([[0], ends[:-1]])
    gap = ends - forces["n"] != starts
    if gap.any():
        k = int(np.argmax(gap))
        raise SessionError(f"{FORCES}: row {k} covers steps {ends[k] - forces['n'][k]}..{ends[k]} "
                           f"but the previous row ended at step {starts[k]}")

    # one order: every seq once, steps never decreasing along it
    seq_step = [(int(s), int(t)) for s, t in zip(inputs["seq"], inputs["step"])]
    seq_step += [(p["seq"], p["step"]) for p in params]
    seq_step += [(int(s), int(t) - int(n)) for s, t, n in zip(forces["seq"], forces["step"], forces["n"])]
    seq_step.sort()
    if [s for s, _ in seq_step] != list(range(len(seq_step))):
        raise SessionError("event sequence numbers must be 0..N-1, each once")
    last = 0
    for s, t in seq_step:
        if t < last:
            raise SessionError(f"event {s} is at step {t}, before the previous event (step {last})")
        last = t
    # inputs and parameters happen between force rows: at the step the last row ended
    ends_by_seq = {int(s): int(t) for s, t in zip(forces["seq"], forces["step"])}
    clock = 0
    order = {int(s): ("i", int(t)) for s, t in zip(inputs["seq"], inputs["step"])}
    order.update({p["seq"]: ("p", p["step"]) for p in params})
    for s in range(len(seq_step)):
        if s in ends_by_seq:
            clock = ends_by_seq[s]
        elif order[s][1] != clock:
            raise SessionError(f"event {s} is stamped step {order[s][1]} but happens at step {clock}")
    return Session(manifest=manifest, config=config, body=body, backend=manifest["backend"],
                   force_models=tuple(initial_models), inputs=inputs, parameters=params,
                   forces=forces, models=tuple(models), start=start, state=state,
                   inlet_reference=_validate_inlet_reference(inlet_reference, config), source=src,
                   units=_validate_units(manifest.get(UNITS)))


def _validate_units(units) -> dict | None:
    """The optional manifest key UNITS: None, or {"fluid", "size_m", "span_m"} with a known
    fluid and positive finite lengths in metres."""
    if units is None:
        return None
    from feelflow.solver.units import FLUIDS

    fluids = ("lattice",) + tuple(FLUIDS)
    if not isinstance(units, dict) or set(units) != {"fluid", "size_m", "span_m"}:
        raise SessionError(f"{MANIFEST}: {UNITS} must hold exactly fluid, size_m and span_m")
    if units["fluid"] not in fluids:
        raise SessionError(f"{MANIFEST}: {UNITS}.fluid must be one of {', '.join(fluids)}, got {units['fluid']!r}")
    for key in ("size_m", "span_m"):
        v = units[key]
        if not (is_number(v) and 0 < v < 1e6):
            raise SessionError(f"{MANIFEST}: {UNITS}.{key} must be a positive length in metres, got {v!r}")
    return {"fluid": units["fluid"], "size_m": float(units["size_m"]), "span_m": float(units["span_m"])}


def _validate_inlet_reference(reference, config: FlowConfig):
    """state.npz's quiet-inlet reference: only with a quiet inlet, ny finite numbers."""
    if reference is None:
        return None
    if not (config.x_boundary == "tunnel" and config.inlet_nonreflecting > 0):
        raise SessionError(f"{STATE}: {INLET_REFERENCE!r} given but the scene has no quiet inlet (inlet_nonreflecting = 0)")
    if reference.shape != (config.ny,) or not np.isfinite(reference).all():
        raise SessionError(f"{STATE}: {INLET_REFERENCE!r} must be {config.ny} finite numbers, got shape {reference.shape}")
    return reference


def _validate_start(start, state, config: FlowConfig):
    """manifest "start" (null, or how the running flow was when recording began) and its state."""
    from feelflow.solver.forces import MODELS

    if start is None:
        return None
    where = f"{MANIFEST}: start"
    keys = {"time", "body_placed", "velocity", "omega", "force_models", "inflow_speed"}
    if not isinstance(start, dict) or set(start) != keys:
        raise SessionError(f"{where} must have exactly {', '.join(sorted(keys))}")
    if isinstance(start["time"], bool) or not isinstance(start["time"], int) or start["time"] < 0:
        raise SessionError(f"{where}.time must be a non-negative integer")
    if not isinstance(start["body_placed"], bool):
        raise SessionError(f"{where}.body_placed must be true or false")
    v = start["velocity"]
    if not (isinstance(v, list) and len(v) == 2 and all(is_number(c) for c in v)) or not is_number(start["omega"]) \
            or math.hypot(*v) > MAX_LATTICE_SPEED:
        raise SessionError(f"{where}: velocity and omega must be finite numbers (|v| <= 1)")
    if not isinstance(start["force_models"], list) or not all(isinstance(m, str) and m in MODELS for m in start["force_models"]):
        raise SessionError(f"{where}.force_models must list force models ({', '.join(MODELS)})")
    u = start["inflow_speed"]
    if u is not None and not (is_number(u) and abs(u) <= MAX_LATTICE_SPEED):
        raise SessionError(f"{where}.inflow_speed must be null or a number in -1..1")
    if state.shape != (9, config.ny, config.nx):
        raise SessionError(f"{STATE}: 'f' has shape {state.shape}, expected (9, {config.ny}, {config.nx})")
    if not np.isfinite(state).all():
        raise SessionError(f"{STATE}: the populations hold NaN or inf")
    return start


def _validate_parameters(parameters, config: FlowConfig) -> list:
    from feelflow.solver.forces import MODELS

    if not isinstance(parameters, list):
        raise SessionError(f"{PARAMETERS}: must be a list of parameter changes")
    out = []
    for k, p in enumerate(parameters):
        where = f"{PARAMETERS}: change {k}"
        if not isinstance(p, dict) or set(p) != {"seq", "step", "name", "value"}:
            raise SessionError(f"{where} must have exactly seq, step, name, value")
        for key in ("seq", "step"):
            if isinstance(p[key], bool) or not isinstance(p[key], int) or p[key] < 0:
                raise SessionError(f"{where}: {key} must be a non-negative integer, got {p[key]!r}")
        name, v = p["name"], p["value"]
        if name not in PARAMETER_NAMES:
            raise SessionError(f"{where}: unknown parameter {name!r} (one of {', '.join(PARAMETER_NAMES)})")
        if name == "inflow_speed" and not (is_number(v) and abs(v) <= MAX_LATTICE_SPEED):
            raise SessionError(f"{where}: inflow_speed must be a number in -1..1, got {v!r}")
        if name == "nu":
            if not is_number(v):
                raise SessionError(f"{where}: nu must be a finite number, got {v!r}")
            try:
                dataclasses.replace(config, nu=float(v)).validate()
            except ConfigError as exc:
                raise SessionError(f"{where}: {exc}") from None
        if name == "force_models" and (not isinstance(v, list) or not all(isinstance(m, str) and m in MODELS for m in v)):
            raise SessionError(f"{where}: force_models must list force models ({', '.join(MODELS)})")
        if name == "body" and v is not None:
            shape_from_dict(v, f"{where}: body", None)
        if name == "rebuild":
            if not isinstance(v, dict) or set(v) != {"config", "keep_flow"} or not isinstance(v["keep_flow"], bool):
                raise SessionError(f"{where}: rebuild must be {{\"config\": {{...}}, \"keep_flow\": true|false}}")
            try:
                config_from_dict(v["config"])
            except SessionError as exc:
                raise SessionError(f"{where}: rebuild {exc}") from None
        if name in ("pause", "resume", "reset") and v is not None:
            raise SessionError(f"{where}: {name} takes no value")
        out.append(dict(p))
    return out


def export_csv(session: Session, path, values=None, rows: int | None = None, torques=None) -> Path:
    """Write the force series as CSV (`force_columns`), atomically; `values` and `torques`
    replace the recorded forces and torques (e.g. a replay's); `rows` keeps only the first rows
    (a diverged replay's)."""
    lines = [",".join(force_columns(session.models))]
    lines += [",".join(row) for row in session.csv_rows(values, torques)][:rows]
    return atomic_write_bytes(path, ("\n".join(lines) + "\n").encode(), "CSV file")


def export_manifest(session: Session, path) -> Path:
    """Write the manifest as JSON, atomically."""
    return atomic_write_bytes(path, (json.dumps(session.manifest, indent=2) + "\n").encode(), "manifest JSON")
