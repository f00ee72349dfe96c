"""The gl backend's texture layout (solver/gl_layout.py): two nodes per texel, packed and
unpacked without loss, for even and odd widths, and the same table as the shaders'."""
import re

import numpy as np
import pytest

from feelflow.solver.gl_layout import LAYOUT, TEXTURES, pack, slots, texel_box, texels, unpack
from feelflow.solver.gl_programs import SHADER_DIR


@pytest.mark.parametrize("w", [1, 6, 7])
def test_pack_unpack_round_trip(w):
    g = np.random.default_rng(1).standard_normal((9, 3, w)).astype(np.float32)
    t = pack(g)
    assert len(t) == TEXTURES and t[0].shape == (3, texels(w), 4)
    back = unpack(t)
    assert np.array_equal(back[:, :, :w], g)
    assert not back[:, :, w:].any()  # the unused b node of an odd width is zero


def test_every_population_has_one_channel():
    entries = [e for channels in LAYOUT for e in channels if e is not None]
    assert sorted(entries) == [(i, node) for i in range(9) for node in (0, 1)]


def test_streaming_fetches_each_neighbour_texel_once():
    """What stream_pair (shaders/lbm_step.glsl) relies on: the populations that reach the two
    nodes of texel k from texel k + dk (dk = -1, 0, 1) of row y - c_y lie in one texture, which
    holds nothing a neighbour in another column needs (nine fetches for two nodes)."""
    from feelflow.solver.lattice import C

    source = {}  # (texture, channel) -> texel offset (dk, dy) it is fetched from
    for i in range(9):
        for node in (0, 1):
            x = node - C[i][0]          # the source node's column, relative to node a's
            dk, src = divmod(x, 2)      # its texel offset and which node of that texel
            source.setdefault(slots()[i][2 * src:2 * src + 2], set()).add((dk, -C[i][1]))
    by_texture = {}
    for (t, _), offsets in source.items():
        assert len(offsets) == 1  # a channel is read from one neighbour only
        by_texture.setdefault(t, set()).update(offsets)
    fetches = sum(len(offsets) for offsets in by_texture.values())
    assert fetches == 9
    assert set().union(*by_texture.values()) == {(dk, dy) for dk in (-1, 0, 1) for dy in (-1, 0, 1)}


def test_texel_box():
    assert texel_box((3, 1, 8, 5)) == (1, 1, 4, 5)
    assert texel_box((4, 0, 9, 2)) == (2, 0, 5, 2)


def test_shader_table_matches():
    """SLOT in shaders/paired_layout.glsl: (texture, channel) of node a, then of node b, of
    every direction, as solver/gl_layout.py's table."""
    text = (SHADER_DIR / "paired_layout.glsl").read_text()
    body = text[text.index("const ivec4 SLOT[9]"):]
    body = body[:body.index(";")]
    table = [tuple(map(int, m)) for m in re.findall(r"ivec4\((\d+), (\d+), (\d+), (\d+)\)", body)]
    assert table == slots()
