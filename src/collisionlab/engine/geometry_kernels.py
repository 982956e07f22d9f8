"""The narrow phase and two balls' time of impact, written once as scalar kernels (the contact
law is :mod:`.contact_law`'s).

Every function here takes and returns plain floats (a vector is three of them), so the same
source runs two ways: as ordinary Python (the scalar API in :mod:`collisionlab.narrowphase` and
:mod:`collisionlab.resolution`, and small worlds) and compiled by numba inside the engine's
array steppers (:mod:`collisionlab.engine.compiled`). Nothing here allocates or raises.

A separation is returned as ``(distance, nx, ny, nz, px, py, pz)``: the signed distance
(negative when overlapping), the unit normal from A to B and the contact point, as
:class:`~collisionlab.contact.Separation` documents.

>>> separation_ball_ball(0.0, 0.0, 0.0, 1.0, 3.0, 4.0, 0.0, 2.0)[0]   # |(3, 4)| - (1 + 2)
2.0
"""

from __future__ import annotations

import math

from ..tolerances import FALLBACK_NORMAL

__all__ = [
    "first_root",
    "norm3",
    "separation_ball_ball",
    "separation_ball_box",
    "separation_boundary_ball",
    "separation_boundary_box",
    "separation_box_box",
    "separation_wall_ball",
    "separation_wall_box",
    "time_of_impact_ball_ball",
]

Sep = tuple[float, float, float, float, float, float, float]

#: Helpers the compiled form inlines into their callers (the exact steppers' time-of-impact loops).
INLINE = ("first_root",)

_FX = FALLBACK_NORMAL[0]
_FY = FALLBACK_NORMAL[1]
_FZ = FALLBACK_NORMAL[2]
#: Components beyond this (or below its inverse) are scaled before squaring, so a length never
#: overflows to inf or underflows to 0 (2**500: squares of three such numbers stay finite).
_BIG = 2.0**500
_SMALL = 2.0**-500


def norm3(x: float, y: float, z: float) -> float:
    """``sqrt(x^2 + y^2 + z^2)``, scaled when the components are huge or tiny.

    >>> norm3(3.0, 4.0, 12.0), norm3(1e300, 1e300, 0.0) > 1e300, norm3(5e-324, 0.0, 0.0) > 0.0
    (13.0, True, True)
    """
    m = max(abs(x), abs(y), abs(z))
    if m == 0.0 or m == math.inf or m != m:
        return m
    if m > _BIG or m < _SMALL:
        x, y, z = x / m, y / m, z / m
        return m * math.sqrt(x * x + y * y + z * z)
    return math.sqrt(x * x + y * y + z * z)


# --- one kernel per pair of features ------------------------------------------------------------
def separation_ball_ball(ax: float, ay: float, az: float, ra: float, bx: float, by: float, bz: float, rb: float) -> Sep:
    """Two balls: ``d = |p2 - p1| - (r1 + r2)`` (lab eqs. 1-2; Ericson 4.3.1). Coincident centres
    take ``FALLBACK_NORMAL``; the point is midway between the two surface points.

    >>> separation_ball_ball(0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.5, 1.0)   # 1.5 - 2; point z = 0.75
    (-0.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.75)
    >>> separation_ball_ball(1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 2.0)[1:4]   # coincident
    (1.0, 0.0, 0.0)
    """
    dx = bx - ax
    dy = by - ay
    dz = bz - az
    length = norm3(dx, dy, dz)
    if length > 0.0:
        nx, ny, nz = dx / length, dy / length, dz / length
    else:
        nx, ny, nz = _FX, _FY, _FZ
    half = (ra - rb) * 0.5
    px = (ax + bx) * 0.5 + nx * half
    py = (ay + by) * 0.5 + ny * half
    pz = (az + bz) * 0.5 + nz * half
    return (length - (ra + rb), nx, ny, nz, px, py, pz)


def separation_boundary_ball(
    ox: float, oy: float, oz: float, ux: float, uy: float, uz: float, cx: float, cy: float, cz: float, r: float
) -> Sep:
    """A two-sided line or plane (point ``o``, unit normal ``u``) and a ball: ``s = u.(Q - P)``,
    ``d = |s| - r`` (lab eqs. 6-9); the normal points to the side the centre is on (``u`` when
    the centre is on the boundary).

    >>> separation_boundary_ball(0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, -0.5, 2.0, 1.0)
    (-0.5, -0.0, -1.0, -0.0, 1.0, 0.25, 2.0)
    """
    s = ux * (cx - ox) + uy * (cy - oy) + uz * (cz - oz)
    if s < 0.0:
        nx, ny, nz = -ux, -uy, -uz
    else:
        nx, ny, nz = ux, uy, uz
    # lab eq. 8: S = Q - Proj_n(PQ), the closest point of the boundary
    sx, sy, sz = cx - ux * s, cy - uy * s, cz - uz * s
    px = (sx + cx - nx * r) * 0.5
    py = (sy + cy - ny * r) * 0.5
    pz = (sz + cz - nz * r) * 0.5
    return (abs(s) - r, nx, ny, nz, px, py, pz)


def separation_wall_ball(
    ox: float, oy: float, oz: float, ux: float, uy: float, uz: float, cx: float, cy: float, cz: float, r: float
) -> Sep:
    """A one-sided wall (the inside is where ``u.(x - o) >= 0``) and a ball: ``d = u.(c - o) - r``,
    the normal always ``u``, so a ball past the wall is pushed back inside, never out.

    >>> separation_wall_ball(0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, -3.0, 0.0, 1.0)[:4]
    (-4.0, 0.0, 1.0, 0.0)
    """
    s = ux * (cx - ox) + uy * (cy - oy) + uz * (cz - oz)
    px = cx - ux * ((s + r) * 0.5)
    py = cy - uy * ((s + r) * 0.5)
    pz = cz - uz * ((s + r) * 0.5)
    return (s - r, ux, uy, uz, px, py, pz)


def _nearest_vertex(c: float, lo: float, hi: float, n: float) -> float:
    """The coordinate of the box vertex nearest a boundary of normal component ``n``, taken
    from the corners themselves (centre -+ half size can round 1 ulp onto the boundary)."""
    if n > 0.0:
        return lo
    if n < 0.0:
        return hi
    return c


def separation_boundary_box(
    ox: float,
    oy: float,
    oz: float,
    ux: float,
    uy: float,
    uz: float,
    lox: float,
    loy: float,
    loz: float,
    hix: float,
    hiy: float,
    hiz: float,
) -> Sep:
    """A two-sided line or plane and a box (Ericson 5.2.3): the box's projected radius on the
    normal is ``h = sum_i |n_i| e_i`` and ``d = |n.(c - P)| - h``, computed as ``n.(v - P)`` for
    the vertex ``v`` nearest the boundary.

    >>> separation_boundary_box(0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, -0.25, 1.0, 1.0, 1.0)[0]
    -0.25
    """
    cx, cy, cz = (lox + hix) * 0.5, (loy + hiy) * 0.5, (loz + hiz) * 0.5
    s = ux * (cx - ox) + uy * (cy - oy) + uz * (cz - oz)
    if s < 0.0:
        nx, ny, nz = -ux, -uy, -uz
    else:
        nx, ny, nz = ux, uy, uz
    vx = _nearest_vertex(cx, lox, hix, nx)
    vy = _nearest_vertex(cy, loy, hiy, ny)
    vz = _nearest_vertex(cz, loz, hiz, nz)
    gap = nx * (vx - ox) + ny * (vy - oy) + nz * (vz - oz)
    return (gap, nx, ny, nz, vx - nx * (gap * 0.5), vy - ny * (gap * 0.5), vz - nz * (gap * 0.5))


def separation_wall_box(
    ox: float,
    oy: float,
    oz: float,
    ux: float,
    uy: float,
    uz: float,
    lox: float,
    loy: float,
    loz: float,
    hix: float,
    hiy: float,
    hiz: float,
) -> Sep:
    """A one-sided wall and a box: the vertex deepest towards the outside, ``d = u.(v - o)``."""
    vx = _nearest_vertex((lox + hix) * 0.5, lox, hix, ux)
    vy = _nearest_vertex((loy + hiy) * 0.5, loy, hiy, uy)
    vz = _nearest_vertex((loz + hiz) * 0.5, loz, hiz, uz)
    gap = ux * (vx - ox) + uy * (vy - oy) + uz * (vz - oz)
    return (gap, ux, uy, uz, vx - ux * (gap * 0.5), vy - uy * (gap * 0.5), vz - uz * (gap * 0.5))


def _clamp(c: float, lo: float, hi: float) -> float:
    return min(max(c, lo), hi)


def separation_ball_box(
    cx: float,
    cy: float,
    cz: float,
    r: float,
    lox: float,
    loy: float,
    loz: float,
    hix: float,
    hiy: float,
    hiz: float,
    dims: int,
) -> Sep:
    """A ball and a box (Ericson 5.2.5): the closest point ``q`` is the centre clamped to the box;
    ``d = |q - c| - r``. A centre inside (or on) the box leaves through the nearest face among the
    first ``dims`` axes (first in x-, x+, y-, y+, z-, z+ order on a tie): the normal is minus that
    face's outward normal and ``d = -(r + distance to the face)``.

    >>> separation_ball_box(1.0, 0.5, 0.0, 1.0, 0.0, 0.0, 0.0, 4.0, 4.0, 0.0, 2)[:4]   # face y = 0
    (-1.5, 0.0, 1.0, 0.0)
    """
    qx, qy, qz = _clamp(cx, lox, hix), _clamp(cy, loy, hiy), _clamp(cz, loz, hiz)
    dx, dy, dz = qx - cx, qy - cy, qz - cz
    length = norm3(dx, dy, dz)
    if length > 0.0:
        nx, ny, nz = dx / length, dy / length, dz / length
        return (
            length - r,
            nx,
            ny,
            nz,
            (cx + nx * r + qx) * 0.5,
            (cy + ny * r + qy) * 0.5,
            (cz + nz * r + qz) * 0.5,
        )
    best_axis = 0
    best_sign = -1.0
    best_gap = math.inf
    for axis in range(dims):
        if axis == 0:
            c, lo, hi = cx, lox, hix
        elif axis == 1:
            c, lo, hi = cy, loy, hiy
        else:
            c, lo, hi = cz, loz, hiz
        if c - lo < best_gap:
            best_axis, best_sign, best_gap = axis, -1.0, c - lo
        if hi - c < best_gap:
            best_axis, best_sign, best_gap = axis, 1.0, hi - c
    # The face's outward normal as an axis times a sign (0 * -1 is -0.0, as Vector3D gives).
    fx = (1.0 if best_axis == 0 else 0.0) * best_sign
    fy = (1.0 if best_axis == 1 else 0.0) * best_sign
    fz = (1.0 if best_axis == 2 else 0.0) * best_sign
    shift = (best_gap - r) * 0.5
    return (-(r + best_gap), -fx, -fy, -fz, cx + fx * shift, cy + fy * shift, cz + fz * shift)


def _axis_gap(alo: float, ahi: float, blo: float, bhi: float) -> float:
    return max(alo - bhi, blo - ahi)


def _axis_apart(alo: float, ahi: float, blo: float, bhi: float) -> tuple[float, float]:
    """Along one axis of two boxes that do not overlap everywhere: the component of the gap
    vector from A to B and the middle of the gap (or of the overlap)."""
    if ahi < blo:
        return blo - ahi, (ahi + blo) * 0.5
    if bhi < alo:
        return bhi - alo, (bhi + alo) * 0.5
    return 0.0, (max(alo, blo) + min(ahi, bhi)) * 0.5


def separation_box_box(
    alox: float,
    aloy: float,
    aloz: float,
    ahix: float,
    ahiy: float,
    ahiz: float,
    blox: float,
    bloy: float,
    bloz: float,
    bhix: float,
    bhiy: float,
    bhiz: float,
    dims: int,
) -> Sep:
    """Two boxes in 2D or 3D (lab part III, eqs. 4-5; Ericson 4.2.1). Per axis the gap is
    ``max(a.min - b.max, b.min - a.max)``. When every gap is <= 0 the contact is along the axis of
    least overlap (ties: x before y before z), the normal's sign from A's centre to B's (+ when
    level). Otherwise the distance is the length of the vector of positive gaps.

    >>> separation_box_box(0.0, 0.0, 0.0, 2.0, 2.0, 0.0, 1.5, 1.0, 0.0, 3.0, 3.0, 0.0, 2)
    (-0.5, 1.0, 0.0, 0.0, 1.75, 1.5, 0.0)
    """
    gx = _axis_gap(alox, ahix, blox, bhix)
    gy = _axis_gap(aloy, ahiy, bloy, bhiy)
    gz = _axis_gap(aloz, ahiz, bloz, bhiz) if dims == 3 else -math.inf
    if max(gx, gy, gz) > 0.0:
        dx, mx = _axis_apart(alox, ahix, blox, bhix)
        dy, my = _axis_apart(aloy, ahiy, bloy, bhiy)
        dz, mz = _axis_apart(aloz, ahiz, bloz, bhiz)
        if dims != 3:
            dz = 0.0
        length = norm3(dx, dy, dz)
        return (length, dx / length, dy / length, dz / length, mx, my, mz)
    axis = 0
    gap = gx
    if gy > gap:
        axis, gap = 1, gy
    if dims == 3 and gz > gap:
        axis, gap = 2, gz
    if axis == 0:
        offset = (blox + bhix) * 0.5 - (alox + ahix) * 0.5
    elif axis == 1:
        offset = (bloy + bhiy) * 0.5 - (aloy + ahiy) * 0.5
    else:
        offset = (bloz + bhiz) * 0.5 - (aloz + ahiz) * 0.5
    sign = -1.0 if offset < 0.0 else 1.0
    mx = (max(alox, blox) + min(ahix, bhix)) * 0.5
    my = (max(aloy, bloy) + min(ahiy, bhiy)) * 0.5
    mz = (max(aloz, bloz) + min(ahiz, bhiz)) * 0.5
    nx = (1.0 if axis == 0 else 0.0) * sign
    ny = (1.0 if axis == 1 else 0.0) * sign
    nz = (1.0 if axis == 2 else 0.0) * sign
    return (gap, nx, ny, nz, mx, my, mz)


# --- time of impact -------------------------------------------------------------------------------
def first_root(c0: float, c1: float, c2: float, limit: float) -> float:
    """The first ``t`` in ``(0, limit]`` where ``c0 + c1 t + c2 t^2`` (with ``c0 > 0``) reaches 0,
    or ``inf`` (numerically stable roots: Press et al., *Numerical Recipes*, 5.6).

    >>> first_root(1.0, -2.0, 0.0, 10.0)   # 1 - 2t = 0
    0.5
    >>> first_root(1.0, 0.0, -1.0, 10.0)   # 1 - t^2 = 0
    1.0
    >>> first_root(1.0, 1.0, 1.0, 10.0)    # never below 1
    inf
    """
    if c2 == 0.0:
        if c1 < 0.0:
            t = -c0 / c1
            return t if t <= limit else math.inf
        return math.inf
    disc = c1 * c1 - 4.0 * c2 * c0
    if disc < 0.0:
        return math.inf
    q = -0.5 * (c1 + math.copysign(math.sqrt(disc), c1))
    r1 = q / c2
    r2 = c0 / q
    best = math.inf
    if r1 > 0.0:
        best = r1
    if 0.0 < r2 < best:
        best = r2
    return best if best <= limit else math.inf


def time_of_impact_ball_ball(dx: float, dy: float, dz: float, wx: float, wy: float, wz: float, reach2: float) -> float:
    """When two balls whose centres are ``d`` apart (B minus A), moving at relative velocity
    ``w`` (B minus A) in straight flight, come within ``sqrt(reach2)`` (the sum of the radii):
    the smaller root of ``|d + w t|^2 = reach^2`` (Ericson, *Real-Time Collision Detection*,
    4.4.3), ``t = a / (-b + sqrt(b^2 - w^2 a))`` with ``a = |d|^2 - reach^2``, ``b = d . w``: the
    same root as ``(-b - sqrt(...)) / w^2`` without its cancellation when ``a`` is small (two
    balls just apart). Approaching (``b < 0``) and already touching or overlapping: 0. Not
    approaching, or passing wide (``b^2 < w^2 a``): ``inf``; a graze (``b^2 = w^2 a``) touches
    at ``-a / b``.

    Written with no branch on whether the pair approaches: a many-body stepper tests every
    neighbour, whether a pair approaches is a coin toss the processor cannot predict, and a
    mispredicted branch cost more than always taking the square root and the division.

    >>> time_of_impact_ball_ball(3.0, 0.0, 0.0, -1.0, 0.0, 0.0, 4.0)   # gap 3 - 2 closed at speed 1
    1.0
    >>> time_of_impact_ball_ball(3.0, 0.0, 0.0, 1.0, 0.0, 0.0, 4.0)    # moving apart
    inf
    >>> time_of_impact_ball_ball(3.0, 1.0, 0.0, -1.0, 0.0, 0.0, 1.0)   # (3 - t)^2 + 1 = 1: a graze at t = 3
    3.0
    >>> time_of_impact_ball_ball(1.5, 0.0, 0.0, -1.0, 0.0, 0.0, 4.0), time_of_impact_ball_ball(0, 0, 0, 0, 0, 0, 4.0)
    (0.0, inf)
    """
    b = dx * wx + dy * wy + dz * wz
    a = dx * dx + dy * dy + dz * dz - reach2
    disc = b * b - (wx * wx + wy * wy + wz * wz) * a
    den = -b + math.sqrt(max(disc, 0.0))
    root = a / (den if den > 0.0 else 1.0)  # den <= 0 only when not approaching: discarded below
    t = 0.0 if a <= 0.0 else root
    return t if (b < 0.0) & (disc >= 0.0) else math.inf
