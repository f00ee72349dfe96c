"""A body move, compiled (numba), over the body's box: the raster of a cylinder or a polygonal
shape and the Bouzidi links with the moving-wall term (the cpu and gl backends), the equilibrium
refill and the node list of the step's boundary pass (the cpu backend).

The same arithmetic, in the same order, as the numpy reference it stands for, so the results are
equal bit for bit (tests/test_body_local_move.py): shapes/raster.py `rasterise` with
shapes/cylinder.py's `contains` and `segment_hit` (a circle's exact cut fractions, Bouzidi,
Firdaouss & Lallemand, Phys. Fluids 13 (2001) 3452) or shapes/polygon.py's edge tests,
solver/bouzidi.py `build_links` (the moving-wall term of Lallemand & Luo, J. Comput. Phys. 184
(2003) 406); solver/body.py `refill` (equilibrium scheme) to the storage's rounding. Compiled
without fastmath (no contraction into fused multiply-adds), so each operation rounds as numpy's
does. A towed body is placed before every step, so what numpy spends on calls over a few hundred
nodes would cost more than the compiled step itself (docs/science/force-models.md, 'What moving
costs'). The numpy backend, the reference, keeps its own readable code.
"""
from __future__ import annotations

import math

import numba
import numpy as np

from feelflow.shapes.base import BodyRaster
from feelflow.shapes.cylinder import GRAZE, Cylinder
from feelflow.shapes.polygon import BOUNDARY_TOLERANCE, EDGE_SLACK, PolygonalShape
from feelflow.solver.body import expand_box, union_box
from feelflow.solver.bouzidi import BodyLinks, periodic_wrap
from feelflow.solver.lattice import C, OPP, RHO0, W

_JIT = dict(cache=True, nogil=True, error_model="numpy")
_CXI = np.ascontiguousarray(C[:, 0])
_CYI = np.ascontiguousarray(C[:, 1])
_OPPI = OPP.astype(np.int64)
_WR = W * RHO0    # w_i RHO0, as build_links's W[i] * RHO0


@numba.njit(**_JIT)
def _cylinder_box(xc, yc, r, r2, graze, x0, y0, x1, y1):
    """(box_solid (h, w), box_q (9, h, w)) of a circle centred (xc, yc), radius r (r2 = r ** 2,
    graze = (GRAZE r) ** 2) over the box: shapes/raster.py `_generic_box` with the circle's
    `contains`, `boundary_distance` and `segment_hit`, then `_cut_every_link_into_solid`."""
    h, w = y1 - y0, x1 - x0
    solid = np.zeros((h, w), np.bool_)
    q = np.zeros((9, h, w))
    band = math.sqrt(2.0) + 1e-9
    for jy in range(h):
        ry = float(y0 + jy) - yc
        for jx in range(w):
            rx = float(x0 + jx) - xc
            solid[jy, jx] = rx * rx + ry * ry <= r2
    for jy in range(h):
        for jx in range(w):
            if solid[jy, jx]:
                continue
            ry = float(y0 + jy) - yc
            rx = float(x0 + jx) - xc
            if abs(math.hypot(rx, ry) - r) > band:
                continue
            c = rx * rx + ry * ry - r2
            for d in range(1, 9):
                dx, dy = float(_CXI[d]), float(_CYI[d])
                a = dx * dx + dy * dy
                half_b = rx * dx + ry * dy
                disc = half_b * half_b - a * c
                if not (half_b < 0.0 and disc > graze * a * a and c > 0.0):
                    continue
                t = c / (-half_b + math.sqrt(disc))
                if t > 0.0 and t <= 1.0:
                    q[d, jy, jx] = t
    _cut_every_link_into_solid(solid, q)
    return solid, q


@numba.njit(**_JIT)
def _cut_every_link_into_solid(solid, q):
    """shapes/raster.py `_cut_every_link_into_solid`: a fluid -> solid link always crosses the
    boundary; where round-off at a vertex lost the crossing, the wall is at the solid node."""
    h, w = solid.shape
    for jy in range(h):
        for jx in range(w):
            if solid[jy, jx]:
                continue
            for d in range(1, 9):
                ty, tx = jy + _CYI[d], jx + _CXI[d]
                if 0 <= ty < h and 0 <= tx < w and solid[ty, tx] and q[d, jy, jx] <= 0.0:
                    q[d, jy, jx] = 1.0


@numba.njit(**_JIT)
def _edge_distance(qx, qy, ax, ay, ex, ey):
    """shapes/polygon.py `edge_distance` of one point and one edge."""
    len2 = ex * ex + ey * ey
    wx, wy = qx - ax, qy - ay
    t = 0.0
    if len2 > 0.0:
        t = min(max((wx * ex + wy * ey) / len2, 0.0), 1.0)
    return math.hypot(wx - t * ex, wy - t * ey)


@numba.njit(**_JIT)
def _polygon_box(world, edges, x0, y0, x1, y1, tolerance, slack):
    """(box_solid, box_q) of a polygon (world vertices and edge vectors (n, 2)) over the box:
    shapes/raster.py `_polygon_box` (scanline parity for the interior; each edge, cut into pieces
    no longer than a cell, tested against the nodes of its 6 x 6 stencil; points within
    `tolerance` of an edge count as inside; a link's first crossing wins) and
    `_cut_every_link_into_solid`. Each (edge, node) pair is tested once: the pieces of an edge
    come one after the other, so a node remembers the last edge that tested it."""
    h, w = y1 - y0, x1 - x0
    n = world.shape[0]
    solid = np.zeros((h, w), np.bool_)
    counts = np.zeros(w + 1, np.int64)
    for r in range(h):       # interior: an odd number of crossings at x > node
        qy = float(y0 + r)
        for j in range(w + 1):
            counts[j] = 0
        for k in range(n):
            ax, ay, ex, ey = world[k, 0], world[k, 1], edges[k, 0], edges[k, 1]
            if (ay > qy) == ((ay + ey) > qy):
                continue
            xcross = ax + (qy - ay) * ex / ey
            last = min(max(int(math.ceil(xcross)) - 1 - x0, -1), w - 1)
            if last >= 0:
                counts[last] += 1
        parity = 0
        for j in range(w - 1, -1, -1):
            parity += counts[j]
            solid[r, j] = parity % 2 == 1
    band = math.sqrt(2.0) + 1e-9
    q = np.empty((9, h, w))
    seen = np.empty((h, w), np.int64)   # the last edge a node was tested against
    for jy in range(h):
        for jx in range(w):
            for d in range(9):
                q[d, jy, jx] = np.inf
    for sweep in range(2):   # 0: boundary points inside; 1: links of fluid nodes near an edge
        for jy in range(h):
            for jx in range(w):
                seen[jy, jx] = -1
        for k in range(n):
            ax, ay, ex, ey = world[k, 0], world[k, 1], edges[k, 0], edges[k, 1]
            length = math.hypot(ex, ey)
            if not length > 0.0:
                continue
            pieces = max(1, int(math.ceil(length / 1.0)))
            for p in range(pieces):
                frac = (p + 0.5) / pieces
                bx = int(math.floor(ax + frac * ex)) - x0
                by = int(math.floor(ay + frac * ey)) - y0
                for jy in range(by - 2, by + 4):
                    if jy < 0 or jy >= h:
                        continue
                    py = float(jy + y0)
                    for jx in range(bx - 2, bx + 4):
                        if jx < 0 or jx >= w or seen[jy, jx] == k:
                            continue
                        seen[jy, jx] = k
                        px = float(jx + x0)
                        dist = _edge_distance(px, py, ax, ay, ex, ey)
                        if sweep == 0:
                            if dist <= tolerance:
                                solid[jy, jx] = True
                            continue
                        if solid[jy, jx] or not dist <= band:
                            continue
                        for d in range(1, 9):
                            dx, dy = float(_CXI[d]), float(_CYI[d])
                            denom = dx * ey - dy * ex
                            if denom == 0.0:
                                continue
                            wx, wy = ax - px, ay - py
                            t = (wx * ey - wy * ex) / denom
                            s = (wx * dy - wy * dx) / denom
                            if t > 0.0 and t <= 1.0 + slack and s >= -slack and s <= 1.0 + slack:
                                q[d, jy, jx] = min(q[d, jy, jx], min(t, 1.0))
    for d in range(9):
        for jy in range(h):
            for jx in range(w):
                if q[d, jy, jx] == np.inf:
                    q[d, jy, jx] = 0.0
    _cut_every_link_into_solid(solid, q)
    return solid, q


@numba.njit(**_JIT)
def _raster_window(solid, q, x0, y0, nx, ny):
    """shapes/raster.py `_window` with margin 0: the half-open box of every solid node and both
    ends of every cut link."""
    h, w = solid.shape
    lo_x, lo_y, hi_x, hi_y = 1 << 60, 1 << 60, -(1 << 60), -(1 << 60)
    for jy in range(h):
        for jx in range(w):
            if solid[jy, jx]:
                lo_x, hi_x = min(lo_x, jx), max(hi_x, jx)
                lo_y, hi_y = min(lo_y, jy), max(hi_y, jy)
            for d in range(9):
                if q[d, jy, jx] != 0.0:
                    ex, ey = jx + _CXI[d], jy + _CYI[d]
                    lo_x, hi_x = min(lo_x, jx, ex), max(hi_x, jx, ex)
                    lo_y, hi_y = min(lo_y, jy, ey), max(hi_y, jy, ey)
    if hi_x < lo_x:
        return 0, 0, 0, 0
    return max(0, lo_x + x0), max(0, lo_y + y0), min(nx, hi_x + x0 + 1), min(ny, hi_y + y0 + 1)


def raster(shape, nx: int, ny: int) -> BodyRaster:
    """shapes/raster.py `rasterise(shape, nx, ny, 0)` of a `Cylinder` or a polygonal shape
    (`PolygonalShape`: polygon, plate, wedge, airfoils), compiled."""
    xmin, ymin, xmax, ymax = shape.bounding_box()
    x0, y0 = max(0, math.floor(xmin) - 1), max(0, math.floor(ymin) - 1)
    x1, y1 = min(nx, math.ceil(xmax) + 2), min(ny, math.ceil(ymax) + 2)
    if x0 >= x1 or y0 >= y1:
        return BodyRaster(np.zeros((0, 0), bool), np.zeros((9, 0, 0)), (0, 0, 0, 0), (nx, ny), (0, 0, 0, 0))
    if isinstance(shape, PolygonalShape):
        world, edges = shape.world_edges
        solid, q = _polygon_box(world, edges, x0, y0, x1, y1, BOUNDARY_TOLERANCE, EDGE_SLACK)
    else:
        r = shape.radius
        solid, q = _cylinder_box(float(shape.x), float(shape.y), r, r ** 2, (GRAZE * r) ** 2, x0, y0, x1, y1)
    window = tuple(int(v) for v in _raster_window(solid, q, x0, y0, nx, ny))
    return BodyRaster(solid, q, (x0, y0, x1, y1), (nx, ny), window)


def compiled_raster(shape):
    """`raster` where it has this shape's kind (a cylinder or a polygonal shape), else None."""
    return raster if type(shape) is Cylinder or isinstance(shape, PolygonalShape) else None


@numba.njit(**_JIT)
def _links(q, solid, x0, y0, xc, yc, vx, vy, omega, wrap_x, wrap_y):
    """The arrays of solid/bouzidi.py `build_links`, in its order (direction, row, column), as
    two: (i, ib, iy, ix, fy, fx) int64 (6, n) and (q, ux_w, uy_w, a, b, c, d) float64 (7, n)."""
    h, w = solid.shape
    n = 0
    for i in range(1, 9):
        ib = _OPPI[i]
        for iy in range(h):
            for ix in range(w):
                if q[ib, iy, ix] > 0.0 and not solid[iy, ix]:
                    n += 1
    ints = np.empty((6, n), np.int64)
    flts = np.empty((7, n))
    k = 0
    for i in range(1, 9):
        ib = _OPPI[i]
        cx, cy = _CXI[i], _CYI[i]
        for iy in range(h):
            for ix in range(w):
                if not (q[ib, iy, ix] > 0.0 and not solid[iy, ix]):
                    continue
                qq = q[ib, iy, ix]
                fy, fx = iy + cy, ix + cx
                if wrap_x:
                    fx = fx % w
                if wrap_y:
                    fy = fy % h
                second = (0 <= fy < h and 0 <= fx < w and not solid[fy, fx] and q[i, iy, ix] == 0.0)
                # wall velocity at the crossing x - q c_i (world coordinates)
                px = float(x0 + ix) - qq * float(cx)
                py = float(y0 + iy) - qq * float(cy)
                ux = vx - omega * (py - yc)
                uy = vy + omega * (px - xc)
                cu = _WR[i] * (float(cx) * ux + float(cy) * uy)
                if qq < 0.5 and second:   # 2q f*_ib(x) + (1-2q) f*_ib(xf) + 6 w (c.u_w)
                    a, b, c, d = 2 * qq, 1 - 2 * qq, 0.0, 6.0 * cu
                elif qq < 0.5:            # half-way: f*_ib(x) + 6 w (c.u_w)
                    a, b, c, d = 1.0, 0.0, 0.0, 6.0 * cu
                    fy, fx = iy, ix
                else:                     # 1/(2q) f*_ib(x) + (2q-1)/(2q) f*_i(x) + 3/q w (c.u_w)
                    a, b, c, d = 0.5 / qq, 0.0, (2 * qq - 1) / (2 * qq), (3.0 / qq) * cu
                    fy, fx = iy, ix
                ints[0, k], ints[1, k], ints[2, k], ints[3, k], ints[4, k], ints[5, k] = i, ib, iy, ix, fy, fx
                flts[0, k], flts[1, k], flts[2, k] = qq, ux, uy
                flts[3, k], flts[4, k], flts[5, k], flts[6, k] = a, b, c, d
                k += 1
    return ints, flts


def build_links(q, solid, x0: int, y0: int, center, velocity, omega, wrap=(False, False)) -> BodyLinks:
    """solver/bouzidi.py `build_links`, compiled (uw: a transposed view of the float rows)."""
    ints, flts = _links(q, solid, int(x0), int(y0), float(center[0]), float(center[1]), float(velocity[0]),
                        float(velocity[1]), float(omega), bool(wrap[0]), bool(wrap[1]))
    return BodyLinks(ints[0], ints[1], ints[2], ints[3], ints[4], ints[5], flts[0], flts[1:3].T,
                     flts[3], flts[4], flts[5], flts[6])


#: the momentum-booking schemes of solver/body.py IMPULSE_SCHEMES as the kernel's codes
IMPULSE_CODES = {"relative": 0, "absolute": 1, "none": 2}


@numba.njit(**_JIT)
def _feq(rho, ux, uy, out, iy, ix):
    """solver/lattice.py `equilibrium` (second order, compressible) of one node into out[:, iy, ix]."""
    usq = 1.5 * (ux * ux + uy * uy)
    for i in range(9):
        cu = 3.0 * (float(_CXI[i]) * ux + float(_CYI[i]) * uy)
        out[i, iy, ix] = _W9[i] * rho * (1.0 + cu + 0.5 * cu * cu - usq)


_W9 = W.copy()


@numba.njit(**_JIT)
def _refill(g, x0, y0, old, new, xc, yc, vx, vy, omega, wrap_x, wrap_y, impulse):
    """solver/body.py `refill` with the equilibrium scheme, on the window (x0, y0) + old.shape of
    the shifted state g (9, ny, nx), in place: cover, uncover (f^eq at the mean density of the
    fluid neighbours and u_body), f^eq(RHO0, u_body) on every solid node, the mass this makes or
    removes put back on the fluid ring around the body. `impulse` 0 relative, 1 absolute, 2 none.
    Returns the impulse (Jx, Jy)."""
    h, w = old.shape
    f = np.empty((9, h, w))
    for i in range(9):
        for y in range(h):
            for x in range(w):
                f[i, y, x] = np.float64(g[i, y0 + y, x0 + x]) + _WR[i]
    changed = np.zeros((h, w), np.bool_)
    n_cov = n_unc = 0
    for y in range(h):
        for x in range(w):
            n_cov += new[y, x] and not old[y, x]
            n_unc += old[y, x] and not new[y, x]
    jx = jy = 0.0
    lost = 0.0
    if n_cov + n_unc > 0:
        for y in range(h):          # covered nodes give their momentum to the body
            for x in range(w):
                if not (new[y, x] and not old[y, x]):
                    continue
                rho = 0.0
                for i in range(9):
                    fi = f[i, y, x]
                    jx += _CXI[i] * fi
                    jy += _CYI[i] * fi
                    rho += fi
                lost += rho - RHO0
                if impulse == 0:
                    jx -= rho * (vx - omega * (float(y0 + y) - yc))
                    jy -= rho * (vy + omega * (float(x0 + x) - xc))
        rho_new = np.empty((h, w))
        for y in range(h):          # uncovered nodes: the mean density of their donor neighbours
            for x in range(w):
                if not (old[y, x] and not new[y, x]):
                    continue
                rsum = cnt = 0.0
                for k in range(1, 9):
                    yy, xx = y + _CYI[k], x + _CXI[k]
                    if wrap_x:
                        xx %= w
                    if wrap_y:
                        yy %= h
                    if not (0 <= yy < h and 0 <= xx < w) or new[yy, xx] or (old[yy, xx] and not new[yy, xx]):
                        continue
                    r = f[0, yy, xx]
                    for i in range(1, 9):
                        r += f[i, yy, xx]
                    rsum += r
                    cnt += 1.0
                rn = rsum / max(cnt, 1.0) if cnt > 0 else RHO0
                rho_new[y, x] = rn
                lost += RHO0 - rn
                if impulse == 1:
                    jx -= rn * (vx - omega * (float(y0 + y) - yc))
                    jy -= rn * (vy + omega * (float(x0 + x) - xc))
    for y in range(h):              # solid nodes at RHO0, uncovered ones at rho_new, both at u_body
        for x in range(w):
            if new[y, x] or (old[y, x] and n_cov + n_unc > 0):
                rho = RHO0 if new[y, x] else rho_new[y, x]
                _feq(rho, vx - omega * (float(y0 + y) - yc), vy + omega * (float(x0 + x) - xc), f, y, x)
                changed[y, x] = True
    if n_cov + n_unc > 0:
        ring = np.zeros((h, w), np.bool_)
        n_ring = 0
        for y in range(h):          # fluid nodes next to an old or new solid node
            for x in range(w):
                if new[y, x]:
                    continue
                for k in range(1, 9):
                    yy, xx = y + _CYI[k], x + _CXI[k]
                    if wrap_x:
                        xx %= w
                    if wrap_y:
                        yy %= h
                    if 0 <= yy < h and 0 <= xx < w and (new[yy, xx] or old[yy, xx]):
                        ring[y, x] = True
                        n_ring += 1
                        break
        if lost != 0.0 and n_ring > 0:
            per = lost / n_ring
            for y in range(h):
                for x in range(w):
                    if not ring[y, x]:
                        continue
                    rho = f[0, y, x]
                    for i in range(1, 9):
                        rho += f[i, y, x]
                    scale = 1.0 + per / rho
                    dm = 0.0
                    for i in range(9):
                        fi = f[i, y, x]
                        added = fi * (scale - 1.0)
                        f[i, y, x] = fi + added
                        jx -= _CXI[i] * added
                        jy -= _CYI[i] * added
                        dm += added
                    if impulse == 0:
                        jx += dm * (vx - omega * (float(y0 + y) - yc))
                        jy += dm * (vy + omega * (float(x0 + x) - xc))
                    changed[y, x] = True
        else:
            for y in range(h):
                for x in range(w):
                    changed[y, x] |= ring[y, x]
    for y in range(h):
        for x in range(w):
            if changed[y, x]:
                for i in range(9):
                    g[i, y0 + y, x0 + x] = f[i, y, x] - _WR[i]
    if impulse == 2:
        return 0.0, 0.0
    return jx, jy


def move_body(old, new, config, g, impulse: str) -> tuple[float, float]:
    """solver/body.py `move_body` with the equilibrium refill, on the shifted state g (9, ny, nx)
    in place, compiled. Returns the impulse (Jx, Jy)."""
    box = union_box(old.raster.window if old else None, new.raster.window if new else None)
    if box is None:
        return 0.0, 0.0
    box = expand_box(box, 1, config.nx, config.ny)
    x0, y0, x1, y1 = box
    shape = (y1 - y0, x1 - x0)
    old_solid = old.raster.crop_solid(box) if old else np.zeros(shape, bool)
    new_solid = new.raster.crop_solid(box) if new else np.zeros(shape, bool)
    motion = new if new is not None else old
    xc, yc = (motion.shape.x, motion.shape.y) if motion.shape is not None else (0.0, 0.0)
    wrap = periodic_wrap(config, box)
    return _refill(g, x0, y0, old_solid, new_solid, float(xc), float(yc), float(motion.velocity[0]),
                   float(motion.velocity[1]), float(motion.omega), wrap[0], wrap[1], IMPULSE_CODES[impulse])


@numba.njit(**_JIT)
def _redo_nodes(ey, ex, ebits, edge_grid, li, liy, lix, lfy, lfx, lq, x0, y0, h, w):
    """The boundary pass's node list (solver/cpu_backend.py `_redo_nodes`): the domain-edge nodes
    (ey, ex, ebits) that own no body link, then each node that owns a body link, row by row, with
    a bit per link direction and its edge bits, as (3, m) (iy, ix, bits), each node once; the
    links' (iy, ix, fy, fx) in grid coordinates (4, n); and their wall crossings x - q c_i
    (px, py) (2, n), for the torque."""
    win = np.zeros((h, w), np.int64)
    for k in range(len(li)):
        win[liy[k], lix[k]] |= 1 << li[k]
    m = 0
    for y in range(h):
        for x in range(w):
            m += win[y, x] != 0
    keep = np.ones(len(ey), np.bool_)
    for k in range(len(ey)):
        yy, xx = ey[k] - y0, ex[k] - x0
        if 0 <= yy < h and 0 <= xx < w and win[yy, xx] != 0:
            keep[k] = False
    ne = 0
    for k in range(len(ey)):
        ne += keep[k]
    nodes = np.empty((3, ne + m), np.int64)
    k = 0
    for j in range(len(ey)):
        if keep[j]:
            nodes[0, k], nodes[1, k], nodes[2, k] = ey[j], ex[j], ebits[j]
            k += 1
    for y in range(h):
        for x in range(w):
            if win[y, x] != 0:
                nodes[0, k], nodes[1, k] = y + y0, x + x0
                nodes[2, k] = win[y, x] | edge_grid[y + y0, x + x0]
                k += 1
    grid = np.empty((4, len(li)), np.int64)
    cross = np.empty((2, len(li)))
    for k in range(len(li)):
        grid[0, k], grid[1, k], grid[2, k], grid[3, k] = liy[k] + y0, lix[k] + x0, lfy[k] + y0, lfx[k] + x0
        cross[0, k] = float(lix[k] + x0) - lq[k] * float(_CXI[li[k]])
        cross[1, k] = float(liy[k] + y0) - lq[k] * float(_CYI[li[k]])
    return nodes, grid, cross


def redo_nodes(edge_nodes, edge_grid, links, window):
    """((iy, ix, bits) of the boundary pass's nodes, the link arrays in grid coordinates) of the
    body `links` on `window` (solver/cpu_backend.py `_redo_nodes`), compiled."""
    x0, y0, x1, y1 = window
    ey, ex, ebits = edge_nodes
    c = np.ascontiguousarray
    nodes, grid, cross = _redo_nodes(ey, ex, ebits, edge_grid, c(links.i), c(links.iy), c(links.ix), c(links.fy),
                                     c(links.fx), c(links.q), x0, y0, y1 - y0, x1 - x0)
    uw = links.uw
    return (nodes[0], nodes[1], nodes[2]), (c(links.i), grid[0], grid[1], grid[2], grid[3], c(links.a), c(links.b),
                                            c(links.c), c(links.d), c(uw[:, 0]), c(uw[:, 1]), cross[0], cross[1])
