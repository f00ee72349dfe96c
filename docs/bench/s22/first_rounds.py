"""The first round of each `feelflow bench` run against its other two (twenty-second session,
docs/performance.md): for the moving tunnel at 512x256, numpy's first-round MLUPS against the
mean of its rounds 2 and 3, and gl / numpy as the run's median and as the mean of rounds 2 and 3.

    python docs/bench/s22/first_rounds.py docs/bench/s13/solver-after-*.json docs/bench/s19/solver-*.json ...
"""
import json
import sys

for path in sys.argv[1:]:
    data = json.load(open(path))
    ratios = data["speedups_per_round"]["tunnel 512x256"]
    numpy = next(r["rounds_mlups"] for r in data["results"]
                 if r["scene"] == "tunnel" and r["grid"] == "512x256" and r["backend"] == "numpy")
    rest = sum(numpy[1:3]) / 2
    print(f"{path}: numpy first round {numpy[0]:.2f} against {rest:.2f} ({100 * (numpy[0] / rest - 1):+.1f} %); "
          f"gl / numpy median {data['speedups']['tunnel 512x256']:.2f}, rounds 2 and 3 {sum(ratios[1:3]) / 2:.3f}")
