"""`feelflow bench [solver] [--json PATH] [--quick] [--variants]`: solver speed, every backend.

In one process, the same scenes on the numpy, the compiled cpu (numba) and the gl backend (EGL
standalone context):
an empty periodic box and a tunnel with a moving cylinder (moved every 10 steps as the window
does per frame, the reference force computed every step), at 256x128, 512x256 and 1024x512.
For each: MLUPS (million lattice-node updates per second), steps per second and, for gl, the
renderer; also MLUPS per CPU-second of this process (all its threads, llvmpipe's and numba's
included), which a busy machine disturbs less than the wall clock. Each scene runs in `--rounds`
alternating rounds (numpy, cpu, gl, numpy, cpu, gl, ...): rows give the medians, speedups (each
backend's, and the fastest backend's, against numpy) the median of the per-round ratios; every run is measured only after its warm-up (`warmup_steps`: for a tunnel,
its start-up transient). It also measures this machine's memory-copy bandwidth (numpy copy, bytes read +
written per second) and reports each MLUPS as a fraction of the D2Q9 bound, 72 bytes per node
and step (9 float32 read + 9 written). GPU work is timed up to `glFinish`.

`--variants` instead compares the gl backend's tuning choices on the moving-cylinder tunnel,
interleaved in the same run with the periodic box and the numpy tunnel (so that the ratios, and
the box's ceiling on any gl tunnel, are taken within each round), and llvmpipe's thread count
and SIMD width in subprocesses
(docs/performance.md). Figures from a shared machine are indicative.
"""
from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
import time

import numpy as np

from feelflow.app.errors import UserError
from feelflow.app.headless import gl_context
from feelflow.app.machine import cpu_name

GRIDS = ((256, 128), (512, 256), (1024, 512))
SCENES = ("box", "tunnel")
#: the backends `feelflow bench` compares, numpy (the reference) first
BENCH_BACKENDS = ("numpy", "cpu", "gl")
BYTES_PER_NODE_STEP = 72
MOVE_EVERY = 10


def machine() -> dict:
    return {"cpu": cpu_name(), "cores": os.cpu_count(), "system": f"{platform.system()} {platform.release()}",
            "python": platform.python_version(), "numpy": np.__version__,
            "LP_NUM_THREADS": os.environ.get("LP_NUM_THREADS", "(default)")}


def copy_bandwidth(megabytes: int, repeats: int = 5) -> float:
    """Bytes read + written per second by numpy.copyto on a large float32 array, best of runs."""
    n = megabytes * 2**20 // 4
    src = np.ones(n, dtype=np.float32)
    dst = np.empty_like(src)
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        np.copyto(dst, src)
        best = min(best, time.perf_counter() - t0)
    return 2 * src.nbytes / best


def scene_config(scene: str, nx: int, ny: int):
    from feelflow.solver.config import FlowConfig

    if scene == "box":
        return FlowConfig(nx=nx, ny=ny, nu=0.02, collision="trt", dtype="float32", x_boundary="periodic",
                          y_boundary="periodic", initial_velocity=(0.03, 0.01))
    return FlowConfig(nx=nx, ny=ny, nu=0.02, collision="trt", dtype="float32", x_boundary="tunnel",
                      y_boundary="no_slip", inflow_speed=0.05, inflow_ramp_steps=200, sponge_cells=nx // 16)


def warmup_steps(scene: str, config, quick: bool) -> int:
    """Steps each run takes before it is measured: 20 (shader compile, first draw, caches), and
    for a tunnel, unless `quick`, also its start-up transient: the inflow ramp, then 2 nx steps,
    more than the sqrt(3) nx the inlet's sound front needs to cross the channel (c_s = 1/sqrt(3)).
    Until the front has passed, the still fluid ahead of it holds populations so small that
    float32 stores them subnormal; x86 computes with those many times slower, so numpy's first
    round ran about 10 % slow (llvmpipe flushes them to zero) and the first round's ratio came
    out high (docs/bench/s22/subnormals.txt, subnormals-1024.txt: none were left after 600 steps
    at 512x256, 1 200 at 1024x512)."""
    if scene != "tunnel" or quick:
        return 20
    return 20 + config.inflow_ramp_steps + 2 * config.nx


class SceneRun:
    """One scene on one solver: `advance(n)` runs n steps the way the window drives them.

    For the tunnel's cost breakdown (`--variants`), `moves=False` keeps the cylinder where it
    was placed, and `call_steps` sets how many steps each `step()` call runs (None: all n at
    once) instead of MOVE_EVERY."""

    def __init__(self, scene, solver, moves: bool = True, call_steps: int | None = MOVE_EVERY,
                 after_call=None):
        from feelflow.shapes import Cylinder

        self.scene, self.solver = scene, solver
        self.moves, self.call_steps, self.after_call = moves, call_steps, after_call
        cfg = solver.config
        self.k = 0
        if scene == "tunnel":
            self.d = cfg.ny / 8
            self.x, self.y0 = cfg.nx / 4, cfg.ny / 2
            self.cylinder = Cylinder
            solver.enable_force_models(["momentum_exchange"])
            self._move()

    def _move(self):
        cfg = self.solver.config
        amp, period = cfg.ny / 8, 2000
        phase = 2 * np.pi * self.k / period
        y = self.y0 + amp * np.sin(phase)
        vy = amp * 2 * np.pi / period * np.cos(phase)
        self.solver.set_body(self.cylinder(self.d, x=self.x, y=y), velocity=(0.0, vy))

    def advance(self, n: int):
        done = 0
        while done < n:
            chunk = n - done if self.call_steps is None else min(self.call_steps, n - done)
            self.solver.step(chunk)
            if self.after_call is not None:
                self.after_call()
            self.k += chunk
            done += chunk
            if self.scene == "tunnel" and self.moves:
                self._move()
        finish = getattr(self.solver, "finish", None)
        if finish is not None:
            finish()


def measure(run: SceneRun, seconds: float, warmup: int = 20) -> dict:
    """Steps until `seconds` of wall time; MLUPS per wall second and per CPU second (all
    threads of this process: llvmpipe's too), the latter steadier on a shared machine."""
    run.advance(warmup)  # shader compile, first draw, caches
    cfg = run.solver.config
    steps, elapsed, cpu, chunk = 0, 0.0, 0.0, MOVE_EVERY
    while elapsed < seconds:
        t0, c0 = time.perf_counter(), time.process_time()
        run.advance(chunk)
        elapsed += time.perf_counter() - t0
        cpu += time.process_time() - c0
        steps += chunk
        chunk = min(chunk * 2, 400)
    nodes = cfg.nx * cfg.ny * steps / 1e6
    return {"steps": steps, "seconds": round(elapsed, 4), "mlups": round(nodes / elapsed, 2),
            "steps_per_s": round(steps / elapsed, 1), "mlups_per_cpu_s": round(nodes / max(cpu, 1e-9), 2)}


def _gl_context():
    """(the process's EGL context, None), or (None, why) where there is none: the numpy figures stay."""
    try:
        return gl_context(), None
    except UserError as exc:
        return None, str(exc)


def bench_rounds(quick: bool, rounds: int | None) -> int:
    """`--rounds` as given (default 3, --quick 1); UserError unless it is at least 1."""
    rounds = rounds if rounds is not None else (1 if quick else 3)
    if rounds < 1:
        raise UserError(f"--rounds: must be at least 1, got {rounds}")
    return rounds


def bench_grids(texts) -> tuple:
    """`--grid NXxNY` options as (nx, ny) pairs (default GRIDS); UserError for a malformed one."""
    if not texts:
        return GRIDS
    grids = []
    for text in texts:
        parts = str(text).lower().split("x")
        if len(parts) != 2 or not all(p.isdigit() and int(p) >= 8 for p in parts):
            raise UserError(f"--grid: must be NXxNY with both at least 8, e.g. 512x256, got {text!r}")
        grids.append((int(parts[0]), int(parts[1])))
    return tuple(grids)


def run_bench(quick: bool, seconds: float | None, rounds: int | None = None, grids=GRIDS):
    """Every scene and grid on every backend, in `rounds` alternating rounds (numpy, cpu, gl,
    numpy, ...; default 3, --quick 1), each `seconds` long: a row holds the medians of its rounds
    and each round's MLUPS, and a speedup is the median of the per-round ratios to numpy, so
    that a slow spell of this shared machine slows the backends of a round alike. `fastest`
    names, per scene and grid, the backend with the highest median MLUPS and its ratio."""
    from feelflow.solver.backend import create_solver

    seconds = seconds if seconds is not None else (0.3 if quick else 2.0)
    rounds = bench_rounds(quick, rounds)
    bandwidth = copy_bandwidth(64 if quick else 512)
    bound = bandwidth / BYTES_PER_NODE_STEP / 1e6
    ctx, gl_error = _gl_context()
    renderer = ctx.info.get("GL_RENDERER") if ctx else None
    rows = []
    ratios = {b: {} for b in BENCH_BACKENDS if b != "numpy"}
    fastest = {}
    for scene in SCENES:
        for nx, ny in grids:
            runs, samples, here = {}, {}, []
            for backend in BENCH_BACKENDS:
                row = {"scene": scene, "backend": backend, "grid": f"{nx}x{ny}", "nx": nx, "ny": ny}
                here.append(row)
                if backend == "gl" and ctx is None:
                    row["error"] = gl_error
                    continue
                solver = create_solver(backend, scene_config(scene, nx, ny), **({"ctx": ctx} if backend == "gl" else {}))
                runs[backend] = SceneRun(scene, solver)
                runs[backend].advance(warmup_steps(scene, solver.config, quick))
                samples[backend] = []
            for _ in range(rounds):
                for backend, run in runs.items():
                    samples[backend].append(measure(run, seconds, warmup=0))
            for row in here:
                if "error" in row:
                    rows.append(row)
                    continue
                backend = row["backend"]
                runs[backend].solver.close()
                row.update(_median_of_rounds(samples[backend]))
                row["fraction_of_bound"] = round(row["mlups"] / bound, 4)
                if backend == "gl":
                    row["renderer"] = renderer
                rows.append(row)
                print(_format_row(row), flush=True)
            key = f"{scene} {nx}x{ny}"
            for backend in samples:
                if backend != "numpy":
                    ratios[backend][key] = [round(b["mlups"] / n["mlups"], 3)
                                            for n, b in zip(samples["numpy"], samples[backend])]
            best = max((r for r in here if "error" not in r), key=lambda r: r["mlups"])
            per_round = ([1.0] * rounds if best["backend"] == "numpy" else ratios[best["backend"]][key])
            fastest[key] = {"backend": best["backend"], "ratio_to_numpy": round(float(np.median(per_round)), 2)}
    by_backend = {b: {k: round(float(np.median(v)), 2) for k, v in r.items()} for b, r in ratios.items()}
    return {"machine": machine(), "renderer": renderer, "copy_bandwidth_gb_s": round(bandwidth / 1e9, 2),
            "d2q9_bound_mlups": round(bound, 1), "bytes_per_node_step": BYTES_PER_NODE_STEP,
            "loadavg": load_average(), "seconds_per_case": seconds, "rounds": rounds, "results": rows,
            "speedups": by_backend["gl"], "speedups_per_round": ratios["gl"],
            "speedups_by_backend": by_backend, "speedups_by_backend_per_round": ratios, "fastest": fastest}


def load_average():
    """The 1, 5 and 15 minute load averages (os.getloadavg), or None where there are none: on a
    shared machine they say how much the other work disturbed the run."""
    try:
        return [round(v, 2) for v in os.getloadavg()]
    except OSError:
        return None


def _median_of_rounds(samples: list[dict]) -> dict:
    """A row's figures from its rounds (`measure` results): medians, totals, each round's MLUPS."""
    medians = {key: round(float(np.median([m[key] for m in samples])), 2)
               for key in ("mlups", "steps_per_s", "mlups_per_cpu_s")}
    return {"steps": sum(m["steps"] for m in samples), "seconds": round(sum(m["seconds"] for m in samples), 4),
            **medians, "rounds_mlups": [m["mlups"] for m in samples]}


def _format_row(r) -> str:
    if "error" in r:
        return f"{r['scene']:7s} {r['grid']:>9s} {r['backend']:6s} unavailable: {r['error']}"
    rounds = r.get("rounds_mlups", [])
    each = f"  rounds: {' '.join(f'{v:.1f}' for v in rounds)}" if len(rounds) > 1 else ""
    return (f"{r['scene']:7s} {r['grid']:>9s} {r['backend']:6s} {r['mlups']:8.1f} MLUPS "
            f"{r['steps_per_s']:9.1f} steps/s  {100 * r['fraction_of_bound']:5.1f} % of bound  "
            f"({r['mlups_per_cpu_s']:.1f} MLUPS per CPU-second){each}")


# --- tuning variants (docs/performance.md) ---------------------------------------------------
#: the runs of `--variants` that `against_numpy` divides
DEFAULT_TUNNEL = "default: the step's own pass sums the links as it streams (G4 zw)"
LINK_SUM_PASS_TUNNEL = "a link-sum pass per step sums them into a band area (forces=pass)"
WINDOW_COPY_TUNNEL = "the step's own pass copies the window to a band area (forces=window)"
BOX = "empty periodic box (default)"
#: the tunnel with parts taken away, each run in one step(n) call a round (no call ends):
#: against numpy they say what the tunnel would reach if those parts cost nothing
FIXED_ONE_CALL = "default, cylinder not moved, one step(n) call a round"
FIXED_NO_FORCE_ONE_CALL = "default, cylinder not moved, no force model, one step(n) call a round"
NO_BODY_ONE_CALL = "tunnel without a body (edges and sponge only), one step(n) call a round"
FIXED_STEP_CALLS = "default, cylinder not moved, step(10) calls"
STAIRCASE = (("free moves (not moved, step(10) calls) / numpy", FIXED_STEP_CALLS),
             ("free moves and call ends (not moved, one call) / numpy", FIXED_ONE_CALL),
             ("... and no force model / numpy", FIXED_NO_FORCE_ONE_CALL),
             ("... and no body (edges, sponge) / numpy", NO_BODY_ONE_CALL))
NUMPY_TUNNEL = "numpy backend, the same moving tunnel (the reference)"
#: the premise of a design whose moves and read-backs never drain llvmpipe's queue: CPU work done
#: while llvmpipe still has steps queued is free. Two runs of the default tunnel add the same
#: Python busy work to every step(10) call: once after the call's read (llvmpipe idle), once
#: before it (GLSolver.before_read: llvmpipe busy with the call's last queued steps).
CPU_WORK_MS = 3.0
WORK_AFTER_READ = f"default + {CPU_WORK_MS:g} ms of Python per step(10) call, after its read"
WORK_BEFORE_READ = f"default + {CPU_WORK_MS:g} ms of Python per step(10) call, before its read (GPU busy)"
VARIANTS = {
    "one program for every node (no regions)": {"split": False},
    "regions, read back every step": {"check_every": 1, "window": "read"},
    "default, force window read right after each step": {"window": "read"},
    "blocks of 32, a pass per step copies the window to an atlas": {"window": "atlas"},
    WINDOW_COPY_TUNNEL: {"forces": "window"},
    LINK_SUM_PASS_TUNNEL: {"forces": "pass"},
    DEFAULT_TUNNEL: {},
    "default, regions as two triangles each, not scissored": {"draw": "triangles"},
    "default, divergence by discard + occlusion query": {"divergence": "discard"},
}
#: step variants (body, edges, sponge) whose cost per node the variants run measures
REGION_VARIANTS = {"interior (fast path)": (0, 0, 0), "interior + sponge rates": (0, 0, 1),
                   "edges: walls, inlet, outlet": (0, 1, 1), "body window": (1, 0, 1),
                   "everything (body + edges)": (1, 1, 1)}


def against_numpy(wall: dict) -> dict:
    """Per round, the gl default tunnel and the gl box against the numpy tunnel measured in the
    same round, seconds apart (`--variants` interleaves its runs, so a slow spell of a shared
    machine hits them alike): best and median over the rounds.

    The box is the ceiling: it runs the tunnel interior's collide-and-stream pass on every node
    with no walls, inlet, outlet, sponge, body, moves, force model or read-back, so no tunnel
    built on that pass does less work per node. Where box / numpy stays below a target (issue 4:
    2x), no change to the tunnel's boundaries, moves or read-backs reaches it on this machine
    today; only a faster pass or renderer could.

    Between the two, where those runs are there (STAIRCASE), the tunnel with parts taken away:
    the cylinder not moved, in the same step(10) calls (what a body path whose moves cost
    nothing could reach), then with all steps in one call (what a design with moves and
    read-backs that never drain llvmpipe's queue could reach at best), then also without a force model,
    then without the body: each ratio bounds what the tunnel reaches if what is taken away
    cost nothing, so the steps between them price each part against the target."""
    ref = wall[NUMPY_TUNNEL]
    out = {}
    pairs = (("gl tunnel / numpy tunnel", DEFAULT_TUNNEL),) + STAIRCASE + (("ceiling: gl box / numpy tunnel", BOX),)
    for label, name in pairs:
        if name not in wall:
            continue
        ratios = [round(g / n, 3) for g, n in zip(wall[name], ref)]
        out[label] = _stats(ratios)
    return out


def cpu_work_cost(wall: dict, nodes: int) -> dict:
    """Per round, the wall milliseconds per step(MOVE_EVERY) call that CPU_WORK_MS of CPU work
    added to the default tunnel, placed after the call's read and before it (from MLUPS
    measured in the same round). Overlap gains where 'before' costs less than 'after'."""
    def per_call_ms(mlups):
        return nodes * MOVE_EVERY / (mlups * 1e6) * 1e3

    out = {}
    for label, name in (("after the read", WORK_AFTER_READ), ("before the read (GPU busy)", WORK_BEFORE_READ)):
        if name in wall and DEFAULT_TUNNEL in wall:
            added = [round(per_call_ms(w) - per_call_ms(d), 3) for w, d in zip(wall[name], wall[DEFAULT_TUNNEL])]
            out[label] = {"best": min(added), "median": float(np.median(added)), "samples": added}
    return out


def busy_python(ms: float) -> None:
    """Keep this thread busy for `ms` of its own CPU time (the CPU work of cpu_work_cost)."""
    end = time.thread_time() + ms / 1e3
    while time.thread_time() < end:
        pass


def _stats(values):
    return {"best": max(values), "median": float(np.median(values)), "samples": values}


def run_variants(quick: bool, seconds: float | None):
    """Interleaved rounds of every tuning variant on the moving-cylinder tunnel (MLUPS per wall
    and per CPU second), with the gl box and the numpy tunnel in the same rounds (`against_numpy`:
    the ratios and the ceiling), the cost per node of each step variant, and llvmpipe's thread
    count and vector width (subprocesses)."""
    from feelflow.shapes import Cylinder
    from feelflow.solver.backend import create_solver
    from feelflow.solver.gl_backend import GLSolver

    seconds = seconds if seconds is not None else (0.3 if quick else 1.0)
    rounds = 2 if quick else 5
    nx, ny = 512, 256
    ctx, err = _gl_context()
    if ctx is None:
        raise SystemExit(f"feelflow: {err}")
    runs = {}
    for name, tuning in VARIANTS.items():
        runs[name] = SceneRun("tunnel", GLSolver(scene_config("tunnel", nx, ny), ctx=ctx, tuning=tuning))
    no_force = SceneRun("tunnel", GLSolver(scene_config("tunnel", nx, ny), ctx=ctx))
    no_force.solver.enable_force_models([])
    runs["default, no force model (no window readback)"] = no_force
    runs[FIXED_STEP_CALLS] = SceneRun(
        "tunnel", GLSolver(scene_config("tunnel", nx, ny), ctx=ctx), moves=False)
    for name, forces, body in ((FIXED_ONE_CALL, True, True), (FIXED_NO_FORCE_ONE_CALL, False, True),
                               (NO_BODY_ONE_CALL, False, False)):
        run = SceneRun("tunnel", GLSolver(scene_config("tunnel", nx, ny), ctx=ctx), moves=False, call_steps=None)
        if not forces:
            run.solver.enable_force_models([])
        if not body:
            run.solver.set_body(None)
        runs[name] = run
    runs[WORK_AFTER_READ] = SceneRun("tunnel", GLSolver(scene_config("tunnel", nx, ny), ctx=ctx),
                                     after_call=lambda: busy_python(CPU_WORK_MS))
    runs[WORK_BEFORE_READ] = SceneRun("tunnel", GLSolver(scene_config("tunnel", nx, ny), ctx=ctx))
    runs[WORK_BEFORE_READ].solver.before_read = lambda: busy_python(CPU_WORK_MS)
    runs[BOX] = SceneRun("box", GLSolver(scene_config("box", nx, ny), ctx=ctx))
    runs[NUMPY_TUNNEL] = SceneRun("tunnel", create_solver("numpy", scene_config("tunnel", nx, ny)))
    wall = {name: [] for name in runs}
    per_cpu = {name: [] for name in runs}
    for run in runs.values():
        run.advance(warmup_steps(run.scene, run.solver.config, quick))
    for _ in range(rounds):
        for name, run in runs.items():
            m = measure(run, seconds, warmup=0)
            wall[name].append(m["mlups"])
            per_cpu[name].append(m["mlups_per_cpu_s"])
    probe = GLSolver(scene_config("tunnel", nx, ny), ctx=ctx)
    probe.set_body(Cylinder(ny / 8, x=nx / 4, y=ny / 2))
    draws = 20 if quick else 60
    cost = {name: [] for name in REGION_VARIANTS}
    for key in REGION_VARIANTS.values():
        probe.time_variant(key, 3)  # compile
    for _ in range(rounds):
        for name, key in REGION_VARIANTS.items():
            c0 = time.process_time()
            probe.time_variant(key, draws)
            cost[name].append(round(nx * ny * draws / (time.process_time() - c0) / 1e6, 2))
    result = {"grid": f"{nx}x{ny}", "renderer": ctx.info.get("GL_RENDERER"), "machine": machine(),
              "variants": {n: {"wall": _stats(wall[n]), "per_cpu_s": _stats(per_cpu[n])} for n in runs},
              "against_numpy": against_numpy(wall),
              "cpu_work_ms_per_call": {"work_ms": CPU_WORK_MS, **cpu_work_cost(wall, nx * ny)},
              "step_variants_full_grid_mlups_per_cpu_s": {n: _stats(v) for n, v in cost.items()}}
    result["llvmpipe_knobs"] = {
        f"{var}={value}": _subprocess_tunnel(nx, ny, seconds * rounds, {var: value})
        for var, values in LLVMPIPE_KNOBS.items() for value in values}
    return result


#: llvmpipe environment variables measured by `--variants` in subprocesses (llvmpipe reads them
#: once, when it loads): rasteriser threads, and the SIMD width of its generated code
#: ("256 bits" in the renderer string; AVX-512 machines accept 512)
LLVMPIPE_KNOBS = {"LP_NUM_THREADS": ("1", "2", "4"), "LP_NATIVE_VECTOR_WIDTH": ("128", "256", "512")}


PROFILE_PARTS = {  # (label, function name, file suffix or None for a built-in method)
    "draw calls (queue the step; wait while llvmpipe's queue is full)": ("<method 'render' of 'mgl.VertexArray' objects>", None),
    "end of each step() call: read back, force models, divergence check": ("_resolve_checks", "gl_backend.py"),
    "moves: set_body (raster, refill with its read and write, uploads)": ("set_body", "gl_backend.py"),
}


def thread_cpu_seconds() -> dict | None:
    """CPU seconds used so far by this process's threads, split into llvmpipe's rasteriser
    threads (named "llvmpipe-N") and the rest (the main thread: Python, and Mesa's draw calls,
    which bin each step's triangles), from /proc/self/task: each thread's schedstat (nanoseconds
    on a CPU), or where the kernel has none its stat (utime + stime, in clock ticks of 10 ms,
    too coarse for a short run); None where there is no /proc."""
    try:
        tick = os.sysconf("SC_CLK_TCK")
        out = {"llvmpipe": 0.0, "other": 0.0}
        for tid in os.listdir("/proc/self/task"):
            try:
                with open(f"/proc/self/task/{tid}/schedstat") as f:
                    seconds = int(f.read().split()[0]) / 1e9
            except (OSError, ValueError, IndexError):
                with open(f"/proc/self/task/{tid}/stat") as f:
                    fields = f.read().rsplit(")", 1)[1].split()  # after "pid (comm)"
                seconds = (int(fields[11]) + int(fields[12])) / tick
            with open(f"/proc/self/task/{tid}/comm") as f:
                name = f.read().strip()
            out["llvmpipe" if name.startswith("llvmpipe") else "other"] += seconds
        return out
    except (OSError, ValueError, IndexError):
        return None


def thread_split(run: SceneRun, steps: int) -> dict | None:
    """`steps` of `run` without the profiler: CPU milliseconds per step of llvmpipe's threads
    and of the rest, and the share of the cores' time (os.cpu_count() x wall) nobody used."""
    c0, t0 = thread_cpu_seconds(), time.perf_counter()
    run.advance(steps)
    wall, c1 = time.perf_counter() - t0, thread_cpu_seconds()
    if c0 is None or c1 is None:
        return None
    used = {k: c1[k] - c0[k] for k in c0}
    cores = os.cpu_count() or 1
    return {"steps": steps, "wall_ms_per_step": round(1e3 * wall / steps, 3),
            "llvmpipe_cpu_ms_per_step": round(1e3 * used["llvmpipe"] / steps, 3),
            "other_cpu_ms_per_step": round(1e3 * used["other"] / steps, 3),
            "cores_idle_fraction": round(max(0.0, 1.0 - sum(used.values()) / (cores * wall)), 3)}


def run_profile(seconds: float | None):
    """The default moving tunnel (512x256, gl) under cProfile: where its wall time goes.

    Each part is the cumulative wall time of one function (docs/performance.md); the parts do
    not overlap, and the rest is the Python around them. While the main thread waits in a draw
    call, llvmpipe's threads are busy; during the other parts they have nothing queued."""
    import cProfile
    import pstats

    from feelflow.solver.gl_backend import GLSolver

    ctx, gl_error = _gl_context()
    if ctx is None:
        raise UserError(f"--profile needs the gl backend: {gl_error}")
    nx, ny = 512, 256
    run = SceneRun("tunnel", GLSolver(scene_config("tunnel", nx, ny), ctx=ctx))
    run.advance(200)
    steps = max(MOVE_EVERY, int(round((seconds if seconds is not None else 5.0) * 400 / MOVE_EVERY)) * MOVE_EVERY)
    threads = {"moving tunnel, step(10) calls": thread_split(run, steps)}
    fixed = SceneRun("tunnel", GLSolver(scene_config("tunnel", nx, ny), ctx=ctx), moves=False, call_steps=None)
    fixed.advance(200)
    threads["not moved, one call"] = thread_split(fixed, steps)
    fixed.solver.close()
    prof = cProfile.Profile()
    t0, c0 = time.perf_counter(), time.process_time()
    prof.enable()
    run.advance(steps)
    prof.disable()
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    run.solver.close()
    stats = pstats.Stats(prof).stats
    parts = {}
    for label, (name, suffix) in PROFILE_PARTS.items():
        parts[label] = sum(v[3] for (file, _, fn), v in stats.items()
                           if fn == name and (suffix is None or file.endswith(suffix)))
    parts["other Python (scene script, call overhead)"] = max(0.0, wall - sum(parts.values()))
    return {"machine": machine(), "renderer": ctx.info.get("GL_RENDERER"), "grid": f"{nx}x{ny}",
            "steps": steps, "wall_s": round(wall, 3), "cpu_s": round(cpu, 3),
            "mlups": round(nx * ny * steps / wall / 1e6, 2),
            "parts_s": {k: round(v, 3) for k, v in parts.items()},
            "parts_fraction": {k: round(v / wall, 3) for k, v in parts.items()},
            "threads_without_profiler": threads}


def _subprocess_tunnel(nx: int, ny: int, seconds: float, env_extra: dict):
    """The default moving-cylinder tunnel in a fresh process with `env_extra` set: wall MLUPS,
    MLUPS per CPU-s and the renderer string, or None where the process failed."""
    code = ("import json; from feelflow.app.bench.solver_speed import _gl_context, SceneRun, scene_config, measure; "
            "from solver.gl_backend import GLSolver; ctx, _ = _gl_context(); "
            f"r = SceneRun('tunnel', GLSolver(scene_config('tunnel', {nx}, {ny}), ctx=ctx)); "
            f"m = measure(r, {seconds}); m['renderer'] = ctx.info.get('GL_RENDERER'); print(json.dumps(m))")
    out = subprocess.run([sys.executable, "-c", code], env={**os.environ, **env_extra},
                         capture_output=True, text=True)
    if out.returncode != 0:
        return None
    m = json.loads(out.stdout.strip().splitlines()[-1])
    return {"mlups": m["mlups"], "mlups_per_cpu_s": m["mlups_per_cpu_s"], "renderer": m["renderer"]}


def main(args) -> int:
    quick = bool(getattr(args, "quick", False))
    seconds = getattr(args, "seconds", None)
    if getattr(args, "profile", False):
        result = run_profile(seconds)
        print(f"moving-cylinder tunnel {result['grid']}, gl, {result['renderer']}: {result['steps']} steps, "
              f"{result['wall_s']} s wall, {result['cpu_s']} s CPU (all threads), {result['mlups']} MLUPS under the profiler")
        for label, t in result["parts_s"].items():
            print(f"  {label:72s} {t:7.3f} s  {100 * result['parts_fraction'][label]:5.1f} %")
        print("  CPU per step by thread, the same number of steps without the profiler:")
        for label, th in result["threads_without_profiler"].items():
            if th is None:
                print(f"    {label}: no /proc/self/task here")
                continue
            print(f"    {label:32s} wall {th['wall_ms_per_step']:.3f} ms, llvmpipe threads "
                  f"{th['llvmpipe_cpu_ms_per_step']:.3f} CPU-ms, main thread {th['other_cpu_ms_per_step']:.3f} "
                  f"CPU-ms, cores idle {100 * th['cores_idle_fraction']:.1f} %")
    elif getattr(args, "variants", False):
        result = run_variants(quick, seconds)
        print(f"gl tuning variants, moving-cylinder tunnel {result['grid']}, {result['renderer']}")
        print(f"  {'variant':72s} {'MLUPS (wall) best/median':>26s} {'per CPU-s best/median':>24s}")
        for name, v in result["variants"].items():
            w, c = v["wall"], v["per_cpu_s"]
            print(f"  {name:72s} {w['best']:12.1f} {w['median']:9.1f} {c['best']:14.1f} {c['median']:9.1f}")
        for label, v in result["against_numpy"].items():
            print(f"  {label:72s} {v['best']:11.2f}x {v['median']:8.2f}x   (ratios within each round)")
        work = result["cpu_work_ms_per_call"]
        for label in ("after the read", "before the read (GPU busy)"):
            if label in work:
                print(f"  {work['work_ms']:g} ms of Python per step(10) call {label:40s} adds "
                      f"{work[label]['median']:6.2f} ms a call (median; best {work[label]['best']:.2f})")
        print("  step variant drawn over the whole grid (MLUPS per CPU-s, best/median):")
        for name, v in result["step_variants_full_grid_mlups_per_cpu_s"].items():
            print(f"    {name:70s} {v['best']:12.1f} {v['median']:9.1f}")
        print("  llvmpipe settings, default moving tunnel in a fresh process (MLUPS wall, per CPU-s, renderer):")
        for knob, m in result["llvmpipe_knobs"].items():
            print(f"    {knob:28s} " + (f"{m['mlups']:8.1f} {m['mlups_per_cpu_s']:8.1f}  {m['renderer']}"
                                         if m is not None else "failed"))
    else:
        bench_rounds(quick, getattr(args, "rounds", None))  # refused before anything is printed or run
        grids = bench_grids(getattr(args, "grid", None))
        m = machine()
        print(f"machine: {m['cpu']}, {m['cores']} cores, {m['system']}, Python {m['python']}, "
              f"numpy {m['numpy']}, LP_NUM_THREADS {m['LP_NUM_THREADS']}")
        result = run_bench(quick, seconds, getattr(args, "rounds", None), grids)
        print(f"renderer: {result['renderer']}")
        print(f"memory copy bandwidth: {result['copy_bandwidth_gb_s']} GB/s (read + write) -> D2Q9 bound "
              f"{result['d2q9_bound_mlups']} MLUPS at {BYTES_PER_NODE_STEP} bytes per node and step")
        print(f"load average (1, 5, 15 min): {result['loadavg']}")
        for backend, speedups in result["speedups_by_backend"].items():
            for key, ratio in speedups.items():
                each = result["speedups_by_backend_per_round"][backend][key]
                print(f"{backend} / numpy, {key}: {ratio:.2f}x"
                      + (f" (median of the rounds: {', '.join(f'{v:.2f}' for v in each)})" if len(each) > 1 else ""))
        for key, best in result["fastest"].items():
            print(f"fastest, {key}: {best['backend']}, {best['ratio_to_numpy']:.2f}x numpy")
    if getattr(args, "json", None):
        from feelflow.app.files import write_json_atomic

        write_json_atomic(args.json, result)
    return 0
