"""Probe (twenty-second session; docs/performance.md): why the numpy tunnel's first bench round
ran slow. The bench's moving tunnel (app/commands/bench_solver.py) on the numpy backend, in
float32 (the bench's) and float64, and on gl: for blocks of 100 steps from the start, the
subnormal float32 populations (non-zero, below 1.18e-38 in magnitude) at the block's end and
the block's wall milliseconds per step; numpy's step does the same operations whatever the
values, so a slower block with the same work is the arithmetic on subnormals.

    python docs/bench/s22/probe_subnormals.py [NX NY]   (from the repository root)
"""
import sys
import time
from dataclasses import replace

sys.path.insert(0, ".")
import numpy as np

from app.commands.bench_solver import SceneRun, scene_config
from app.headless import gl_context
from solver.backend import create_solver

nx, ny = (int(sys.argv[1]), int(sys.argv[2])) if len(sys.argv) > 2 else (512, 256)
BLOCK, BLOCKS = 100, 16
TINY = np.finfo(np.float32).tiny
ctx = gl_context()
runs = {}
for name, backend, dtype in (("numpy float32", "numpy", "float32"), ("numpy float64", "numpy", "float64"),
                             ("gl float32", "gl", "float32")):
    cfg = replace(scene_config("tunnel", nx, ny), dtype=dtype)
    runs[name] = SceneRun("tunnel", create_solver(backend, cfg, **({"ctx": ctx} if backend == "gl" else {})))
print(f"moving tunnel {nx}x{ny}, blocks of {BLOCK} steps from the start; per run: ms per step, "
      f"subnormal float32 populations at the block's end")
rows = {name: [] for name in runs}
for b in range(BLOCKS):
    for name, run in runs.items():  # interleaved, so a slow spell of the machine hits all three
        t = time.perf_counter()
        run.advance(BLOCK)
        ms = (time.perf_counter() - t) / BLOCK * 1e3
        f = run.solver.shifted_distributions().astype(np.float32)
        rows[name].append((ms, int(np.count_nonzero((f != 0) & (np.abs(f) < TINY)))))
print(f"{'steps':>11s}" + "".join(f"  {name:>24s}" for name in runs))
for b in range(BLOCKS):
    print(f"{b * BLOCK:5d}-{(b + 1) * BLOCK:5d}" + "".join(f"  {rows[n][b][0]:8.2f} ms {rows[n][b][1]:9d} sub" for n in runs))
for name, r in runs.items():
    early = np.median([ms for ms, _ in rows[name][1:7]])  # steps 100 - 700: the front crosses
    late = np.median([ms for ms, _ in rows[name][12:]])   # steps 1200 - 1600: past it
    print(f"{name}: steps 100-700 {early:.2f} ms a step, steps 1200-1600 {late:.2f} ms a step: "
          f"{100 * (early / late - 1):+.1f} %")
