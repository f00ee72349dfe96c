"""How the gl backend stores the populations: two nodes per texel in five RGBA32F textures.

Texel (k, y) holds nodes a = (2k, y) and b = (2k + 1, y). `LAYOUT[t]` lists the four channels
of texture t, each as (direction, node) with node 0 for a and 1 for b:

    G0 (g0a g1a g0b g3b)  G1 (g2a g5a g2b g6b)  G2 (g4a g8a g4b g7b)
    G3 (g1b g3a g5b g6a)  G4 (g8b g7a  -   - )

The streaming step pulls g_i(x - c_i). A fragment updates both nodes of its texel k, and the
nine texels it needs, (k - 1 .. k + 1, y - 1 .. y + 1), are each fetched once
(shaders/lbm_step.glsl, stream_pair):
- G0, G1, G2 at the texel k of rows y, y - 1, y + 1 hold everything that stays in the texel's
  column pair: the rest populations and, per row offset, what moves straight, what node a
  sends to node b (east-going, c_x = +1) and what node b sends to node a (west-going);
- G3 and G4 hold what crosses into the next texel: node b's east-going populations (fetched
  from texel k - 1) and node a's west-going ones (fetched from texel k + 1); G3 for rows y and
  y - 1, G4 for row y + 1.
(A layout that kept each direction's a and b side by side needed 12.)
`shaders/paired_layout.glsl` holds the same table for the shaders (a test compares them). An
odd nx leaves node b of the last texel column unused (kept at zero, rest). G4's channels 2, 3
hold no population: zero, except over the body window, where the step's pass keeps the running
total of the momentum exchange's link sums (shaders/lbm_step.glsl, LINK_SUMS), and channel 2 of
texel column 0, which holds the quiet inlet's reference density (solver/quiet_inlet.py);
`unpack` ignores them.
"""
from __future__ import annotations

import numpy as np

from feelflow.solver.lattice import Q

A, B = 0, 1
#: texture t -> its four channels, each (direction, node A or B), or None (no population)
LAYOUT = (
    ((0, A), (1, A), (0, B), (3, B)),
    ((2, A), (5, A), (2, B), (6, B)),
    ((4, A), (8, A), (4, B), (7, B)),
    ((1, B), (3, A), (5, B), (6, A)),
    ((8, B), (7, A), None, None),
)
TEXTURES = len(LAYOUT)
#: texture units, fixed for every pass (each binds all it samples before drawing): the population
#: textures G0..G4, the body's node mask and link fractions, the inflow profile, the per-column
#: rates of the sponge, the link sums' list of texels
UNIT_G = tuple(range(TEXTURES))
UNIT_MASK, UNIT_QA, UNIT_QB, UNIT_INFLOW, UNIT_OMEGA, UNIT_LINKS = 5, 6, 7, 8, 9, 10
#: sampler uniforms of the population textures
G_NAMES = tuple(f"G{t}" for t in range(TEXTURES))


def slots() -> list[tuple[int, int, int, int]]:
    """Per direction i: (texture of node a, its channel, texture of node b, its channel)."""
    where = {}
    for t, channels in enumerate(LAYOUT):
        for c, entry in enumerate(channels):
            if entry is not None:
                where[entry] = (t, c)
    return [where[(i, A)] + where[(i, B)] for i in range(Q)]


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
    for channels in LAYOUT:
        t = np.zeros((h, texels(w), 4), np.float32)
        for c, entry in enumerate(channels):
            if entry is not None:
                i, node = entry
                t[:, :, c] = padded[i, :, node::2]
        out.append(t)
    return out


def unpack(textures) -> np.ndarray:
    """The five texture arrays (h, k, 4) -> node populations g (9, h, 2k), float32."""
    h, k, _ = textures[0].shape
    g = np.zeros((Q, h, 2 * k), np.float32)
    for t, channels in zip(textures, LAYOUT):
        for c, entry in enumerate(channels):
            if entry is not None:
                i, node = entry
                g[i, :, node::2] = t[:, :, c]
    return g
