"""Diagnose Schaefer-Turek 2D-2 (docs/science/validation.md): record C_D(t), C_L(t) and analyse them.

    python -m feelflow.app.bench.st2d2_diagnose record --d 20 [--u 0.075] [--ramp-periods 2 | --impulsive]
        [--sponge CELLS [--absorb A]] [--length-d 22] [--conv-times 60] [--sample 2]
        [--collision trt|bgk] [--magic 0.1875] [--equilibrium compressible|incompressible] [--stress]
        [--backend numpy|gl] --out series.npz
    python -m feelflow.app.bench.st2d2_diagnose analyse series.npz [...]

`analyse` folds the last three shedding periods (upward zero crossings of C_L) into a
period-averaged signal and prints: per-period C_D maxima, mean C_D, C_D,max and C_L,max of the
raw signal (with C_L,min; five digits) and of the period-averaged one, the rms of C_D around the
period-averaged signal (what does not repeat: sound), and the strongest lines of the C_D
spectrum in units of the shedding frequency. Run from the repository root (numpy backend;
`--backend gl` runs the fragment-shader backend, float32, on an EGL standalone context, several
times faster on this machine).

`--stress` also records C_D from a second, independent force evaluation of the same flow: the
pressure (lattice equation of state, `feelflow.solver.forces.pressure`) plus the viscous stress
(`feelflow.solver.forces.stress`) integrated over the exact surface, sampled at the end of each block
(momentum exchange: the block's mean); `analyse` prints both means. Where the two agree, the
drag excess is in the flow, not in the force evaluation.
"""
from __future__ import annotations

import argparse

import numpy as np

from feelflow.solver.config import EQUILIBRIA
from feelflow.solver.validation.schaefer_turek import Geometry
from feelflow.solver.validation.schaefer_turek_2d2 import RE, upward_zero_crossings


def record(a) -> None:
    from feelflow.solver.backend import create_solver
    from feelflow.solver.forces import create_model
    from feelflow.solver.forces.stress import viscous_force

    geo = Geometry(a.d, RE, u_max=a.u)
    geo.nx = int(round(a.length_d * a.d))
    over = dict(sponge_cells=a.sponge, sponge_strength=10.0, sponge_absorb=a.absorb) if a.sponge else {}
    over.update(collision=a.collision, trt_magic=a.magic, equilibrium=a.equilibrium)
    if a.backend == "gl":  # a diagnostic: the CLI's one-line EGL error handling is app's (solver may not import it)
        import moderngl

        ctx = moderngl.create_context(standalone=True, backend="egl", require=330)
        factory = lambda c: create_solver("gl", c, ctx=ctx)  # noqa: E731
    else:
        factory = lambda c: create_solver("numpy", c)  # noqa: E731
    if a.impulsive:
        solver = geo.start(factory, **over)
    else:
        solver = geo.start_from_rest(factory, round(a.ramp_periods * geo.acoustic_period()), **over)
    steps = int(a.conv_times * a.d / geo.u_mean)
    t, cd, cl, cd_stress, cl_stress, n = [], [], [], [], [], 0
    pressure = create_model("pressure") if a.stress else None
    while n < steps:
        solver.step(a.sample)
        n += a.sample
        c = geo.coefficients(solver.forces()["momentum_exchange"])
        t.append(n - a.sample / 2)
        cd.append(c[0])
        cl.append(c[1])
        if pressure is not None:
            window = solver.body_window()
            p_, v_ = pressure.compute(window), viscous_force(window)
            c_stress = geo.coefficients((p_[0] + v_[0], p_[1] + v_[1]))
            cd_stress.append(c_stress[0])
            cl_stress.append(c_stress[1])
    solver.close()
    extra = {"cd_stress": np.array(cd_stress), "cl_stress": np.array(cl_stress)} if a.stress else {}
    from feelflow.app.files import atomic_path

    with atomic_path(a.out, suffix=".npz") as tmp:
        np.savez(tmp, t=np.array(t), cd=np.array(cd), cl=np.array(cl), d=a.d, u_mean=geo.u_mean, **extra)


def analyse(path: str, periods: int = 3) -> None:
    z = np.load(path)
    t, cd, cl, d, um = z["t"], z["cd"], z["cl"], int(z["d"]), float(z["u_mean"])
    ups = upward_zero_crossings(t, cl)
    k0 = len(ups) - 1 - periods
    T = (ups[-1] - ups[k0]) / periods
    w = (t >= ups[k0]) & (t < ups[-1])
    phase = np.linspace(0, 1, 600, endpoint=False)
    fold_cd = np.mean([np.interp(ups[k0] + (j + phase) * T, t, cd) for j in range(periods)], axis=0)
    fold_cl = np.mean([np.interp(ups[k0] + (j + phase) * T, t, cl) for j in range(periods)], axis=0)
    resid = cd[w] - np.interp(((t[w] - ups[k0]) / T) % 1, phase, fold_cd, period=1)
    per_max = [cd[(t >= a) & (t < b)].max() for a, b in zip(ups[k0:-1], ups[k0 + 1:])]
    print(f"{path}: D {d}, {t[-1]:.0f} steps, St {d / T / um:.4f}, periods {np.round(np.diff(ups[k0:]), 1)}")
    print(f"  C_D max per period {np.round(per_max, 4)}, mean {cd[w].mean():.4f}")
    if "cd_stress" in z:
        print(f"  mean C_D from pressure + viscous stress integration {z['cd_stress'][w].mean():.4f} "
              f"(momentum exchange {cd[w].mean():.4f})")
    if "cl_stress" in z:
        print(f"  C_D,max / C_L,max from pressure + viscous stress {z['cd_stress'][w].max():.4f} / "
              f"{z['cl_stress'][w].max():.4f} (sampled at block ends)")
    print(f"  raw: C_D,max {cd[w].max():.5f} C_L,max {cl[w].max():.5f} C_L,min {cl[w].min():.5f}; "
          f"period-averaged: "
          f"C_D,max {fold_cd.max():.4f} C_L,max {fold_cl.max():.4f}; rms of C_D around it {resid.std():.4f}")
    k0 = max(0, len(ups) - 9)  # spectrum over up to 8 periods
    w = (t >= ups[k0]) & (t < ups[-1])
    x = cd[w] - cd[w].mean()
    amp = np.abs(np.fft.rfft(x)) * 2 / len(x)
    freq = np.fft.rfftfreq(len(x), t[1] - t[0]) * T
    top = sorted(np.argsort(amp)[::-1][:8])
    print("  C_D lines (f / f_shedding: amplitude):", ", ".join(f"{freq[i]:.2f}: {amp[i]:.4f}" for i in top))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("record")
    r.add_argument("--d", type=int, default=20)
    r.add_argument("--u", type=float, default=0.075)
    r.add_argument("--ramp-periods", type=float, default=2.0)
    r.add_argument("--impulsive", action="store_true", help="developed channel flow at t = 0 (the old start)")
    r.add_argument("--sponge", type=int, default=0)
    r.add_argument("--absorb", type=float, default=0.0,
                   help="with --sponge: its absorbing layer's strength (FlowConfig.sponge_absorb)")
    r.add_argument("--length-d", type=float, default=22.0)
    r.add_argument("--conv-times", type=float, default=60.0)
    r.add_argument("--sample", type=int, default=2)
    r.add_argument("--collision", choices=("trt", "bgk"), default="trt")
    r.add_argument("--magic", type=float, default=3.0 / 16.0, help="TRT magic parameter Lambda")
    r.add_argument("--equilibrium", choices=EQUILIBRIA, default="compressible",
                   help="FlowConfig.equilibrium: incompressible is He & Luo 1997")
    r.add_argument("--stress", action="store_true",
                   help="also record C_D from pressure + viscous stress integration (slower)")
    r.add_argument("--backend", choices=("numpy", "gl"), default="numpy")
    r.add_argument("--out", required=True)
    an = sub.add_parser("analyse")
    an.add_argument("paths", nargs="+")
    a = p.parse_args()
    if a.cmd == "record":
        from feelflow.solver.validation.schaefer_turek import check_resolution

        try:
            check_resolution(a.d)
        except ValueError as exc:
            p.error(f"--d: {exc}")
        from feelflow.app.errors import UserError
        from feelflow.app.files import check_output

        try:   # before the run: never a device, never an existing file (the output policy)
            check_output(a.out, "--out")
        except UserError as exc:
            p.error(str(exc))
        record(a)
    else:
        for path in a.paths:
            analyse(path)


if __name__ == "__main__":
    main()
