"""Where the scheme stays stable on the hard cases a classroom produces: a scan of viscosity nu
against wind speed U, per hard scene and collision operator, on the window's grid.

Scenes (grid 192 x 96, the window's tunnel: velocity inlet, pressure outlet with its 32-cell
sponge and its absorbing layer, the quiet inlet (as the window has), no-slip walls,
float32; the body of size `d` at the window's start point (0.3 nx, ny/2)):
  plate45            - a flat plate d long and 0.5 cells thick (thinner than a cell) at 45 deg,
                       fixed, the wind blowing everywhere from the first step (the window's start);
  cylinder_impulsive - a cylinder, fluid at rest, the inflow switched on at full speed (no ramp);
  cylinder_shaken    - a cylinder moved back and forth along the stream over one diameter and
                       spun, its fastest surface point at the Mach cap `FlowConfig.max_speed`
                       (what a student's fast drag and wheel do), in the running wind;
  wedge_upstream     - the 60-degree wedge pointing upstream, fixed, wind everywhere.

A point (scene, collision, U, nu) is *stable* when the run lasts `CONVECTIVE_TIMES` d / U steps
without `SolverDiverged` and with max |u| below `U_BOUND` (a bounded flow: twice the largest
wind); else it is *diverged* (the solver's check) or *unbounded*. Stability falls as nu falls,
so each (scene, collision, U) bisects the ordered viscosities for the smallest stable one
(points not run are inferred from that order and marked so in the map).

The limit is reported per (scene, collision, d) as a grid Reynolds number Re_cell = U / nu:
the lowest Re_cell at which a run failed and the highest below which every run was stable.
Whether Re_cell or Re_D = U d / nu describes it is measured: the full scan repeats the most
restrictive TRT scene with d = 10 and 40 (`SIZE_CHECK`). Measured (docs/science/validation.md, 'Stability'): neither
is constant; Re_cell sqrt(d) varies less (27.7 / 39.1 / 27.7 at d = 10 / 20 / 40), so
solver/stability_limit.py states the limit as U sqrt(d) / nu <= K with K the smallest
(`k_measured_<collision>` in the results).

Background: LBM loses stability as tau -> 1/2 at finite Mach number (Krueger et al. 2017,
sec. 4.5 and 10.7: the grid Reynolds number U dx / nu bounds the resolvable flow). TRT
(Ginzburg 2008) with a fixed magic number Lambda = 3/16 sets tau- = 1/2 + Lambda / (tau+ - 1/2),
which grows without bound as tau+ -> 1/2 (tau- = 32 at nu = 0.002): the odd (flux) moments are
barely relaxed there, and on this scan TRT fails where BGK does not.

The full scan also runs the high-Reynolds hold (`hold_scan`): the recursive-regularised operator
(solver/regularised.py) on every hard case at U = 0.05 and 0.09, U / nu = 50, 75, 100,
d = 10, 20, 40, for 30 d / U each (docs/science/collision-operators.md); `python -m
feelflow.solver.validation.stability --collision rr --backend gl ...` runs single points of it.

`feelflow validate --case stability [--backend gl] [--json PATH]` runs the full scan;
`--quick` runs `quick_points()` (as the default test suite does): one point per hard case inside the
window's guarded region (must stay finite and bounded) and one far outside (must diverge).
The constants the window uses live in `solver/stability_limit.py`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from feelflow.solver.backend import SolverDiverged
from feelflow.solver.config import FlowConfig
from feelflow.solver.validation.base import CaseResult, Check, SolverFactory, Stopwatch

NAME = "stability"
DEFAULT_RESOLUTION = 20   # body size d in cells (the window's default)
QUICK_RESOLUTION = 20
GRID = (192, 96)
SPONGE_CELLS = 32
#: the absorbing layer of the window's sponge (app.simulation.default_base_config; a test keeps them equal)
SPONGE_ABSORB = 0.1
#: the window's quiet inlet (app.simulation.QUIET_INLET_RATE; a test keeps them equal)
QUIET_INLET_RATE = 1e-3
SCENES = ("plate45", "cylinder_impulsive", "cylinder_shaken", "wedge_upstream")
COLLISIONS = ("bgk", "trt")
#: every operator a single point can run (`main`); the scan keeps COLLISIONS
ALL_COLLISIONS = ("bgk", "trt", "rr", "kbc")
VISCOSITIES = (0.002, 0.003, 0.004, 0.006, 0.008, 0.012, 0.018, 0.027, 0.04)
SPEEDS = (0.02, 0.035, 0.05, 0.07, 0.09)
SIZE_CHECK = (10, 40)
#: the high-Reynolds hold (`hold_scan`): the operator the chooser adds beyond TRT's region, at the
#: window's wind and the top wind, to lower viscosities, every hard case, d = 10, 20, 40, for
#: HOLD_CONVECTIVE_TIMES d / U (solver/operator_choice.py, docs/science/collision-operators.md)
HOLD_COLLISION = "rr"
HOLD_SPEEDS = (0.05, 0.09)
HOLD_RE_CELL = (50.0, 75.0, 100.0)
HOLD_SIZES = (10, 20, 40)
HOLD_CONVECTIVE_TIMES = 30.0
CONVECTIVE_TIMES = 6.0
U_BOUND = 0.35          # 0.6 c_s: far beyond any physical speed here (wind + body <= 0.19); a runaway
CHECK_EVERY = 100        # steps between the max |u| checks
PLATE_THICKNESS = 0.5
PLATE_ANGLE_DEG = 45.0
WEDGE_APEX_DEG = 60.0


@dataclass
class Point:
    scene: str
    collision: str
    speed: float
    nu: float
    size: int
    state: str = ""            # stable | diverged | unbounded (measured) or inferred-stable/-unstable
    steps: int = 0             # steps run (up to the failure)
    max_u: float = float("nan")
    #: max |u| over the last third of the steps run (a bounded flow's is not above the earlier ones)
    max_u_last_third: float = float("nan")
    #: with the local guard (`run_point(..., guard=True)`): the viscosity the run ended at and
    #: each (step, max |u|, new viscosity) at which the guard raised it
    nu_final: float = float("nan")
    guard_raises: tuple = ()

    @property
    def re_cell(self) -> float:
        return self.speed / self.nu

    @property
    def stable(self) -> bool:
        return self.state in ("stable", "inferred-stable")

    def to_dict(self) -> dict:
        out = {"scene": self.scene, "collision": self.collision, "u": self.speed, "nu": self.nu,
               "size": self.size, "re_cell": round(self.re_cell, 4), "state": self.state, "steps": self.steps,
               "max_u": None if not math.isfinite(self.max_u) else round(self.max_u, 5),
               "max_u_last_third": None if not math.isfinite(self.max_u_last_third) else round(self.max_u_last_third, 5)}
        if self.guard_raises or math.isfinite(self.nu_final):
            out.update(nu_final=self.nu_final, guard_raises=[list(r) for r in self.guard_raises])
        return out


def scene_config(scene: str, collision: str, speed: float, nu: float, grid=GRID, smagorinsky: float = 0.0,
                 mach_limit: float | None = None) -> FlowConfig:
    """The scene's flow; `mach_limit` (default FlowConfig's) sets the Mach cap the shaken
    cylinder is driven at."""
    nx, ny = grid
    start = (0.0, 0.0) if scene == "cylinder_impulsive" else (speed, 0.0)
    extra = {} if mach_limit is None else {"mach_limit": mach_limit}
    return FlowConfig(nx=nx, ny=ny, nu=nu, collision=collision, smagorinsky=smagorinsky, dtype="float32", x_boundary="tunnel",
                      y_boundary="no_slip", inflow_speed=speed, inflow_ramp_steps=0, initial_velocity=start,
                      sponge_cells=min(SPONGE_CELLS, nx // 4), sponge_absorb=SPONGE_ABSORB,
                      inlet_nonreflecting=QUIET_INLET_RATE, **extra).validate()


def scene_body(scene: str, size: float, grid=GRID):
    from feelflow.shapes import Cylinder, FlatPlate, Wedge

    x, y = 0.3 * grid[0], 0.5 * grid[1]
    if scene == "plate45":
        return FlatPlate(size, PLATE_THICKNESS, x, y, math.radians(PLATE_ANGLE_DEG))
    if scene == "wedge_upstream":
        return Wedge(size, math.radians(WEDGE_APEX_DEG), "upstream", x, y)
    if scene in ("cylinder_impulsive", "cylinder_shaken"):
        return Cylinder(size, x, y)
    raise ValueError(f"unknown stability scene {scene!r}; choose from {', '.join(SCENES)}")


def _max_speed(solver) -> float:
    _, ux, uy = solver.macroscopic()
    s = np.hypot(ux, uy)
    return float(np.nanmax(s)) if np.isfinite(s).all() else float("inf")


class _Live:
    """The running solver, replaced when the local guard rebuilds it at a higher viscosity."""

    def __init__(self, solver):
        self.solver = solver


def run_point(make_solver: SolverFactory, scene: str, collision: str, speed: float, nu: float,
              size: int = DEFAULT_RESOLUTION, watch: Stopwatch | None = None,
              convective_times: float = CONVECTIVE_TIMES, grid=GRID, u_bound: float = U_BOUND,
              smagorinsky: float = 0.0, mach_limit: float | None = None, guard: bool = False) -> Point:
    """Run one point; its state is stable, diverged (SolverDiverged) or unbounded (max |u| above
    `u_bound`; pass math.inf to count only the solver's own divergence check). `mach_limit`:
    the Mach cap the shaken cylinder is driven at (default FlowConfig's). `guard`: the window's
    local stability guard (solver/local_guard.py) acts every GUARD_EVERY steps, raising the
    viscosity with the flow kept, as the window does; `point.nu_final` and `point.guard_raises`
    say what it did."""
    config = scene_config(scene, collision, speed, nu, grid, smagorinsky, mach_limit)
    body = scene_body(scene, size, grid)
    watch = watch or Stopwatch()
    steps = int(math.ceil(convective_times * size / speed))
    point = Point(scene, collision, speed, nu, size)
    live = _Live(make_solver(config))
    rebuild = (lambda new_nu: _rebuild(live, make_solver, new_nu)) if guard else None
    try:
        if scene == "cylinder_shaken":
            _shake(live, body, steps, point, watch, u_bound, rebuild)
        else:
            live.solver.set_body(body)
            _run(live, steps, point, watch, lambda n: watch.step(live.solver, n), u_bound, rebuild)
    finally:
        live.solver.close()
    if guard:
        point.nu_final = live.solver.config.nu
    return point


#: steps between the guard's reads of max |u| (the window's physical-range check)
GUARD_EVERY = 64


def _rebuild(live, make_solver, nu):
    """The solver at viscosity nu with the flow kept (the window's set_flow(nu=...))."""
    from dataclasses import replace

    f = live.solver.distributions()
    old = live.solver
    live.solver = make_solver(replace(old.config, nu=nu).validate())
    old.close()
    live.solver.set_distributions(f)


def _run(live, steps, point, watch, advance, u_bound, rebuild=None):
    from feelflow.solver import local_guard

    done = 0
    point.max_u = point.max_u_last_third = 0.0
    every = GUARD_EVERY if rebuild else CHECK_EVERY
    try:
        while done < steps:
            n = min(every, steps - done)
            advance(n)
            done += n
            now = _max_speed(live.solver)
            point.max_u = max(point.max_u, now)
            if 3 * done > 2 * steps:
                point.max_u_last_third = max(point.max_u_last_third, now)
            if point.max_u > u_bound:
                point.state, point.steps = "unbounded", done
                return
            if rebuild is not None:
                cfg = live.solver.config
                verdict = local_guard.check(cfg.collision, cfg.nu, now)
                if not verdict.inside and verdict.nu_needed is not None:
                    nu = math.ceil(verdict.nu_needed * 1e4 - 1e-6) / 1e4   # as the window rounds it
                    rebuild(nu)
                    point.guard_raises += ((done, round(now, 4), nu),)
    except SolverDiverged as exc:
        point.state, point.steps, point.max_u = "diverged", exc.step + 1, float("inf")
        return
    point.state, point.steps = "stable", done


def _shake(live, body, steps, point, watch, u_bound, rebuild=None):
    """Back and forth along the stream over one diameter (centred on the start), spinning with
    the direction of travel, at the Mach cap: asks for the cap in translation and in rotation;
    `set_body` scales both so that the fastest surface point moves at exactly max_speed
    (docs/science/algorithm.md 'Speed limit'), so each keeps half of it."""
    cap = live.solver.config.max_speed
    x0, y0, x1, y1 = body.bounding_box()
    radius = math.hypot(0.5 * (x1 - x0), 0.5 * (y1 - y0))   # the cap's R: centre to a box corner
    v = 0.5 * cap                                         # the capped translation speed
    sweep = max(2, int(round(body.diameter / v)))          # steps per sweep of one diameter
    state = {"x": body.x, "t": 0}

    def move_and_step():
        t = state["t"]
        direction = -1.0 if ((t + sweep // 2) // sweep) % 2 == 0 else 1.0   # first against the stream
        live.solver.set_body(body.moved(x=state["x"], y=body.y), velocity=(direction * cap, 0.0),
                             omega=direction * cap / radius)
        live.solver.step(1)
        state["x"] += direction * v
        state["t"] = t + 1

    def advance(n):  # the moves count in the stopwatch's time, as the steps they belong to
        for _ in range(n):
            watch.timed(live.solver.config.nx * live.solver.config.ny, 1, move_and_step)

    _run(live, steps, point, watch, advance, u_bound, rebuild)


# --- the scan ---------------------------------------------------------------------------------
def scan(make_solver: SolverFactory, scenes=SCENES, collisions=COLLISIONS, speeds=SPEEDS,
         viscosities=VISCOSITIES, size: int = DEFAULT_RESOLUTION, watch: Stopwatch | None = None,
         progress=None) -> list[Point]:
    """Every (scene, collision, U, nu) point, run (no point is inferred)."""
    points = []
    for scene in scenes:
        for collision in collisions:
            for speed in speeds:
                for nu in viscosities:
                    p = run_point(make_solver, scene, collision, speed, nu, size, watch)
                    points.append(p)
                    if progress:
                        progress(p)
    return points


def hold_scan(make_solver: SolverFactory, watch: Stopwatch | None = None, progress=None,
              collision: str = HOLD_COLLISION, speeds=HOLD_SPEEDS, re_cells=HOLD_RE_CELL,
              sizes=HOLD_SIZES) -> list[Point]:
    """Every hard case at each (U, Re_cell = U / nu, d) for HOLD_CONVECTIVE_TIMES d / U."""
    points = []
    for size in sizes:
        for scene in SCENES:
            for speed in speeds:
                for re_cell in re_cells:
                    p = run_point(make_solver, scene, collision, speed, speed / re_cell, size, watch,
                                  convective_times=HOLD_CONVECTIVE_TIMES)
                    points.append(p)
                    if progress:
                        progress(p)
    return points


def limits(points) -> dict:
    """Per (scene, collision, size): the lowest Re_cell = U / nu at which a run failed, the
    highest Re_cell below which every run was stable, and per speed the bracket of nu."""
    out = {}
    keys = sorted({(p.scene, p.collision, p.size) for p in points}, key=lambda k: (SCENES.index(k[0]), k[1], k[2]))
    for key in keys:
        group = [p for p in points if (p.scene, p.collision, p.size) == key]
        failed = [p.re_cell for p in group if not p.stable]
        fail = min(failed) if failed else math.inf
        stable_below = max((p.re_cell for p in group if p.stable and p.re_cell < fail), default=0.0)
        per_speed = {}
        for u in sorted({p.speed for p in group}):
            row = sorted((p for p in group if p.speed == u), key=lambda p: p.nu)
            bad = [p.nu for p in row if not p.stable]
            good = [p.nu for p in row if p.stable and (not bad or p.nu > max(bad))]
            per_speed[u] = {"largest_failed_nu": max(bad) if bad else None,
                            "smallest_stable_nu": min(good) if good else None,
                            "monotone": all(p.stable for p in row if bad and p.nu > max(bad))
                            and not any(p.stable for p in row if bad and p.nu < max(bad))}
        out[key] = {"re_cell_failed": fail, "re_cell_stable": stable_below,
                    "re_d_failed": fail * key[2], "per_speed": per_speed}
    return out


def run(make_solver: SolverFactory, resolution: int | None = None, quick: bool = False,
        backend: str = "numpy", progress=None) -> CaseResult:
    from feelflow.solver.stability_limit import SAFETY_MARGIN, STABLE_U_SQRT_D_OVER_NU, min_stable_viscosity

    size = resolution or DEFAULT_RESOLUTION
    watch = Stopwatch()
    if quick:
        points = [run_point(make_solver, *qp, size=size, watch=watch) for qp in quick_points()]
    else:
        points = scan(make_solver, size=size, watch=watch, progress=progress)
        worst = min(SCENES, key=lambda s: limits([p for p in points if p.scene == s and p.collision == "trt"])
                    [(s, "trt", size)]["re_cell_failed"])
        for d in SIZE_CHECK:   # does the limit move with the body size? (Re_cell or Re_D)
            points += scan(make_solver, scenes=(worst,), collisions=("trt",), size=d, watch=watch,
                           progress=progress)
        points += hold_scan(make_solver, watch=watch, progress=progress)
    result = CaseResult(NAME, backend, size)
    guarded = []
    for key, lim in limits(points).items():
        tag = f"{key[0]}_{key[1]}" + ("" if key[2] == size else f"_d{key[2]}")
        result.quantities[f"re_cell_failed_{tag}"] = lim["re_cell_failed"]
        result.quantities[f"re_cell_stable_{tag}"] = lim["re_cell_stable"]
    for collision in sorted({p.collision for p in points}):   # the constant K of solver/stability_limit.py
        result.quantities[f"k_measured_{collision}"] = min(
            lim["re_cell_stable"] * math.sqrt(k[2]) for k, lim in limits(points).items() if k[1] == collision)
    for collision in sorted({p.collision for p in points} & {HOLD_COLLISION}):   # STABLE_CELL_REYNOLDS
        result.quantities[f"re_cell_measured_{collision}"] = min(
            lim["re_cell_stable"] for k, lim in limits(points).items() if k[1] == collision)
    for p in points:   # every point the window would allow must have been stable
        if p.nu >= min_stable_viscosity(p.speed, p.collision, p.size) - 1e-12:
            guarded.append(p)
    result.quantities["guarded_points"] = float(len(guarded))
    result.quantities["guarded_points_stable"] = float(sum(p.stable for p in guarded))
    result.quantities["guarded_all_stable"] = float(all(p.stable for p in guarded))
    result.checks.append(Check("guarded_all_stable", 1.0, 1.0,
                               "every point the window allows (U sqrt(d) / nu <= margin x K) stays stable"))
    if quick:
        outside = [p for p in points if p.nu < min_stable_viscosity(p.speed, p.collision, p.size)]
        result.quantities["outside_points_failed"] = float(sum(not p.stable for p in outside))
        result.quantities["outside_all_failed"] = float(all(not p.stable for p in outside))
        result.checks.append(Check("outside_all_failed", 1.0, 1.0, "the far-outside points must diverge"))
    result.details = {"points": [p.to_dict() for p in points],
                      "limits": [{"scene": k[0], "collision": k[1], "size": k[2],
                                  **{n: v for n, v in lim.items() if n != "per_speed"},
                                  "per_speed": [{"u": u, **b} for u, b in lim["per_speed"].items()]}
                                 for k, lim in limits(points).items()]}
    result.notes = (f"{GRID[0]} x {GRID[1]} tunnel, float32, body size {size} cells, {CONVECTIVE_TIMES:g} d / U "
                    f"steps per point; window limit U sqrt(d) / nu <= {SAFETY_MARGIN} x {STABLE_U_SQRT_D_OVER_NU}")
    return watch.fill(result)


def quick_points():
    """(scene, collision, U, nu) for the default test suite: per hard case, the window's own
    corner (the highest wind at the lowest viscosity the guard allows) for TRT and for the
    high-Reynolds operator, and TRT at the panel's extreme corner (U = 0.09, nu = 0.002), far
    outside TRT's measured region."""
    from feelflow.solver.stability_limit import min_stable_viscosity

    u = max(SPEEDS)
    out = []
    for scene in SCENES:
        out.append((scene, "trt", u, min_stable_viscosity(u, "trt", DEFAULT_RESOLUTION)))
        out.append((scene, "trt", u, min(VISCOSITIES)))
        out.append((scene, HOLD_COLLISION, u, min_stable_viscosity(u, HOLD_COLLISION, DEFAULT_RESOLUTION)))
    return out


def format_details(result: CaseResult) -> str:
    """The stable / failed map per scene and collision (rows U, columns nu) and the limits."""
    points = [Point(d["scene"], d["collision"], d["u"], d["nu"], d["size"], d["state"], d["steps"])
              for d in result.details.get("points", [])]
    if not points:
        return ""
    mark = {"stable": "s", "diverged": "**D**", "unbounded": "**U**"}
    lines = ["Stability map (s stable, **D** diverged, **U** unbounded max |u| > "
             f"{U_BOUND}); cell Reynolds number Re_cell = U / nu:", ""]
    nus = sorted({p.nu for p in points})
    lines.append("| scene | collision | d | U \\ nu | " + " | ".join(f"{n:g}" for n in nus) + " |")
    lines.append("| --- | --- | --- | --- | " + " | ".join("---" for _ in nus) + " |")
    lim = limits(points)
    for key in lim:
        group = [p for p in points if (p.scene, p.collision, p.size) == key]
        for u in sorted({p.speed for p in group}):
            cells = {p.nu: mark.get(p.state, p.state) for p in group if p.speed == u}
            lines.append(f"| {key[0]} | {key[1]} | {key[2]} | {u:g} | "
                         + " | ".join(cells.get(n, "") for n in nus) + " |")
    lines += ["", "| scene | collision | d | lowest failing Re_cell | highest all-stable Re_cell | "
              "lowest failing Re_D | all-stable Re_cell sqrt(d) |", "| --- | --- | --- | --- | --- | --- | --- |"]
    for key, v in lim.items():
        lines.append(f"| {key[0]} | {key[1]} | {key[2]} | {v['re_cell_failed']:.3g} | {v['re_cell_stable']:.3g} | "
                     f"{v['re_d_failed']:.4g} | {v['re_cell_stable'] * math.sqrt(key[2]):.4g} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    """`python -m feelflow.solver.validation.stability --u 0.09 --nu 0.002 --collision bgk --convective-times 30`:
    the four hard cases at one point for longer than the scan, one line each (JSON with --json)."""
    import argparse
    import json
    import time
    import warnings

    from feelflow.solver.backend import create_solver

    parser = argparse.ArgumentParser(prog="python -m feelflow.solver.validation.stability", description=main.__doc__)
    parser.add_argument("--u", type=float, required=True, help="wind speed (cells per step)")
    parser.add_argument("--nu", type=float, default=None, help="viscosity (default: --k gives it)")
    parser.add_argument("--k", type=float, default=None, help="instead of --nu: nu = U sqrt(d) / K")
    parser.add_argument("--collision", default="trt", choices=ALL_COLLISIONS)
    parser.add_argument("--smagorinsky", type=float, default=0.0, help="Smagorinsky constant (collision rr)")
    parser.add_argument("--size", type=int, nargs="+", default=[DEFAULT_RESOLUTION], help="body size(s) in cells")
    parser.add_argument("--scene", nargs="+", default=list(SCENES), choices=SCENES)
    parser.add_argument("--convective-times", type=float, default=CONVECTIVE_TIMES)
    parser.add_argument("--backend", default="numpy", help="numpy, cpu or gl (EGL standalone context)")
    parser.add_argument("--mach-limit", type=float, default=None,
                        help="the Mach cap the shaken cylinder is driven at (default: the window's, FlowConfig's)")
    parser.add_argument("--no-bound", action="store_true",
                        help=f"count only the solver's NaN check, not max |u| > {U_BOUND}")
    parser.add_argument("--guard", action="store_true",
                        help="the window's local stability guard raises the viscosity when the flow leaves its region")
    args = parser.parse_args(argv)
    if (args.nu is None) == (args.k is None):
        parser.error("give --nu or --k")
    kwargs = {}
    if args.backend == "gl":   # the CLI's way (docs/developer/architecture.md, rule 2): an EGL standalone context
        import moderngl

        kwargs["ctx"] = moderngl.create_context(standalone=True, backend="egl", require=330)

    def make_solver(config):
        return create_solver(args.backend, config, **kwargs)

    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)
        for size in args.size:
            nu = args.nu if args.nu is not None else args.u * math.sqrt(size) / args.k
            for scene in args.scene:
                start = time.perf_counter()
                p = run_point(make_solver, scene, args.collision, args.u, nu, size,
                              convective_times=args.convective_times, smagorinsky=args.smagorinsky,
                              u_bound=math.inf if args.no_bound else U_BOUND, mach_limit=args.mach_limit,
                              guard=args.guard)
                row = {**p.to_dict(), "smagorinsky": args.smagorinsky, "backend": args.backend,
                       "mach_limit": args.mach_limit, "bound": None if args.no_bound else U_BOUND,
                       "convective_times": args.convective_times, "seconds": round(time.perf_counter() - start, 1)}
                print(json.dumps(row), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
