"""Throwaway probe (twenty-second session, docs/performance.md; not product code): llvmpipe's
thread count (LP_NUM_THREADS, read once when Mesa loads) in fresh processes: the moving tunnel
512x256, gl and numpy alternating in each process (3 rounds of 2 s, 20 steps of warm-up), the
ratio per process; the settings alternate.

    python docs/bench/s22/probe_threads.py default,3,4 REPEATS   (from the repository root)
"""
import json, os, subprocess, sys
import numpy as np
CHILD = r'''
import json, sys
sys.path.insert(0, ".")
from app.commands.bench_solver import scene_config, SceneRun, measure
from app.headless import gl_context
from solver.backend import create_solver
ctx = gl_context()
runs = {b: SceneRun("tunnel", create_solver(b, scene_config("tunnel", 512, 256), **({"ctx": ctx} if b == "gl" else {}))) for b in ("numpy", "gl")}
for r in runs.values(): r.advance(20)
out = {"numpy": [], "gl": []}
for _ in range(3):
    for b, r in runs.items(): out[b].append(measure(r, 2.0, warmup=0)["mlups"])
print(json.dumps(out))
'''
settings = sys.argv[1].split(",")
reps = int(sys.argv[2])
res = {s: [] for s in settings}
for _ in range(reps):
    for s in settings:
        env = dict(os.environ)
        if s != "default":
            env["LP_NUM_THREADS"] = s
        p = subprocess.run([sys.executable, "-c", CHILD], env=env, capture_output=True, text=True, check=True)
        res[s].append(json.loads(p.stdout.strip().splitlines()[-1]))
for s, outs in res.items():
    gl = [np.median(o["gl"]) for o in outs]
    ratio = [np.median([g / n for g, n in zip(o["gl"], o["numpy"])]) for o in outs]
    print(f"LP_NUM_THREADS {s:8s} gl {np.median(gl):6.1f} MLUPS (runs {' '.join(f'{v:.1f}' for v in gl)})  "
          f"gl/numpy {np.median(ratio):.3f} (runs {' '.join(f'{v:.2f}' for v in ratio)})")
