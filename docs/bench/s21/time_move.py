"""Main-thread CPU of one move of the bench's moving tunnel (512x256, gl): set_body and its parts.

    python docs/bench/s21/time_move.py   (from the repository root; EGL standalone context)

Wraps the functions a move calls with timers and moves the cylinder 300 times along the bench's
path with no steps between moves (llvmpipe idle), so the figures are the CPU cost of a move
alone. Nested functions are counted in their callers too (rasterise in make_body_state, refill in
move_body, ...). README 'Speed, measured', twenty-first session.
"""
import sys
sys.path.insert(0, ".")
import time, numpy as np, moderngl
from app.commands.bench_solver import scene_config, SceneRun
from solver.gl_backend import GLSolver
import solver.gl_backend as gb, solver.body as body, shapes.raster as raster
ctx = moderngl.create_context(standalone=True, backend="egl")
s = GLSolver(scene_config("tunnel", 512, 256), ctx)
run = SceneRun("tunnel", s)
run.advance(200)
acc = {}


def wrap(owner, name):
    """Time every call of owner.name into acc[name]."""
    f = getattr(owner, name)

    def timed(*a, **k):
        t = time.perf_counter()
        try:
            return f(*a, **k)
        finally:
            acc[name] = acc.get(name, 0.0) + time.perf_counter() - t
    setattr(owner, name, timed)


for owner, names in ((body, ("make_body_state", "refill")), (raster, ("rasterise",)),
                     (gb, ("move_body", "node_mask")),
                     (GLSolver, ("set_body", "_upload_raster", "_read_texels", "_write_texels", "_set_rects",
                                 "_upload_body_uniforms"))):
    for name in names:
        wrap(owner, name)
n = 300  # moves, no steps between them: the CPU cost of a move alone
for k in range(n):
    run.k += 10
    run._move()
for k, v in sorted(acc.items(), key=lambda kv: -kv[1]):
    print(f"{k:24s} {v / n * 1e3:7.3f} ms per move")
