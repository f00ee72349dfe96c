"""`python -m feelflow.app.bench.numpy_storage [--quick] [--json PATH]`: the numpy backend's speed by storage type.

`feelflow bench` compares the backends (float32); this measures the numpy reference alone in
float64 and float32: an empty periodic box, the tunnel with a fixed cylinder (momentum exchange
every step) and with a cylinder moved every step (set_body each step: rasterise, refill, links).
MLUPS = million node updates per second, best of several blocks (wall clock and process CPU
time; the CPU figure is steadier on a shared machine). Figures from a busy machine are indicative.
"""
from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

GRIDS = ((256, 128), (512, 256))
DTYPES = ("float64", "float32")
SCENES = ("box", "tunnel_fixed", "tunnel_moving")


def make(scene: str, nx: int, ny: int, dtype: str):
    from feelflow.shapes import Cylinder
    from feelflow.solver.backend import create_solver
    from feelflow.solver.config import FlowConfig

    if scene == "box":
        cfg = FlowConfig(nx=nx, ny=ny, nu=0.02, collision="trt", dtype=dtype, x_boundary="periodic",
                         y_boundary="periodic", initial_velocity=(0.03, 0.01))
        return create_solver("numpy", cfg), None
    cfg = FlowConfig(nx=nx, ny=ny, nu=0.02, collision="trt", dtype=dtype, inflow_speed=0.05,
                     inflow_ramp_steps=200, sponge_cells=nx // 16)
    solver = create_solver("numpy", cfg)
    solver.enable_force_models(["momentum_exchange"])
    body = Cylinder(ny / 8, x=nx / 4, y=ny / 2)
    solver.set_body(body)
    return solver, (body if scene == "tunnel_moving" else None)


def measure(scene: str, nx: int, ny: int, dtype: str, steps: int, blocks: int) -> dict:
    solver, moving = make(scene, nx, ny, dtype)
    state = {"k": 0}

    def advance():
        if moving is None:
            solver.step(steps)
            return
        for _ in range(steps):
            state["k"] += 1
            y = moving.y + (ny / 16) * np.sin(2 * np.pi * state["k"] / 2000)
            solver.set_body(moving.moved(y=y), velocity=(0.0, 0.0))
            solver.step(1)

    advance()  # warm-up
    wall = cpu = float("inf")
    for _ in range(blocks):
        t0, c0 = time.perf_counter(), time.process_time()
        advance()
        wall = min(wall, time.perf_counter() - t0)
        cpu = min(cpu, time.process_time() - c0)
    nodes = nx * ny * steps / 1e6
    return {"scene": scene, "grid": f"{nx}x{ny}", "dtype": dtype, "steps": steps * blocks,
            "mlups": round(nodes / wall, 1), "mlups_per_cpu_s": round(nodes / max(cpu, 1e-9), 1)}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m feelflow.app.bench.numpy_storage", description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer steps (smoke test)")
    parser.add_argument("--json", metavar="PATH", help="also write the results as JSON")
    args = parser.parse_args(argv)
    steps, blocks = (5, 2) if args.quick else (20, 5)
    rows = [measure(scene, nx, ny, dtype, steps, blocks)
            for nx, ny in GRIDS for dtype in DTYPES for scene in SCENES]
    print(f"numpy backend, numpy {np.__version__}, {os.cpu_count()} logical CPUs ({platform.machine()}), "
          f"{platform.system()} {platform.release()}")
    print("| grid | dtype | scene | MLUPS (wall) | MLUPS (CPU s) |")
    print("| --- | --- | --- | --- | --- |")
    for r in rows:
        print(f"| {r['grid']} | {r['dtype']} | {r['scene']} | {r['mlups']} | {r['mlups_per_cpu_s']} |")
    if args.json:
        from feelflow.app.files import save_json

        save_json(args.json, {"numpy": np.__version__, "cpus": os.cpu_count(), "results": rows})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
