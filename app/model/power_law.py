"""How drag grows with speed: the exponent n of F ~ U^n from a run's (relative speed, drag)
samples. The U^2 lesson measures it instead of assuming it (F ~ U at creeping flow, U^2 at high
Re: White, *Fluid Mechanics*, ch. 7, drag of immersed bodies)."""
from __future__ import annotations

import numpy as np


def fit_power_law(speed, drag, bins: int = 12):
    """Bin |drag| by relative speed (log bins), fit log F = n log U + c. Returns
    (bin speeds, bin drags, exponent n or None when the speeds do not span a factor 1.5)."""
    speed, drag = np.asarray(speed, float), np.asarray(drag, float)
    ok = np.isfinite(speed) & np.isfinite(drag) & (speed > 1e-4) & (drag > 0)
    speed, drag = speed[ok], drag[ok]
    if len(speed) < 3:
        return np.array([]), np.array([]), None
    if speed.max() < speed.min() * 1.01:     # one speed so far: one point
        return np.array([speed.mean()]), np.array([drag.mean()]), None
    edges = np.geomspace(speed.min(), speed.max() * 1.0001, bins + 1)
    idx = np.digitize(speed, edges) - 1
    us, fs = [], []
    for k in range(bins):
        sel = idx == k
        if sel.sum() >= 3:
            us.append(speed[sel].mean())
            fs.append(drag[sel].mean())
    us, fs = np.array(us), np.array(fs)
    if len(us) < 3 or us.max() / us.min() < 1.5:
        return us, fs, None
    n, _ = np.polyfit(np.log(us), np.log(fs), 1)
    return us, fs, float(n)
