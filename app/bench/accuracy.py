"""`feelflow bench accuracy`: speed against error, on a case with a known answer.

Runs Schaefer-Turek 2D-1 (steady flow past a cylinder at Re = 20, `solver/validation/
schaefer_turek_2d1.py`, to its convergence criterion) for each backend (numpy float64, numpy
float32, gl float32) along three axes of what a run costs and what it tells:

- *resolution*: cells per diameter D at the validation's inflow speed U_m = 0.075: error falls
  like D^-2 (second-order scheme), work rises like D^3 (nodes D^2, steps to the steady state D).
  D runs over multiples of 10, the resolutions at which the channel (4.1 D high, walls half-way
  between nodes) is a whole number of cells high (`schaefer_turek.check_resolution`), so that
  only the resolution changes along the axis and not the blockage D / H;
- *time step*: the inflow speed U_m in lattice units at a fixed D. At fixed D and Re, a larger
  U_m means fewer steps per unit of physical time (the same grid, a larger time step) but a
  larger Mach number, whose compressibility error grows like Ma^2;
- *tau fixed* (diffusive scaling): D grows with U_m D held constant, so tau, the collision's
  and the boundary rules' only parameter, stays that of D = 20 at the validation's U_m, and the
  Mach number falls like 1 / D. Every error term of a second-order scheme then falls like D^-2,
  which the resolution axis cannot show: there tau grows with D, and the curved-wall rule's
  error depends on tau (docs/science/validation.md, Schaefer-Turek 2D-1).

Per run it reports the grid, steps, wall and CPU seconds, MLUPS, and the relative errors of
C_D, C_L and dp against the refined reference values (John 2004); per backend, the observed order of the C_D error between
successive resolutions. All rows of one invocation come from one process, so their ratios
compare; the absolute seconds depend on the machine (printed) and on its load.
"""
from __future__ import annotations

import dataclasses
import math
import time

RESOLUTIONS = (10, 20, 30, 40)
SPEEDS = (0.02, 0.03, 0.05, 0.075, 0.09)  # below the Mach cap (FlowConfig.max_speed, Ma 0.17)
SPEED_RESOLUTION = 20  # the window's default body size
QUICK_RESOLUTIONS = (10, 20)
QUICK_SPEEDS = (0.05, 0.09)
QUICK_SPEED_RESOLUTION = 10
#: (D, U_m) with U_m D constant: tau 0.65 as at D = 20, U_m 0.075; quick: tau 0.59
TAU_FIXED = ((20, 0.075), (30, 0.05), (40, 0.0375))
QUICK_TAU_FIXED = ((10, 0.09), (20, 0.045))
AXES = ("resolution", "speed", "tau")
#: (label, backend, dtype)
VARIANTS = (("numpy float64", "numpy", "float64"), ("numpy float32", "numpy", "float32"),
            ("gl float32", "gl", "float32"))


def _factory(backend: str, dtype: str, ctx):
    from feelflow.solver.backend import create_solver

    def make(config):
        config = dataclasses.replace(config, dtype=dtype)
        return create_solver(backend, config, ctx=ctx)
    return make


def run_point(make_solver, d: int, u_max: float) -> dict:
    """One converged 2D-1 run: its cost and its errors (relative, signed)."""
    from feelflow.solver.validation import schaefer_turek_2d1 as st

    c0 = time.process_time()
    r = st.run(make_solver, resolution=d, u_max=u_max)
    cpu = time.process_time() - c0
    q = r.quantities
    geo = st.Geometry(d, st.RE, u_max=u_max)
    return {"d": d, "u_max": u_max, "mach": round(u_max * math.sqrt(3.0), 4), "grid": f"{geo.nx}x{geo.ny}",
            "node_updates": r.node_updates,
            "tau": round(q["tau"], 4), "steps": r.steps, "converged": bool(q["converged"]),
            "wall_s": round(r.wall_seconds, 2), "cpu_s": round(cpu, 2), "mlups": round(r.mlups, 1),
            "cd": q["cd"], "cd_error": q["cd_rel_error"], "cl_error": q["cl_rel_error"], "dp_error": q["dp_rel_error"]}


def observed_orders(rows) -> list[dict]:
    """Order of the C_D error between successive resolutions of one backend along one axis."""
    out = []
    for a, b in zip(rows, rows[1:]):
        ea, eb = abs(a["cd_error"]), abs(b["cd_error"])
        order = math.log(ea / eb) / math.log(b["d"] / a["d"]) if ea > 0 and eb > 0 else float("nan")
        out.append({"from_d": a["d"], "to_d": b["d"], "order": round(order, 2)})
    return out


def fitted_order(rows) -> float:
    """Least-squares slope of -log|C_D error| against log D over all resolutions: the trend
    through whatever scatter tau (which grows with D at fixed U_m) and the lattice's alignment
    with the cylinder put on the successive orders."""
    pts = [(math.log(r["d"]), math.log(abs(r["cd_error"]))) for r in rows if r["cd_error"] != 0]
    if len(pts) < 2:
        return float("nan")
    mx = sum(x for x, _ in pts) / len(pts)
    my = sum(y for _, y in pts) / len(pts)
    sxx = sum((x - mx) ** 2 for x, _ in pts)
    return round(-sum((x - mx) * (y - my) for x, y in pts) / sxx, 2)


def run_sweep(quick: bool, backends=None, axes=None) -> dict:
    from feelflow.app.bench.solver_speed import _gl_context, machine

    axes = set(axes or AXES)
    resolutions = (QUICK_RESOLUTIONS if quick else RESOLUTIONS) if "resolution" in axes else ()
    speeds = (QUICK_SPEEDS if quick else SPEEDS) if "speed" in axes else ()
    tau_fixed = (QUICK_TAU_FIXED if quick else TAU_FIXED) if "tau" in axes else ()
    d_speed = QUICK_SPEED_RESOLUTION if quick else SPEED_RESOLUTION
    from feelflow.solver.validation.schaefer_turek import U_MAX

    want_gl = not backends or "gl" in backends
    ctx, gl_error = _gl_context() if want_gl else (None, None)
    if backends and "gl" in backends and ctx is None:
        from feelflow.app.errors import UserError

        raise UserError(gl_error)
    renderer = ctx.info.get("GL_RENDERER") if ctx else None
    out = {"machine": machine(), "renderer": renderer, "case": "schaefer-turek-2d1 (Re 20, steady)",
           "resolution_axis": {"u_max": U_MAX, "d": list(resolutions)},
           "speed_axis": {"d": d_speed, "u_max": list(speeds)},
           "tau_axis": {"d_u_max": [list(p) for p in tau_fixed]}, "variants": {}}
    for label, backend, dtype in VARIANTS:
        if backends and backend not in backends:
            continue
        if backend == "gl" and ctx is None:
            out["variants"][label] = {"error": gl_error}
            print(f"{label}: skipped ({gl_error})", flush=True)
            continue
        make = _factory(backend, dtype, ctx)
        done = {}  # (D, U_m) -> row: a point two axes share runs once

        def point(d, u):
            if (d, u) not in done:
                done[d, u] = run_point(make, d, u)
                print(format_row(label, done[d, u]), flush=True)
            return done[d, u]

        by_d = [point(d, U_MAX) for d in resolutions]
        by_u = [point(d_speed, u) for u in speeds]
        by_tau = [point(d, u) for d, u in tau_fixed]
        out["variants"][label] = {"backend": backend, "dtype": dtype, "resolution": by_d,
                                  "orders": observed_orders(by_d), "fitted_order": fitted_order(by_d), "speed": by_u,
                                  "tau": by_tau, "tau_orders": observed_orders(by_tau)}
    return out


HEADER = (f"{'variant':14s} {'D':>3s} {'U_m':>6s} {'grid':>9s} {'tau':>6s} {'steps':>7s} {'wall s':>7s} "
          f"{'CPU s':>7s} {'MLUPS':>6s} {'C_D err %':>10s} {'C_L err %':>10s} {'dp err %':>9s}")


def format_row(label: str, r: dict) -> str:
    flag = "" if r["converged"] else "  (not converged)"
    return (f"{label:14s} {r['d']:3d} {r['u_max']:6.4f} {r['grid']:>9s} {r['tau']:6.3f} {r['steps']:7d} "
            f"{r['wall_s']:7.1f} {r['cpu_s']:7.1f} {r['mlups']:6.1f} {100 * r['cd_error']:+10.3f} "
            f"{100 * r['cl_error']:+10.2f} {100 * r['dp_error']:+9.3f}{flag}")


def markdown_tables(result) -> str:
    """The two axes as Markdown tables (what docs/science/performance.md quotes), rows in the order run."""
    cols = "| variant | D | U_m | tau | grid | steps | wall s | CPU s | MLUPS | C_D error | C_L error | dp error |"
    rule = "|" + " --- |" * (cols.count("|") - 1)
    out = []
    for axis, title in (("resolution", "resolution (U_m fixed)"), ("speed", "time step (D fixed)"),
                        ("tau", "resolution at fixed tau (U_m D fixed)")):
        if not any(v.get(axis) for v in result["variants"].values()):
            continue
        out += ["", f"Axis: {title}", "", cols, rule]
        for label, v in result["variants"].items():
            for r in v.get(axis, []):
                out.append(f"| {label} | {r['d']} | {r['u_max']} | {r['tau']} | {r['grid']} | {r['steps']} | "
                           f"{r['wall_s']:.1f} | {r['cpu_s']:.1f} | {r['mlups']:.1f} | {100 * r['cd_error']:+.3f} % | "
                           f"{100 * r['cl_error']:+.2f} % | {100 * r['dp_error']:+.3f} % |")
    return "\n".join(out)


def main(args) -> int:
    from feelflow.app.bench.solver_speed import machine

    m = machine()
    print(f"machine: {m['cpu']}, {m['cores']} cores, {m['system']}, Python {m['python']}, numpy {m['numpy']}")
    print("Schaefer-Turek 2D-1 (Re 20) to convergence; errors against John 2004's reference values\n")
    print(HEADER, flush=True)
    result = run_sweep(bool(getattr(args, "quick", False)), getattr(args, "backend", None),
                       getattr(args, "axis", None))
    if result["renderer"]:
        print(f"renderer: {result['renderer']}")
    for label, v in result["variants"].items():
        if v.get("orders"):
            orders = ", ".join(f"{o['from_d']}->{o['to_d']}: {o['order']}" for o in v["orders"])
            print(f"{label}: observed order of the C_D error {orders}; fitted over all D: {v['fitted_order']}")
        if v.get("tau_orders"):
            orders = ", ".join(f"{o['from_d']}->{o['to_d']}: {o['order']}" for o in v["tau_orders"])
            print(f"{label}: observed order of the C_D error at fixed tau {orders}")
    print(markdown_tables(result))
    if getattr(args, "json", None):
        from feelflow.app.files import save_json

        save_json(args.json, result)
    return 0
