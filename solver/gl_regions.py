"""Which variant of the step shader (shaders/lbm_step.glsl) draws which part of the grid.

A software rasteriser such as llvmpipe shades 4x4 pixel blocks as SIMD lanes and executes both
sides of a branch whose condition differs within a block, so one program with every boundary
rule would charge each node the cost of the most expensive rule. The step is drawn instead as
rectangles, each with the compile-time variant (BODY, EDGES, SPONGE) it needs:
- the interior: plain streaming and collision (rule f of the algorithm), the fast path;
- edge strips ALIGN texels wide: channel walls (half-way bounce-back or specular reflection),
  the velocity inlet, the pressure outlet and the periodic wrap;
- the outlet sponge's columns: per-column relaxation rates (solver/sponge.py);
- the body window: Bouzidi, Firdaouss & Lallemand (2001) links with the moving-wall term, and
  the solid nodes.
Rectangles are aligned to the 4x4 blocks (a partly covered block runs the whole shader). The
body window is drawn last, over the fast path or edge strip beneath it (its variant writes every
texel it covers), so the other regions stay the same while the body moves. Each rectangle is
drawn as one triangle over the whole texture clipped by a scissor box (`cover_triangle`): two
triangles per rectangle would shade the 4x4 blocks along their shared diagonal twice.
"""
from __future__ import annotations

import numpy as np

from feelflow.solver.gl_programs import triangles

#: region rectangles are aligned to llvmpipe's 4x4 shading blocks
ALIGN = 4


def _aligned(window, kx: int, ny: int):
    """The texel box `window` grown outwards to ALIGN, clipped to the grid."""
    a = ALIGN
    return (window[0] // a * a, window[1] // a * a, min(kx, -(-window[2] // a) * a),
            min(ny, -(-window[3] // a) * a))


def regions(kx: int, ny: int, window=None, sponge_from: int | None = None,
            wraps_free: bool = False) -> dict:
    """{(body, edges, sponge): [rectangles (x0, y0, x1, y1)]} in texels of a grid `kx` texels
    wide and `ny` high.

    window: the body window's texel box, or None; sponge_from: the first texel column of the
    sponge (aligned down), or None without a sponge; wraps_free: both directions periodic and
    the REPEAT samplers wrap exactly (an even nx), so the fast path needs no edge strips.
    A grid too small for strips is drawn by one variant with every rule.
    """
    a = ALIGN
    sp = int(sponge_from is not None)
    x1, y1 = (kx - 1) // a * a, (ny - 1) // a * a
    has_window = window is not None and window[0] < window[2] and window[1] < window[3]
    if x1 <= a or y1 <= a:
        return {(1, 1, sp): [(0, 0, kx, ny)]}
    if wraps_free:
        parts = {(0, 0, 0): [(0, 0, kx, ny)]}
        if has_window:
            parts[(1, 0, 0)] = [_aligned(window, kx, ny)]
        return parts
    interior = (a, a, x1, y1)
    edges = [(0, 0, kx, a), (0, y1, kx, ny), (0, a, a, y1), (x1, a, kx, y1)]
    parts = {(0, 0, 0): [interior], (0, 1, sp): edges}
    if has_window:
        w = _aligned(window, kx, ny)
        inside = w[0] >= a and w[1] >= a and w[2] <= x1 and w[3] <= y1
        parts[(1, 0, sp) if inside else (1, 1, sp)] = [w]
    if sp:  # the interior's sponge columns get the variant with per-column rates
        plain, sponge = [], []
        for r in parts[(0, 0, 0)]:
            if r[0] < sponge_from:
                plain.append((r[0], r[1], min(r[2], sponge_from), r[3]))
            if r[2] > sponge_from:
                sponge.append((max(r[0], sponge_from), r[1], r[2], r[3]))
        parts[(0, 0, 0)], parts[(0, 0, 1)] = plain, sponge
    return {k: v for k, v in parts.items() if v}


def cover_triangle(width: int, height: int) -> np.ndarray:
    """One triangle (3, 2) covering a texture of width x height texels; a scissor box cuts a
    region's rectangle out of it, so every 4x4 block inside is covered by one primitive."""
    return triangles([(0, 0, 2 * width, 2 * height)])[[0, 1, 5]]
