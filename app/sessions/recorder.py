"""Recording a session: the scene, every input, every parameter change and the force series,
stamped with the session step (docs/reference/session-format.md). `SessionSolver` (driver.py) feeds a
recorder as a side effect of being driven. Qt-free."""
from __future__ import annotations

import json
import math
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from feelflow.app.sessions import bounds
from feelflow.app.sessions.format import (FORMAT, PARAMETER_NAMES, UNITS, VERSION, Session, config_to_dict,
                                          feelflow_version, force_columns, save_session)
from feelflow.solver.config import FlowConfig


_ROW_NAMES = {"inputs": "input samples", "parameters": "parameter changes", "forces": "force rows"}


# --- recording --------------------------------------------------------------------------------

class SessionRecorder:
    """Collects a session: the scene, inputs, parameter changes and the force series.

    Events are stamped with the recorder's clock `step` (session steps so far); `record_forces`
    advances it. The optional `step=` arguments are checks: they must equal the clock (inputs,
    parameters) or the clock + n (forces). Normally `SessionSolver` feeds a recorder; a caller
    that drives its own solver may call the record_* methods in the order it drives it.

    A recording never grows past what the session loader accepts (bounds.py `session_problem`:
    rows of each kind, steps on the scene's grid): the row that would pass it is not recorded,
    nor anything after it; `full` then says why in one line, the record_* methods return False,
    and what was recorded up to there stays a valid session to save.
    """

    def __init__(self, config: FlowConfig, body=None, force_models=(), *, backend: str = "numpy",
                 renderer: str | None = None, scene_toml: str | None = None,
                 scene_source: str | None = None, scene_dict: dict | None = None):
        self.config = config.validate()
        self.body = body
        self.force_models = tuple(force_models)
        self.backend = backend
        self.probes: dict | None = None   # the window's probes (app/model/probes.py to_arrays), saved with it
        #: the window's units choice (app/model/display_units.py choice_to_dict), saved in the manifest
        self.units: dict | None = None
        self.renderer = renderer or ("none (numpy on the CPU)" if backend == "numpy" else "unknown")
        self.scene_toml = scene_toml
        self.scene_source = scene_source
        self.scene_dict = scene_dict
        self.created = datetime.now(timezone.utc).isoformat(timespec="seconds")
        self.step = 0
        #: None while recording; one line once the recording stopped at the session bound
        self.full: str | None = None
        #: the bytes parameters.json will have (format.py writes "[\n", the changes, "\n]\n")
        self.parameters_bytes = 3
        self._seq = 0
        self._inputs: list[tuple] = []   # (seq, step, x, y, angle, vx, vy, omega)
        self._parameters: list[dict] = []
        self._forces: list[tuple] = []   # (seq, step, n, (x, y, vx, vy), {model: (fx, fy)}, {model: torque})
        self._models: list[str] = list(self.force_models)
        #: set by SessionSolver.start_recording: how the running flow was when recording began
        self.start: dict | None = None
        self.state: np.ndarray | None = None  # its populations f (9, ny, nx)
        self.inlet_reference: np.ndarray | None = None  # and the quiet inlet's reference (ny,)

    @classmethod
    def from_scene(cls, scene, *, scene_toml: str | None = None, backend: str | None = None,
                   renderer: str | None = None) -> "SessionRecorder":
        """A recorder for an `feelflow.app.model.scene.Scene`."""
        return cls(scene.config, scene.body, scene.force_models, backend=backend or scene.backend,
                   renderer=renderer, scene_toml=scene_toml, scene_source=scene.source)

    def _room(self, key: str, steps: int = 0, json_bytes: int = 0) -> bool:
        """True if one more `key` row (and `steps` more steps) stays within the session bound;
        else the recording stops here (`full`)."""
        if self.full is not None:
            return False
        counts = {"inputs": len(self._inputs), "parameters": len(self._parameters),
                  "forces": len(self._forces), "steps": self.step + steps}
        counts[key] += 1
        problem = bounds.session_problem(counts, self.config.nx, self.config.ny, self.parameters_bytes + json_bytes)
        if problem is None:
            self.parameters_bytes += json_bytes
            return True
        if bounds.rows_problem(counts) is not None:
            problem = f"a session file holds at most {bounds.MAX_ROWS} {_ROW_NAMES[key]}"
        elif problem.startswith("parameters.json"):
            problem = f"a session file holds at most {bounds.MAX_JSON_BYTES} bytes of parameter changes"
        else:
            problem = "a session file may not hold " + problem.removeprefix("the session: counts.steps: ")
        self.full = f"the recording stopped at step {self.step}: {problem}; what was recorded up to there is kept"
        return False

    def _stamp(self, step) -> tuple[int, int]:
        if step is not None and int(step) != self.step:
            raise ValueError(f"event at step {step}, but the recorder is at step {self.step}")
        seq = self._seq
        self._seq += 1
        return seq, self.step

    def record_input(self, x, y, angle=0.0, vx=0.0, vy=0.0, omega=0.0, *, step=None) -> bool:
        """A body pose (x, y, angle) and commanded motion (vx, vy, omega), lattice units.
        False (nothing recorded) once the recording is `full`."""
        values = tuple(float(v) for v in (x, y, angle, vx, vy, omega))
        if not all(math.isfinite(v) for v in values):
            raise ValueError(f"input sample {values} is not finite")
        if not self._room("inputs"):
            return False
        seq, t = self._stamp(step)
        self._inputs.append((seq, t) + values)
        return True

    def record_parameter(self, name: str, value=None, *, step=None) -> bool:
        """A parameter change (PARAMETER_NAMES; docs/reference/session-format.md says what each value is).
        False (nothing recorded) once the recording is `full`."""
        if name not in PARAMETER_NAMES:
            raise ValueError(f"unknown parameter {name!r}; one of {', '.join(PARAMETER_NAMES)}")
        if name == "body" and value is not None and not isinstance(value, dict):
            value = value.to_dict()
        if name == "force_models":
            value = list(value)
        change = {"seq": self._seq, "step": self.step, "name": name, "value": value}
        # must be plain JSON; its bytes in parameters.json (indent=1: " change" and ",\n")
        size = len(json.dumps([change], indent=1, allow_nan=False)) - 2
        if not self._room("parameters", json_bytes=size):
            return False
        self._stamp(step)   # the seq and step of `change`
        self._parameters.append(change)
        return True

    def record_forces(self, n: int, forces: dict, body=(math.nan,) * 4, *, step=None, torques=None) -> bool:
        """`forces` {model: (fx, fy)} averaged over the last n steps, and `torques` {model: T}
        (a model left out: not computed); body (x, y, vx, vy) then.
        False (nothing recorded, the clock stays) once the recording is `full`."""
        n = int(n)
        if n < 1:
            raise ValueError(f"a force row covers at least one step, got n = {n}")
        if self.full is not None:
            return False
        if step is not None and int(step) != self.step + n:
            raise ValueError(f"force row at step {step}, but the recorder is at {self.step} + {n}")
        if not self._room("forces", n):
            return False
        seq = self._seq
        self._seq += 1
        self.step += n
        for name in forces:
            if name not in self._models:
                self._models.append(name)
        self._forces.append((seq, self.step, n, tuple(float(v) for v in body),
                             {k: (float(v[0]), float(v[1])) for k, v in forces.items()},
                             {k: float(v) for k, v in (torques or {}).items() if k in forces}))
        return True

    def rows(self, start: int = 0) -> list[tuple]:
        """Force rows recorded so far, from the `start`-th: (step, n, body, {model: (fx, fy)},
        {model: torque})."""
        return [(step, n, body, dict(forces), dict(torques)) for _, step, n, body, forces, torques in self._forces[start:]]

    # --- output ---------------------------------------------------------------
    def session(self) -> "Session":
        """The recording so far as a `Session` (what `load_session` would return)."""
        ni, nf = len(self._inputs), len(self._forces)
        inp = np.array(self._inputs, dtype=np.float64).reshape(ni, 8)
        values = np.full((nf, 2 * len(self._models)), np.nan)
        torque_values = np.full((nf, len(self._models)), np.nan)
        for r, (_, _, _, _, forces, torques) in enumerate(self._forces):
            for name, (fx, fy) in forces.items():
                k = self._models.index(name)
                values[r, 2 * k:2 * k + 2] = fx, fy
            for name, torque in torques.items():
                torque_values[r, self._models.index(name)] = torque
        return Session(
            manifest=self._manifest(),
            config=self.config, body=self.body, backend=self.backend,
            force_models=self.force_models,
            inputs={"seq": np.array([r[0] for r in self._inputs], dtype=np.int64),
                    "step": np.array([r[1] for r in self._inputs], dtype=np.int64),
                    "pose": np.ascontiguousarray(inp[:, 2:5]), "velocity": np.ascontiguousarray(inp[:, 5:8])},
            parameters=[dict(p) for p in self._parameters],
            forces={"seq": np.array([r[0] for r in self._forces], dtype=np.int64),
                    "step": np.array([r[1] for r in self._forces], dtype=np.int64),
                    "n": np.array([r[2] for r in self._forces], dtype=np.int64),
                    "body": np.array([r[3] for r in self._forces], dtype=np.float64).reshape(nf, 4),
                    "values": values, "torques": torque_values},
            models=tuple(self._models), start=self.start, state=self.state, inlet_reference=self.inlet_reference,
            probes=self.probes, units=self.units,
        )

    def _manifest(self) -> dict:
        scene = {"source": self.scene_source, "toml": self.scene_toml,
                 "config": config_to_dict(self.config),
                 "body": self.body.to_dict() if self.body is not None else None,
                 "force_models": list(self.force_models)}
        if self.scene_dict is not None:
            scene["dict"] = json.loads(json.dumps(self.scene_dict, default=str))
        manifest = {
            "format": FORMAT, "version": VERSION, "feelflow_version": feelflow_version(),
            "created": self.created, "backend": self.backend, "renderer": self.renderer,
            "scene": scene, "start": self.start,
            "forces": {"models": list(self._models), "columns": force_columns(self._models)},
            "counts": {"inputs": len(self._inputs), "parameters": len(self._parameters),
                       "forces": len(self._forces), "steps": self.step},
        }
        if self.units is not None:   # optional: older readers ignore it (format.py UNITS)
            manifest[UNITS] = dict(self.units)
        return manifest

    def save(self, path) -> Path:
        """Write the session file atomically; SessionError (one line) if it cannot."""
        return save_session(self.session(), path)
