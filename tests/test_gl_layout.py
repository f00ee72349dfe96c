"""The gl backend's texture layout (solver/gl_layout.py): two nodes per texel, packed and
unpacked without loss, for even and odd widths, and the same table as the shaders'."""
import re

import numpy as np
import pytest

from solver.gl_layout import PAIRED_LAYOUT, TEXTURES, pack, texel_box, texels, unpack
from solver.gl_programs import SHADER_DIR


@pytest.mark.parametrize("w", [1, 6, 7])
def test_pack_unpack_round_trip(w):
    g = np.random.default_rng(1).standard_normal((9, 3, w)).astype(np.float32)
    t = pack(g)
    assert len(t) == TEXTURES and t[0].shape == (3, texels(w), 4)
    back = unpack(t)
    assert np.array_equal(back[:, :, :w], g)
    assert not back[:, :, w:].any()  # the unused b node of an odd width is zero


def test_every_direction_has_one_slot():
    dirs = [i for pair in PAIRED_LAYOUT for i in pair if i is not None]
    assert sorted(dirs) == list(range(9))


def test_texel_box():
    assert texel_box((3, 1, 8, 5)) == (1, 1, 4, 5)
    assert texel_box((4, 0, 9, 2)) == (2, 0, 5, 2)


def test_shader_table_matches():
    """SLOT in shaders/paired_layout.glsl: (texture, channel of node a) of every direction."""
    text = (SHADER_DIR / "paired_layout.glsl").read_text()
    body = text[text.index("const ivec2 SLOT[9]"):]
    body = body[:body.index(";")]
    slots = [tuple(map(int, m)) for m in re.findall(r"ivec2\((\d+), (\d+)\)", body)]
    expected = [None] * 9
    for t, pair in enumerate(PAIRED_LAYOUT):
        for slot, i in enumerate(pair):
            if i is not None:
                expected[i] = (t, 2 * slot)
    assert slots == expected
