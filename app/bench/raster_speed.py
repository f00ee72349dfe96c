"""Time `rasterise` for the bodies the app moves every frame: `python -m feelflow.app.bench.raster_speed`.

Each case re-rasterises the body at a new sub-cell pose per call (as the app does while the user
drags it) and reports the median and the fastest of `--repeats` batches.
"""
from __future__ import annotations

import argparse
import math
import os
import platform
import time

import numpy as np

from feelflow.shapes import Cylinder, FlatPlate, HalfAirfoil, Polygon, Wedge, rasterise


def cases(nx: int, ny: int):
    cx, cy = 0.4 * nx + 0.3, 0.5 * ny + 0.7
    th = np.linspace(0.0, 2.0 * math.pi, 41)[:-1]
    return {
        "cylinder D=32": Cylinder(32.0, x=cx, y=cy),
        "polygon 40 vertices (r=16)": Polygon(np.column_stack([16 * np.cos(th), 16 * np.sin(th)]), x=cx, y=cy),
        "plate 32 x 0.2": FlatPlate(32.0, 0.2, x=cx, y=cy, angle=0.3),
        "wedge 32, 60 deg": Wedge(32.0, math.radians(60), x=cx, y=cy),
        "half airfoil chord 64": HalfAirfoil(64.0, 8.0, x=cx, y=cy),
    }


def cpu_name() -> str:
    """The CPU model from /proc/cpuinfo (Linux), else the platform's machine name."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.machine()


def measure(shape, nx, ny, calls, repeats):
    per_call = []
    for r in range(repeats):
        start = time.perf_counter()
        for k in range(calls):
            rasterise(shape.moved(x=shape.x + 0.013 * k, angle=shape.angle + 0.002 * k), nx, ny)
        per_call.append((time.perf_counter() - start) / calls)
    return float(np.median(per_call)), float(min(per_call))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m feelflow.app.bench.raster_speed", description=__doc__.splitlines()[0])
    parser.add_argument("--nx", type=int, default=512)
    parser.add_argument("--ny", type=int, default=256)
    parser.add_argument("--calls", type=int, default=100, help="rasterisations per batch")
    parser.add_argument("--repeats", type=int, default=5, help="batches per case")
    parser.add_argument("--json", metavar="PATH", help="also write the results as JSON")
    args = parser.parse_args(argv)
    print(f"rasterise on {args.nx}x{args.ny}; {cpu_name()}, {os.cpu_count()} cores; "
          f"python {platform.python_version()}, numpy {np.__version__}")
    print(f"{'case':30s} {'median ms':>10s} {'best ms':>8s} {'solid':>6s} {'cut links':>9s}")
    results = []
    for name, shape in cases(args.nx, args.ny).items():
        shape.validate(args.nx, args.ny)
        med, best = measure(shape, args.nx, args.ny, args.calls, args.repeats)
        r = rasterise(shape, args.nx, args.ny)
        results.append({"case": name, "nx": args.nx, "ny": args.ny, "median_ms": med * 1e3,
                        "best_ms": best * 1e3, "solid_nodes": int(r.solid.sum()),
                        "cut_links": int(np.count_nonzero(r.q))})
        print(f"{name:30s} {med * 1e3:10.3f} {best * 1e3:8.3f} {results[-1]['solid_nodes']:6d} "
              f"{results[-1]['cut_links']:9d}")
    if args.json:
        from feelflow.app.files import save_json

        save_json(args.json, results)   # the output policy: atomic, a failed write says where it went
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
