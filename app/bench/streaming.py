"""`feelflow bench streaming [--grid NXxNY] [--rounds N] [--seconds S] [--json PATH]`: the
compiled cpu backend's streaming pattern by measurement, two buffers against the AA pattern.

The periodic box of `feelflow bench solver` (app/bench/solver_speed.py: TRT, float32, a uniform
flow, no body) stepped three ways, with numba's threads over blocks of rows, in alternating
rounds:
- two buffers: the cpu backend stepped one step per call (solver/cpu_kernels.py `make_kernel`
  with n = 1: pull from one buffer, collide, store into the other; a Python call per step);
- AA, the solver: the same backend, CALL_STEPS steps per call (the AA pattern between a first
  and a last step in the natural layout);
- AA, box only: `make_box_aa` (one buffer, in place, even and odd steps, nothing but the box).
Rows give the medians of the rounds: MLUPS, the fraction of the D2Q9 bound the solver bench uses
(72 bytes a node and step, from the same copy-bandwidth probe) and MLUPS per CPU-second. Before
timing, all run the same steps from the same state and the largest difference of their
populations is printed (float32 rounding: the kernels collide with the same arithmetic, so it is
expected to be zero or a few ulps).
docs/science/cpu-backend.md quotes the figures and the decision they support.
"""
from __future__ import annotations

import statistics
import time

import numpy as np

from feelflow.app.bench.solver_speed import (BYTES_PER_NODE_STEP, bench_grids, copy_bandwidth, load_average,
                                             machine, scene_config)

GRID = (512, 256)
#: steps per compiled call (even: the AA kernel's state is natural after each pair of steps)
CALL_STEPS = 50
PATTERNS = ("two buffers (pull)", "AA, box only", "AA, the solver")


def stream(g: np.ndarray) -> np.ndarray:
    """Each population moved one link along its direction, periodic: what the AA kernel holds
    between pairs of steps when the two-buffer kernel holds g."""
    from feelflow.solver.lattice import C

    return np.stack([np.roll(g[i], (int(C[i, 1]), int(C[i, 0])), axis=(0, 1)) for i in range(9)])


class SolverSteps:
    """The cpu backend's own step on the box, `per_call` steps per call (1: two buffers; more:
    the AA pattern between natural ends), or all n at once when per_call is None."""

    def __init__(self, config, per_call: int | None = None, g0=None):
        from feelflow.solver.cpu_backend import CpuSolver

        self.solver = CpuSolver(config)
        self.per_call = per_call
        if g0 is not None:
            self.solver.g[...] = g0

    def state(self) -> np.ndarray:
        return stream(self.solver.g)

    def advance(self, n: int) -> None:
        if self.per_call is None:
            self.solver.step(n)
            return
        for _ in range(n // self.per_call):
            self.solver.step(self.per_call)


class AAInPlace:
    """The AA kernel on one buffer, started from `g0` (a two-buffer state) streamed."""

    def __init__(self, config, g0):
        import numba

        from feelflow.solver.cpu_kernels import CHUNK, make_box_aa
        from feelflow.solver.relaxation import relaxation_rates

        dt = np.dtype(config.dtype)
        op, om = relaxation_rates(config)
        self.op, self.om = dt.type(np.ravel(op)[0]), dt.type(np.ravel(om)[0])
        self.g = np.ascontiguousarray(stream(g0), dtype=dt)
        blocks = max(1, int(numba.get_num_threads()))
        self.scratch = np.zeros((blocks, 2, 9, CHUNK), dt)
        self.sums = np.zeros(blocks)
        self.kernel = make_box_aa(config.collision, dt.name)

    def state(self) -> np.ndarray:
        return self.g

    def advance(self, n: int) -> None:
        if n % 2:
            raise ValueError("the AA box advances by pairs of steps")
        done, finite = self.kernel(n, False, self.g, self.op, self.om, self.scratch, self.sums)
        if not finite:
            raise RuntimeError(f"the AA box diverged after {done} steps")


def make_runs(nx: int, ny: int) -> dict:
    """Both patterns on the box, from the same state: the box's uniform flow with a small
    random disturbance (a uniform state streams to itself, which would hide a wrong link)."""
    config = scene_config("box", nx, ny)
    two = SolverSteps(config, per_call=1)
    g = two.solver.g
    g += (1e-4 * np.random.default_rng(1).standard_normal(g.shape)).astype(g.dtype)
    aa = AAInPlace(config, g.copy())
    solver = SolverSteps(config, None, g.copy())
    return {PATTERNS[0]: two, PATTERNS[1]: aa, PATTERNS[2]: solver}


def largest_difference(runs: dict, steps: int = 2 * CALL_STEPS) -> float:
    """Every pattern `steps` steps on from the same state: the largest difference of their
    (shifted) populations from the first's."""
    for run in runs.values():
        run.advance(steps)
    first, *others = (np.asarray(run.state(), np.float64) for run in runs.values())
    return max(float(np.abs(other - first).max()) for other in others)


def measure(run, seconds: float) -> dict:
    steps, wall, cpu = 0, 0.0, 0.0
    while wall < seconds:
        t0, c0 = time.perf_counter(), time.process_time()
        run.advance(CALL_STEPS)
        wall += time.perf_counter() - t0
        cpu += time.process_time() - c0
        steps += CALL_STEPS
    return {"steps": steps, "wall": wall, "cpu": cpu}


def run_streaming(grid=GRID, rounds: int = 3, seconds: float = 2.0) -> dict:
    nx, ny = grid
    bandwidth = copy_bandwidth(512)
    bound = bandwidth / BYTES_PER_NODE_STEP / 1e6
    runs = make_runs(nx, ny)
    difference = largest_difference(runs)    # also the warm-up (compiles on a first run)
    samples = {name: [] for name in runs}
    for _ in range(rounds):
        for name, run in runs.items():
            samples[name].append(measure(run, seconds))
    rows = []
    nodes = nx * ny / 1e6
    for name, ss in samples.items():
        mlups = [nodes * s["steps"] / s["wall"] for s in ss]
        per_cpu = [nodes * s["steps"] / max(s["cpu"], 1e-9) for s in ss]
        m = statistics.median(mlups)
        rows.append({"pattern": name, "mlups": round(m, 1), "fraction_of_bound": round(m / bound, 4),
                     "mlups_per_cpu_s": round(statistics.median(per_cpu), 1),
                     "rounds_mlups": [round(v, 1) for v in mlups]})
    base = samples[PATTERNS[0]]

    def over_two_buffers(name):
        return [(a["steps"] / a["wall"]) / (b["steps"] / b["wall"]) for a, b in zip(samples[name], base)]

    ratio, solver_ratio = over_two_buffers(PATTERNS[1]), over_two_buffers(PATTERNS[2])
    return {"machine": machine(), "grid": f"{nx}x{ny}", "threads": len(runs[PATTERNS[1]].sums),
            "copy_bandwidth_gb_s": round(bandwidth / 1e9, 2), "d2q9_bound_mlups": round(bound, 1),
            "rounds": rounds, "seconds_per_round": seconds, "largest_difference": difference,
            "results": rows, "aa_over_two_buffers_per_round": [round(r, 3) for r in ratio],
            "aa_over_two_buffers": round(statistics.median(ratio), 3),
            "solver_over_two_buffers_per_round": [round(r, 3) for r in solver_ratio],
            "solver_over_two_buffers": round(statistics.median(solver_ratio), 3), "loadavg": load_average()}


def main(args) -> int:
    grids = bench_grids(getattr(args, "grid", None)) if getattr(args, "grid", None) else (GRID,)
    rounds = getattr(args, "rounds", None) or 3
    seconds = getattr(args, "seconds", None) or 2.0
    m = machine()
    print(f"machine: {m['cpu']}, {m['cores']} cores, {m['system']}, Python {m['python']}, numpy {m['numpy']}")
    results = []
    for grid in grids:
        r = run_streaming(grid, rounds, seconds)
        results.append(r)
        print(f"periodic box {r['grid']}, TRT float32, {r['threads']} threads; D2Q9 bound {r['d2q9_bound_mlups']} "
              f"MLUPS ({r['copy_bandwidth_gb_s']} GB/s copy); the patterns differ by at most "
              f"{r['largest_difference']:.2g} after {2 * CALL_STEPS} steps")
        for row in r["results"]:
            print(f"  {row['pattern']:20s} {row['mlups']:8.1f} MLUPS  {100 * row['fraction_of_bound']:5.1f} % of bound  "
                  f"({row['mlups_per_cpu_s']:.1f} MLUPS per CPU-second)  rounds: "
                  + " ".join(f"{v:.1f}" for v in row["rounds_mlups"]))
        print(f"  AA box only / two buffers: {r['aa_over_two_buffers']:.2f}x (rounds: "
              + ", ".join(f"{v:.2f}" for v in r["aa_over_two_buffers_per_round"]) + ")")
        print(f"  AA the solver / two buffers: {r['solver_over_two_buffers']:.2f}x (rounds: "
              + ", ".join(f"{v:.2f}" for v in r["solver_over_two_buffers_per_round"]) + ")")
        print(f"  load average (1, 5, 15 min): {r['loadavg']}")
    if getattr(args, "json", None):
        from feelflow.app.files import save_json

        save_json(args.json, results[0] if len(results) == 1 else results)
    return 0
