"""How the gl backend stores the populations: two nodes per texel in five RGBA32F textures.

Texel (k, y) holds nodes a = (2k, y) and b = (2k + 1, y); `PAIRED_LAYOUT[t]` lists the two
directions of texture t, channels (i_a, i_b, j_a, j_b):

    G0 (g1a g1b g3a g3b)  G1 (g5a g5b g6a g6b)  G2 (g7a g7b g8a g8b)  G3 (g2a g2b g4a g4b)
    G4 (g0a g0b  -   - )

Directions with the same row offset share a texture, so one fragment streams both of its nodes
with 12 texel fetches instead of 18 and writes 5 texels instead of 6 (docs/performance.md;
`shaders/paired_layout.glsl` is the same table for the shaders). An odd nx leaves node b of the
last texel column unused (kept at zero, rest). G4's channels 2, 3 hold no population: zero,
except over the body window, where the step's pass keeps the running total of the momentum
exchange's link sums (shaders/lbm_step.glsl, LINK_SUMS; `unpack` ignores them).
"""
from __future__ import annotations

import numpy as np

from solver.lattice import Q

#: texture t -> (direction in channels 0, 1; direction in channels 2, 3 or None)
PAIRED_LAYOUT = ((1, 3), (5, 6), (7, 8), (2, 4), (0, None))
TEXTURES = len(PAIRED_LAYOUT)


def texels(nodes: int) -> int:
    """Texel columns that hold `nodes` node columns."""
    return (nodes + 1) // 2


def texel_box(box):
    """The texel box (k0, y0, k1, y1) holding the node box (x0, y0, x1, y1)."""
    x0, y0, x1, y1 = box
    return x0 // 2, y0, texels(x1), y1


def pack(g: np.ndarray) -> list[np.ndarray]:
    """Node populations g (9, h, w) starting at an even node column -> the five texture
    arrays (h, ceil(w / 2), 4), float32 (a missing last b node is zero)."""
    q, h, w = g.shape
    assert q == Q
    padded = np.zeros((Q, h, 2 * texels(w)), np.float32)
    padded[:, :, :w] = g
    out = []
    for pair in PAIRED_LAYOUT:
        t = np.zeros((h, texels(w), 4), np.float32)
        for slot, i in enumerate(pair):
            if i is not None:
                t[:, :, 2 * slot] = padded[i, :, 0::2]
                t[:, :, 2 * slot + 1] = padded[i, :, 1::2]
        out.append(t)
    return out


def unpack(textures) -> np.ndarray:
    """The five texture arrays (h, k, 4) -> node populations g (9, h, 2k), float32."""
    h, k, _ = textures[0].shape
    g = np.zeros((Q, h, 2 * k), np.float32)
    for t, pair in zip(textures, PAIRED_LAYOUT):
        for slot, i in enumerate(pair):
            if i is not None:
                g[i, :, 0::2] = t[:, :, 2 * slot]
                g[i, :, 1::2] = t[:, :, 2 * slot + 1]
    return g
