"""Sessions: record what drove the flow, save it as a versioned zip, replay or export it.

- `format`   the file: `Session`, `load_session`, `save_session`, exports, validation
- `recorder` `SessionRecorder`: collects a session while the flow runs
- `driver`   `SessionSolver`: the solver as the app drives it; recording is a side effect
- `replay`   `SessionPlayer` and `replay`: feed a recording back through the same driver

Determinism comes from one code path: the window, the headless runner and the replay all drive
a `SessionSolver`, so on the same backend and machine a replay reproduces the force series bit
for bit; the recorded series is kept in the file too, so `Session.frames()` plays a file back
without simulating (where the GPU differs). Qt-free.
"""
from feelflow.app.sessions.driver import SessionSolver, record_headless
from feelflow.app.sessions.format import (FORCES, INPUTS, MANIFEST, PARAMETERS, STATE, SUFFIX, Session, SessionError,
                                          export_csv, export_manifest, force_columns, load_session, save_session)
from feelflow.app.sessions.recorder import SessionRecorder
from feelflow.app.sessions.replay import ReplayResult, SessionPlayer, replay

__all__ = ["FORCES", "INPUTS", "MANIFEST", "PARAMETERS", "STATE", "SUFFIX", "ReplayResult", "Session", "SessionError",
           "SessionPlayer", "SessionRecorder", "SessionSolver", "export_csv", "export_manifest", "force_columns",
           "load_session", "record_headless", "replay", "save_session"]
