"""`feelflow bench [solver] [--json PATH] [--quick] [--profile] [--grid NXxNY]`: solver speed, every backend.

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

`--profile` instead splits the wall time of the gl moving tunnel into its parts (draw calls,
read-backs, moves) under cProfile, and its CPU time by thread. Figures from a shared machine
are indicative; compare ratios measured in the same run.
"""
from __future__ import annotations

import os
import platform
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
    float32 stores them subnormal; x86 computes with those many times slower (llvmpipe flushes
    them to zero), so numpy's first round would run slow and the first round's ratio come out
    high (tests/test_bench_solver.py checks that none are left after the warm-up)."""
    if scene != "tunnel" or quick:
        return 20
    return 20 + config.inflow_ramp_steps + 2 * config.nx


class SceneRun:
    """One scene on one solver: `advance(n)` runs n steps the way the window drives them.

    For the profile's comparison (`--profile`), `moves=False` keeps the cylinder where it was
    placed, and `call_steps` sets how many steps each `step()` call runs (None: all n at once)
    instead of MOVE_EVERY."""

    def __init__(self, scene, solver, moves: bool = True, call_steps: int | None = MOVE_EVERY):
        from feelflow.shapes import Cylinder

        self.scene, self.solver = scene, solver
        self.moves, self.call_steps = moves, call_steps
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
            self.k += chunk
            done += chunk
            if self.scene == "tunnel" and self.moves:
                self._move()
        self.solver.finish()


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
                solver = create_solver(backend, scene_config(scene, nx, ny), ctx=ctx)
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

    Each part is the cumulative wall time of one function (docs/science/performance.md); the parts do
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
        from feelflow.app.files import save_json

        save_json(args.json, result)
    return 0
