"""Body links across a periodic seam (solver/bouzidi.py `build_links`, `periodic_wrap`)."""
import numpy as np

from feelflow.solver.bouzidi import build_links, periodic_wrap
from feelflow.solver.config import FlowConfig


def _wall_window(w=6, h=5, q_cut=0.3):
    """A window of w columns: row 0 solid, row 1 fluid with every downward link cut at q."""
    solid = np.zeros((h, w), bool)
    solid[0] = True
    q = np.zeros((9, h, w))
    for ib in (4, 7, 8):    # (0,-1), (-1,-1), (1,-1): from row 1 towards row 0
        q[ib, 1] = q_cut
    return q, solid


def test_the_second_node_wraps_only_where_the_window_spans_a_periodic_direction():
    q, solid = _wall_window()
    periodic = FlowConfig(nx=6, ny=20, x_boundary="periodic", y_boundary="no_slip")
    assert periodic_wrap(periodic, (0, 0, 6, 5)) == (True, False)
    assert periodic_wrap(periodic, (1, 0, 6, 5)) == (False, False)   # does not span the width
    tunnel = FlowConfig(nx=6, ny=20)
    assert periodic_wrap(tunnel, (0, 0, 6, 5)) == (False, False)

    wrapped = build_links(q, solid, 0, 0, (0.0, 0.0), (0.0, 0.0), 0.0, wrap=(True, False))
    plain = build_links(q, solid, 0, 0, (0.0, 0.0), (0.0, 0.0), 0.0)
    assert len(wrapped) == len(plain) == 3 * 6
    # q = 0.3 < 1/2: every link takes the two-node rule once the seam wraps
    assert np.all(wrapped.b != 0) and np.allclose(wrapped.a, 0.6) and np.allclose(wrapped.b, 0.4)
    # ... and the second node of the diagonal links at the edge columns is at the other edge
    edge = (wrapped.ix == 5) & (wrapped.i == 5)   # incoming along (1, 1) at the last column
    assert edge.sum() == 1 and wrapped.fx[edge][0] == 0 and wrapped.fy[edge][0] == 2
    # without the wrap those two links fall back to half-way bounce-back
    half_way = plain.b == 0
    assert half_way.sum() == 2 and set(plain.ix[half_way]) == {0, 5}
