"""The step's regions (solver/gl_regions.py): every texel is drawn by exactly one variant
beneath the body window, the rectangles are aligned to the rasteriser's 4x4 blocks, and the
body window's variant covers the whole window."""
from __future__ import annotations

import numpy as np
import pytest

from feelflow.solver.gl_regions import ALIGN, regions


def _coverage(parts, kx, ny):
    count = np.zeros((ny, kx), int)
    for key, rects in parts.items():
        if key[0]:  # the body window is drawn over the others
            continue
        for x0, y0, x1, y1 in rects:
            count[y0:y1, x0:x1] += 1
    return count


@pytest.mark.parametrize("kx, ny, window, sponge_from, wraps_free", [
    (64, 64, None, None, False),
    (64, 64, (10, 20, 17, 29), None, False),
    (129, 75, (1, 1, 9, 9), 112, False),        # odd sizes, window on the edge strip, a sponge
    (64, 32, (30, 5, 41, 14), None, True),      # periodic box: no edge strips
    (3, 3, (0, 0, 2, 2), None, False),          # too small for strips: one variant with every rule
])
def test_regions_tile_the_grid_once_and_cover_the_body_window(kx, ny, window, sponge_from, wraps_free):
    parts = regions(kx, ny, window, sponge_from, wraps_free)
    if (kx - 1) // ALIGN * ALIGN <= ALIGN:
        assert parts == {(1, 1, 0): [(0, 0, kx, ny)]}
        return
    assert np.all(_coverage(parts, kx, ny) == 1)
    for key, rects in parts.items():
        for x0, y0, x1, y1 in rects:  # aligned, except where the grid ends
            assert x0 % ALIGN == 0 and y0 % ALIGN == 0
            assert (x1 % ALIGN == 0 or x1 == kx) and (y1 % ALIGN == 0 or y1 == ny)
            if key == (0, 0, 1):  # the interior's sponge variant only from the sponge's first column on
                assert x0 >= sponge_from
    body = [r for key, rects in parts.items() if key[0] for r in rects]
    if window is None:
        assert not body
    else:
        (x0, y0, x1, y1), = body
        assert x0 <= window[0] and y0 <= window[1] and x1 >= window[2] and y1 >= window[3]
        edges = any(key[0] and key[1] for key in parts)
        on_edge = window[0] < ALIGN or window[1] < ALIGN
        assert edges == (on_edge and not wraps_free)
