"""The rigid body on the lattice: pose, motion, cover/uncover refill and the force window.

docs/science/algorithm.md, 'Moving the body'. Refill after Lallemand & Luo, J. Comput. Phys. 184 (2003)
406: an uncovered node gets f^eq(rho_new, u_body) with rho_new the mean density of its fluid
neighbours. Shared by both backends: the gl backend reads back the body window, calls `refill`
on it and writes the changed nodes back (not for a move that covers and uncovers no node: its
step pass resets the solid nodes itself).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from feelflow.solver.bouzidi import BodyLinks, build_links, periodic_wrap, wall_velocity
from feelflow.solver.lattice import C, Q, RHO0, W, equilibrium
from feelflow.solver.speed_limit import cap_rigid_motion

#: nodes around the raster window the force window keeps: the Bouzidi second node (1) + 1
BASE_MARGIN = 2


def window_margin(models) -> int:
    """Margin of the force window: BASE_MARGIN, or more where an enabled model asks for it
    through a `margin` attribute (e.g. the macroscopic model: ceil(contour distance) + 2)."""
    return max([BASE_MARGIN] + [int(getattr(m, "margin", 0)) for m in models])


def expand_box(box, margin: int, nx: int, ny: int):
    """(x0, y0, x1, y1) half-open box grown by margin, clipped to the domain."""
    x0, y0, x1, y1 = box
    return (max(0, x0 - margin), max(0, y0 - margin), min(nx, x1 + margin), min(ny, y1 + margin))


def union_box(a, b):
    if a is None:
        return b
    if b is None:
        return a
    return (min(a[0], b[0]), min(a[1], b[1]), max(a[2], b[2]), max(a[3], b[3]))


def body_radius(shape) -> float:
    """Largest distance from the reference point to the bounding box: bounds |Omega| r."""
    xmin, ymin, xmax, ymax = shape.bounding_box()
    return max(math.hypot(px - shape.x, py - shape.y) for px in (xmin, xmax) for py in (ymin, ymax))


def capped_motion(shape, velocity, omega, max_speed):
    """The body motion under the Mach limit: ((vx, vy), omega, capped)."""
    radius = body_radius(shape) if shape is not None else 0.0
    return cap_rigid_motion(velocity, omega, radius, max_speed)


def node_velocity(shape, velocity, omega, x0, y0, nodes):
    """u_body at the window nodes where the (h, w) mask `nodes` is True (row by row, as
    boolean indexing orders them), two 1-D arrays; at rest without a shape."""
    iy, ix = np.nonzero(nodes)
    if shape is None:
        return np.zeros(iy.size), np.zeros(iy.size)
    ux, uy = wall_velocity((ix + x0).astype(np.float64), (iy + y0).astype(np.float64), (shape.x, shape.y),
                           velocity, omega)
    return np.broadcast_to(ux, iy.shape).astype(np.float64), np.broadcast_to(uy, iy.shape).astype(np.float64)


def _neighbour_sum(field: np.ndarray, wrap: tuple[bool, bool] = (False, False)) -> np.ndarray:
    """Sum of a (h, w) field, or of each of a stack (k, h, w), over the 8 lattice neighbours:
    zero outside the window, except across a periodic direction the window spans whole
    (`wrap`, x and y: periodic_wrap)."""
    h, w = field.shape[-2:]
    pad = np.zeros(field.shape[:-2] + (h + 2, w + 2), dtype=field.dtype)  # as np.pad: x, then y
    pad[..., 1:-1, 1:-1] = field
    if wrap[0]:
        pad[..., 1:-1, 0], pad[..., 1:-1, -1] = field[..., :, -1], field[..., :, 0]
    if wrap[1]:
        pad[..., 0, :], pad[..., -1, :] = pad[..., -2, :], pad[..., 1, :]
    out = np.zeros(field.shape, dtype=pad.dtype)
    for k in range(1, Q):
        cx, cy = int(C[k, 0]), int(C[k, 1])
        out += pad[..., 1 + cy:1 + cy + h, 1 + cx:1 + cx + w]
    return out


#: how an uncovered node is filled (`refill`): the equilibrium at the body's velocity only
#: (Lallemand & Luo 2003), or that equilibrium plus the non-equilibrium part of its fluid
#: neighbours (Caiazzo, Prog. Comput. Fluid Dyn. 8 (2008) 3)
REFILL_SCHEMES = ("equilibrium", "nonequilibrium")
#: how the momentum of covered and uncovered nodes enters the force (`refill`): "relative", the
#: momentum relative to the body's own motion there (Galilean invariant, as Wen et al. 2014 make
#: each link's term); "absolute", the whole momentum (Wen et al. 2014, Chen et al. 2013); "none"
IMPULSE_SCHEMES = ("relative", "absolute", "none")
#: the schemes in use unless a solver is told otherwise (docs/science/force-models.md says why)
DEFAULT_REFILL = "equilibrium"
DEFAULT_IMPULSE = "relative"


def check_schemes(refill_scheme: str, impulse: str) -> None:
    """ValueError naming the first unknown scheme."""
    if refill_scheme not in REFILL_SCHEMES:
        raise ValueError(f"refill must be one of {', '.join(REFILL_SCHEMES)}, got {refill_scheme!r}")
    if impulse not in IMPULSE_SCHEMES:
        raise ValueError(f"impulse must be one of {', '.join(IMPULSE_SCHEMES)}, got {impulse!r}")


def refill(f: np.ndarray, old_solid: np.ndarray, new_solid: np.ndarray, shape, velocity, omega,
           x0: int, y0: int, wrap: tuple[bool, bool] = (False, False), scheme: str = DEFAULT_REFILL,
           impulse: str = DEFAULT_IMPULSE):
    """Cover, uncover and re-equilibrate the solid nodes of a window of full f* (in place).

    f: (9, h, w) float64 post-collision populations; masks cut to the same window, which must
    reach one node beyond every old and new solid node (or the domain edge); `wrap`: the
    window spans a periodic direction whole, so neighbours continue across the seam.
    Covered nodes (new & ~old) give their momentum to the body; uncovered ones (old & ~new)
    get f^eq(rho_new, u_body) (`scheme` "nonequilibrium": plus the mean non-equilibrium part
    f - f^eq(rho, u) of their fluid neighbours, which carries no mass or momentum) and take
    momentum rho_new u_body from it; every solid node gets f^eq(RHO0, u_body). The mass this
    creates or destroys (solid nodes hold RHO0) goes back to the fluid ring around the body
    (fluid nodes next to an old or new solid node), each node scaled by the same added density
    (velocity kept); the momentum that adds is booked too.
    `impulse`: "absolute" books those momenta whole; "relative" books each less the mass it
    moves times the body's velocity at that node (mass that joins or leaves the body at the
    body's own velocity needs no force: only the momentum relative to the body is exchanged,
    the Galilean-invariant form); "none" books nothing.
    `shape` gives u_body: the new body, or the old one when it is removed (None: at rest).
    Returns (impulse (Jx, Jy), changed (h, w) bool mask of written nodes).
    """
    check_schemes(scheme, impulse)
    covered = new_solid & ~old_solid
    uncovered = old_solid & ~new_solid
    if not (covered.any() or uncovered.any()):
        if new_solid.any():
            ux, uy = node_velocity(shape, velocity, omega, x0, y0, new_solid)
            f[:, new_solid] = equilibrium(np.full(ux.size, RHO0), ux, uy)
        return (0.0, 0.0), new_solid.copy()
    relative = impulse == "relative"
    cx_, cy_ = C[:, 0].astype(np.float64), C[:, 1].astype(np.float64)
    jx = jy = 0.0
    lost = 0.0   # mass the cover/uncover removes from the grid
    if covered.any():
        fc = f[:, covered]
        fc_i = fc.sum(axis=1)
        jx += float(cx_ @ fc_i)
        jy += float(cy_ @ fc_i)
        lost += float(fc.sum()) - RHO0 * int(covered.sum())
        if relative:
            ucx, ucy = node_velocity(shape, velocity, omega, x0, y0, covered)
            rho_c = fc.sum(axis=0)
            jx -= float((rho_c * ucx).sum())
            jy -= float((rho_c * ucy).sum())
    body_nodes = (new_solid | old_solid).astype(np.float64)
    # the equilibria of the uncovered nodes (rho_new) and of the solid ones (RHO0), in one call
    written = uncovered | new_solid
    ux, uy = node_velocity(shape, velocity, omega, x0, y0, written)
    rho_eq = np.full(ux.size, RHO0)
    neq = None
    if uncovered.any():
        rho = f.sum(axis=0)
        donor = ~new_solid & ~uncovered
        fields = [np.where(donor, rho, 0.0), donor.astype(np.float64), body_nodes]
        if scheme == "nonequilibrium":
            per = np.where(donor, rho, 1.0)
            mx = np.tensordot(cx_, f, axes=1)
            my = np.tensordot(cy_, f, axes=1)
            fneq = f - equilibrium(per, np.where(donor, mx, 0.0) / per, np.where(donor, my, 0.0) / per)
            fields += list(np.where(donor, fneq, 0.0))
        # one stacked neighbour sum: donor densities, donor count, body nodes (the ring below)
        sums = _neighbour_sum(np.stack(fields), wrap)
        rsum, cnt, near_body = sums[0], sums[1], sums[2]
        rho_new = np.where(cnt > 0, rsum / np.maximum(cnt, 1), RHO0)[uncovered]
        if scheme == "nonequilibrium":
            neq = (sums[3:] / np.maximum(cnt, 1))[:, uncovered]
            neq -= neq.mean(axis=0)   # no mass (float rounding of the means)
        is_uncovered = uncovered[written]
        rho_eq[is_uncovered] = rho_new
        if not relative:
            uxu, uyu = ux[is_uncovered], uy[is_uncovered]
            jx -= float((rho_new * uxu).sum())
            jy -= float((rho_new * uyu).sum())
        lost += RHO0 * int(uncovered.sum()) - float(rho_new.sum())
    else:
        near_body = _neighbour_sum(body_nodes, wrap)
    f[:, written] = equilibrium(rho_eq, ux, uy)
    if neq is not None:
        f[:, uncovered] += neq
    ring = ~new_solid & (near_body > 0)
    if lost != 0.0 and ring.any():
        fr = f[:, ring]
        rho_r = fr.sum(axis=0)
        scale = 1.0 + (lost / int(ring.sum())) / rho_r
        added = fr * (scale - 1.0)
        f[:, ring] = fr + added
        added_i = added.sum(axis=1)
        jx -= float(cx_ @ added_i)
        jy -= float(cy_ @ added_i)
        if relative:
            urx, ury = node_velocity(shape, velocity, omega, x0, y0, ring)
            dm = added.sum(axis=0)
            jx += float((dm * urx).sum())
            jy += float((dm * ury).sum())
    if impulse == "none":
        jx = jy = 0.0
    return (jx, jy), (new_solid | uncovered | ring)


def move_body(old, new, config, read_window, write_nodes, step_sets_solid: bool = False,
              refill_scheme: str = DEFAULT_REFILL, impulse: str = DEFAULT_IMPULSE):
    """Cover/uncover bookkeeping between two body states (either may be None), for any backend.

    read_window(x0, y0, x1, y1) -> (9, y1-y0, x1-x0) float64 full f* of that box;
    write_nodes(x0, y0, f, changed) writes back the nodes where `changed` (the window's (h, w)
    mask) is True. The box is the union of both raster windows grown by one node (the refill's
    neighbours). Returns the impulse (Jx, Jy) to add to the next step's force.
    `step_sets_solid`: the backend's step gives every solid node f^eq(RHO0, u_body) itself (the
    gl step pass), so a move that covers and uncovers no node (a sub-cell move, most of a
    slowly dragged body's) reads and writes nothing: refill would only write those equilibria.
    `refill_scheme`, `impulse`: `refill`'s `scheme` and `impulse`.
    """
    box = union_box(old.raster.window if old else None, new.raster.window if new else None)
    if box is None:
        return 0.0, 0.0
    x0, y0, x1, y1 = expand_box(box, 1, config.nx, config.ny)
    shape = (y1 - y0, x1 - x0)
    old_solid = old.raster.crop_solid((x0, y0, x1, y1)) if old else np.zeros(shape, bool)
    new_solid = new.raster.crop_solid((x0, y0, x1, y1)) if new else np.zeros(shape, bool)
    if step_sets_solid and np.array_equal(old_solid, new_solid):
        return 0.0, 0.0
    motion = new if new is not None else old
    f = read_window(x0, y0, x1, y1)
    impulse, changed = refill(f, old_solid, new_solid, motion.shape, motion.velocity, motion.omega, x0, y0,
                              wrap=periodic_wrap(config, (x0, y0, x1, y1)), scheme=refill_scheme, impulse=impulse)
    write_nodes(x0, y0, f, changed)
    return impulse


def same_solid_motion(old, new) -> bool:
    """Whether a move from body state `old` to `new` leaves every solid node as it was: the same
    solid nodes (no node covered or uncovered) at the same u_body (same velocity and angular
    velocity, and for a turning body the same centre). The solid nodes then already hold
    f^eq(RHO0, u_body), so the move writes nothing (a sub-cell move of a towed body, most of
    its steps); only the links change."""
    if old is None or new is None or old.velocity != new.velocity or old.omega != new.omega:
        return False
    if new.omega != 0.0 and (old.shape.x, old.shape.y) != (new.shape.x, new.shape.y):
        return False
    return old.raster.box == new.raster.box and np.array_equal(old.raster.box_solid, new.raster.box_solid)


@dataclass
class BodyState:
    """The body on the grid: shape at its pose, capped motion, raster, windows and links.

    window: (x0, y0, x1, y1) force window (raster window + margin, clipped to the domain);
    links: the Bouzidi body links of that window; window_solid_q: (solid, q) cut to that window.
    `solid` is the full-grid mask (built on first use: for tests, not the solver's paths).
    """

    shape: object
    velocity: tuple[float, float]
    omega: float
    capped: bool
    raster: object
    window: tuple[int, int, int, int]
    links: BodyLinks
    window_solid_q: tuple

    @property
    def solid(self) -> np.ndarray:
        return self.raster.solid

    def window_slices(self):
        x0, y0, x1, y1 = self.window
        return slice(y0, y1), slice(x0, x1)

    def window_arrays(self):
        """(solid, q) cut to the force window."""
        return self.window_solid_q


def make_body_state(shape, velocity, omega, config, margin: int, raster=None, links=build_links,
                    rasteriser=None) -> BodyState:
    """Rasterise `shape` (unless `raster` is given: a BodyRaster of this shape with any
    window margin), cap its motion and build its links on raster.window + margin. `links`:
    `build_links` or an equal; `rasteriser(shape, nx, ny)`: one for this shape equal to
    `rasterise(shape, nx, ny, 0)`, or None (the compiled ones: solver/body_compiled.py)."""
    from feelflow.shapes.raster import rasterise

    nx, ny = config.nx, config.ny
    shape.validate(nx, ny)
    vel, om, capped = capped_motion(shape, velocity, omega, config.max_speed)
    if raster is None:
        raster = rasteriser(shape, nx, ny) if rasteriser is not None else rasterise(shape, nx, ny, 0)
    window = expand_box(raster.window, margin, nx, ny)
    x0, y0 = window[:2]
    solid, q = raster.crop(window)
    body_links = links(q, solid, x0, y0, (shape.x, shape.y), vel, om, wrap=periodic_wrap(config, window))
    return BodyState(shape, vel, om, capped, raster, window, body_links, (solid, q))


def shifted(f: np.ndarray) -> np.ndarray:
    """g = f - w_i RHO0 for a (9, ...) array."""
    return f - (W * RHO0).reshape((Q,) + (1,) * (f.ndim - 1))


def unshifted(g: np.ndarray) -> np.ndarray:
    """f = g + w_i RHO0, float64."""
    return g.astype(np.float64) + (W * RHO0).reshape((Q,) + (1,) * (g.ndim - 1))
