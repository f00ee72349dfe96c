"""Throwaway probe (twenty-second session, docs/performance.md; not product code): upper bounds
on two levers for the moving tunnel at 512x256 (gl), against numpy in alternating rounds in one
process: the four edge strips drawn by the interior's variant (wrong physics, the cost of edges
that shaded like the interior), and per step only the G textures bound and the framebuffer set
(what trimming the per-step GL state calls could save).

    python docs/bench/s22/probe_bounds.py [ROUNDS]   (from the repository root)
"""
import sys, time
sys.path.insert(0, ".")
import numpy as np
from app.commands.bench_solver import scene_config, SceneRun, measure
from app.headless import gl_context
from solver.backend import create_solver
from solver.gl_backend import GLSolver, UNIT_G

ctx = gl_context()
orig_regions = GLSolver._regions
orig_bind = GLSolver._bind_sources
orig_begin = GLSolver._begin_pass

def regions_edges_cheap(self, window):
    parts = orig_regions(self, window)
    out = {}
    for k, v in parts.items():
        nk = (k[0], 0, k[2]) if k[0] == 0 else k
        out.setdefault(nk, []).extend(v)
    return out

def bind_g_only(self, side):
    for unit, texture in zip(UNIT_G, self._g[side]):
        texture.use(location=unit)

def begin_min(self, fbo, size):
    fbo.use()

variants = {
    "default": {},
    "edges as interior": {"_regions": regions_edges_cheap},
    "minimal per-step state": {"_bind_sources": bind_g_only, "_begin_pass": begin_min},
}
runs = {}
def make(name):
    s = create_solver("gl", scene_config("tunnel", 512, 256), ctx=ctx)
    return SceneRun("tunnel", s)
res = {n: [] for n in list(variants) + ["numpy"]}
numpy_run = SceneRun("tunnel", create_solver("numpy", scene_config("tunnel", 512, 256)))
numpy_run.advance(20)
for name, patch in variants.items():
    for k, f in patch.items(): setattr(GLSolver, k, f)
    runs[name] = make(name); runs[name].solver._draw_regions = None; runs[name].advance(20)
    GLSolver._regions, GLSolver._bind_sources, GLSolver._begin_pass = orig_regions, orig_bind, orig_begin
for r in range(int(sys.argv[1]) if len(sys.argv) > 1 else 5):
    res["numpy"].append(measure(numpy_run, 2.0, warmup=0)["mlups"])
    for name, patch in variants.items():
        for k, f in patch.items(): setattr(GLSolver, k, f)
        res[name].append(measure(runs[name], 2.0, warmup=0)["mlups"])
        GLSolver._regions, GLSolver._bind_sources, GLSolver._begin_pass = orig_regions, orig_bind, orig_begin
for n, v in res.items():
    ratio = np.median([a / b for a, b in zip(v, res["numpy"])])
    print(f"{n:28s} {np.median(v):6.1f} MLUPS  x numpy {ratio:.3f}  rounds {' '.join(f'{x:.1f}' for x in v)}")
