"""Throwaway probe (twenty-first session, README 'Speed, measured'; not product code): what a
draw call costs on llvmpipe. The 512x256 periodic box (the bench's box scene, gl) with its one
fast-path draw per step split into N scissored draws of horizontal bands (the same program,
the same texels), N = 1, 6, 12, 24, in alternating rounds; prints wall MLUPS per N (median).

    python docs/bench/s21/probe_draw_count.py
"""
import sys, time
sys.path.insert(0, ".")
import numpy as np
import moderngl
from app.commands.bench_solver import scene_config
from solver.gl_backend import GLSolver

ctx = moderngl.create_context(standalone=True, backend="egl")
solver = GLSolver(scene_config("box", 512, 256), ctx)
solver.step(200)
_regions = GLSolver._regions


def bands(n):
    def regions(self, window):
        parts = _regions(self, window)
        (key, [(x0, y0, x1, y1)]), = parts.items()
        edges = np.linspace(y0, y1, n + 1).astype(int)
        return {key: [(x0, int(a), x1, int(b)) for a, b in zip(edges[:-1], edges[1:])]}
    return regions


results = {n: [] for n in (1, 6, 12, 24)}
for _ in range(5):
    for n in results:
        GLSolver._regions = bands(n)
        solver._draw_regions = None
        solver._set_rects(None)
        solver.step(50)
        solver.finish()
        t = time.perf_counter()
        solver.step(1000)
        solver.finish()
        results[n].append(512 * 256 * 1000 / (time.perf_counter() - t) / 1e6)
print(ctx.info["GL_RENDERER"])
for n, v in results.items():
    print(f"{n:3d} draws a step: {np.median(v):6.1f} MLUPS (rounds {', '.join(f'{x:.1f}' for x in v)})")
