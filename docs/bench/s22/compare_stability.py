"""Compare two `feelflow validate --json` runs' stability maps point by point (twenty-second
session, README 'Validation'): the state of every (scene, collision, size, U, nu) point, the
limits, and how far the stable points' max |u| differ.

    python docs/bench/s22/compare_stability.py A.json B.json
"""
import json
import sys


def stability(path):
    for case in json.load(open(path))["cases"]:
        if case["name"] == "stability":
            return case
    raise SystemExit(f"{path}: no stability case")


a, b = (stability(p) for p in sys.argv[1:3])
key = lambda p: (p["scene"], p["collision"], p["size"], p["u"], p["nu"])  # noqa: E731
pa = {key(p): p for p in a["details"]["points"]}
pb = {key(p): p for p in b["details"]["points"]}
same_points = set(pa) == set(pb)
print(f"points: {len(pa)} and {len(pb)}, the same set: {same_points}")
if same_points:
    states = [k for k in pa if pa[k]["state"] != pb[k]["state"]]
    print(f"points in a different state: {len(states)}", *states[:10])
    du = [abs(pa[k]["max_u"] - pb[k]["max_u"]) for k in pa if pa[k]["state"] == pb[k]["state"] == "stable"]
    print(f"stable points' max |u|: largest difference {max(du):.2e}")
limits = {k for k in set(a["quantities"]) | set(b["quantities"]) if k.startswith("re_cell") or k.startswith("guarded")}
differ = sorted(k for k in limits if a["quantities"].get(k) != b["quantities"].get(k))
print(f"limits and guarded counts that differ: {len(differ)}", *differ)
