"""Write the small session files of tests/data/sessions with a FeelFlow checkout's own recorder
(tests/test_session_versions.py opens them). For an older commit C:

    git worktree add /tmp/old C && mkdir -p /tmp/pkg && ln -s /tmp/old /tmp/pkg/feelflow
    cd /tmp && PYTHONPATH=/tmp/pkg:/tmp/old python make_session.py OUT/v1-C

writes OUT/v1-C-start.ffsession (recorded from the first step: a moving body, a wind change, a
viscosity change) and, where that commit's recorder can start on a running flow,
OUT/v1-C-midflow.ffsession (with the flow's state and a rebuild). numpy backend, 32 x 16."""
import sys
import numpy as np

out = sys.argv[1]
try:
    from feelflow.app.sessions import SessionRecorder, SessionSolver
    from feelflow.solver.backend import create_solver
    from feelflow.solver.config import FlowConfig
    from feelflow.shapes import Cylinder
except ImportError:
    from app.session import SessionRecorder, SessionSolver
    from solver.backend import create_solver
    from solver.config import FlowConfig
    from shapes import Cylinder
import dataclasses
names = {f.name for f in dataclasses.fields(FlowConfig)}
kw = dict(nx=32, ny=16, nu=0.05, inflow_speed=0.03, inflow_ramp_steps=0, initial_velocity=(0.03, 0.0),
          dtype="float64", sponge_cells=4)
if "inlet_nonreflecting" in names:
    kw["inlet_nonreflecting"] = 1e-3
cfg = FlowConfig(**kw).validate()
models = ["momentum_exchange"]

# 1. recorded from the start: a moving body, a wind change, a viscosity change
rec = SessionRecorder(cfg, None, models, backend="numpy")
ss = SessionSolver(create_solver("numpy", cfg), rec)
ss.enable_force_models(models)
ss.set_body(Cylinder(4.0, 10.0, 8.0))
ss.step(8)
ss.set_inflow_speed(0.035)
ss.step(8)
ss.set_body(Cylinder(4.0, 10.5, 8.0), velocity=(0.02, 0.0))
ss.step(8)
ss.set_viscosity(0.06)
ss.step(8)
rec.save(out + "-start.ffsession")
print("wrote", out + "-start.ffsession")

# 2. recorded mid-flow (where the recorder can start on a running flow), with a rebuild
if hasattr(SessionSolver, "start_recording"):
    ss = SessionSolver(create_solver("numpy", cfg))
    ss.enable_force_models(models)
    ss.set_body(Cylinder(4.0, 10.0, 8.0))
    ss.step(12)
    rec = ss.start_recording()
    ss.step(6)
    if hasattr(ss, "rebuild"):
        ss.rebuild(dataclasses.replace(cfg, nu=0.055))
        ss.enable_force_models(models)
        ss.set_body(Cylinder(4.0, 10.0, 8.0))
    ss.step(6)
    ss.stop_recording().save(out + "-midflow.ffsession")
    print("wrote", out + "-midflow.ffsession")
