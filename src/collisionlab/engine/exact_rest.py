"""The exact stepper's resting contacts (phase 2 of :mod:`.exact_kernels`): under gravity, a pair
in contact whose normal speed is below ``rest_speed`` and whose accelerations press it together
rests. A slow approach or lift-off is stopped (no event), and the support cancels the pressing
part of the acceleration, shared as an impulse would be; a body already on a support passes the
part along its normal on to it, so stacks settle from the bottom up (Gauss-Seidel on
accelerations). A body on a curved support (two balls; a ball on a box's edge or corner) stays
only while ``v_t^2 / R`` is below the pressing acceleration, and only until its sliding could
leave the support (the rest's expiry, an event of the impacts' heap).

Owns ``MAX_SUPPORTS``, a body's acceleration before its rests (:func:`_base_acceleration`), a
pair's rest (:func:`_rest`, with :func:`_curvature` and :func:`_support_expiry`), the passes over
the pairs in contact (:func:`_rest_passes`) and when a pair need not be looked at again
(:func:`_unchanged_since`). It imports :mod:`.geometry_kernels`, :mod:`.pair_separation`'s shape
kinds and :mod:`.exact_impulses`; it must not import the time of impact, the sweeps, the impacts
or the loop (which look at rests, not the other way round).
"""

from __future__ import annotations

import math
from typing import Any

if "_GEOMETRY" in globals():  # the compiled copy: the kernels it calls are compiled too
    gk: Any = globals()["_GEOMETRY"]
    ps: Any = globals()["_PAIR_SEPARATION"]
    ej: Any = globals()["_EXACT_IMPULSES"]
else:
    from . import exact_impulses as ej
    from . import geometry_kernels as gk
    from . import pair_separation as ps

#: At most this many support normals are kept per body (a floor and two walls).
MAX_SUPPORTS = 3

#: Helpers the compiled form inlines into their callers (:mod:`.compiled`): the small ones, and
#: those the loop calls for every pair it looks at, which take arrays (a call costs a reference
#: count taken and given back for each array it passes; inlined into a ``NO_REFCOUNT`` phase,
#: none at all).
INLINE = (
    "_base_acceleration",
    "_curvature",
    "_support_expiry",
    "_rest",
    "_unchanged_since",
)

#: The loop's phases here that allocate nothing, compiled without numba's reference counts
#: (:mod:`.compiled`).
NO_REFCOUNT = (
    "_base_accelerations",
    "_rest_passes",
)


def _base_acceleration(i: int, acc: Any, ima: Any, gravity: Any, nsup: Any) -> None:
    """Gravity for a body of finite mass, nothing for a kinematic one; no supports."""
    for k in range(3):
        acc[i, k] = gravity[k] if ima[i] > 0.0 else 0.0
    nsup[i] = 0


def _curvature(kind: Any, ext: Any, s_kind: Any, a: int, b: int, nx: float, ny: float, nz: float) -> float:
    """Radius of curvature of the surface pair ``(a, b)`` slides on (the Minkowski sum of the two
    shapes): ``r_a + r_b`` for two balls, the ball's radius on a box's edge or corner (a normal off
    the axes), ``inf`` when flat (a line, a plane, a wall, a box face, two boxes)."""
    if a < 0 and s_kind[-1 - a] != ps.STATIC_BOX:
        return math.inf  # a line, plane or wall: the commonest support, decided first
    ball_a = a >= 0 and kind[a] <= ps.BALL_3D
    ball_b = kind[b] <= ps.BALL_3D
    if ball_a and ball_b:
        return float(ext[a, 0] + ext[b, 0])
    if not ball_a and not ball_b:
        return math.inf
    box_a = (a >= 0 and not ball_a) or (a < 0 and s_kind[-1 - a] == ps.STATIC_BOX)
    if not (box_a or not ball_b):
        return math.inf  # a ball on a line, plane or wall
    off_axes = (1 if nx != 0.0 else 0) + (1 if ny != 0.0 else 0) + (1 if nz != 0.0 else 0)
    if off_axes < 2:
        return math.inf
    return float(ext[a, 0] if ball_a else ext[b, 0])


def _support_expiry(
    a: int, b: int, kind: Any, vel: Any, acc: Any, ext: Any, s_kind: Any, normals: Any, c: int, margin: float
) -> float:
    """How long resting pair ``c`` (normal ``normals[c]``) may be held by its accelerations of
    the moment: a ball on a box (its face ends at an edge, its edge is curved) or on a ball meets a
    support whose normal turns as the two slide past each other, and the flight the rest set
    then leaves the surface by ``s^2 / (2 R)`` after a tangential travel ``s`` (``R``: the ball's
    radius, or the two radii's sum). It is looked at again once ``s`` could reach
    ``sqrt(R margin)`` (a gap of ``margin / 2``): ``s = |v_t| t + |a_t| t^2 / 2``. ``inf`` for a
    flat support (a line, a plane, a wall) or two boxes, and when nothing slides.

    >>> import numpy as np
    >>> kind = np.array([1, 3]); ext = np.array([[0.5, 0, 0], [1.0, 1, 1]]); n = np.array([[0.0, 1, 0]])
    >>> vel = np.array([[0.0, 0, 0], [0.1, 0, 0]]); acc = np.zeros((2, 3))
    >>> round(float(_support_expiry(1, 0, kind, vel, acc, ext, np.zeros(0, np.int64), n, 0, 2e-7)), 12)
    0.00316227766

    (a ball of radius 0.5 on a box sliding past it at 0.1 m/s: ``sqrt(0.5 * 2e-7) / 0.1`` s.)
    """
    if a < 0 and s_kind[-1 - a] != ps.STATIC_BOX:
        return math.inf  # a line, plane or wall: the commonest support, decided first
    ball_a = a >= 0 and kind[a] <= ps.BALL_3D
    ball_b = kind[b] <= ps.BALL_3D
    box_a = (a >= 0 and not ball_a) or (a < 0 and s_kind[-1 - a] == ps.STATIC_BOX)
    if ball_a and ball_b:
        radius = ext[a, 0] + ext[b, 0]
    elif ball_b and box_a:
        radius = ext[b, 0]
    elif ball_a and not ball_b:
        radius = ext[a, 0]
    else:
        return math.inf
    nx = normals[c, 0]
    ny = normals[c, 1]
    nz = normals[c, 2]
    rx = vel[b, 0] - (vel[a, 0] if a >= 0 else 0.0)
    ry = vel[b, 1] - (vel[a, 1] if a >= 0 else 0.0)
    rz = vel[b, 2] - (vel[a, 2] if a >= 0 else 0.0)
    qx = acc[b, 0] - (acc[a, 0] if a >= 0 else 0.0)
    qy = acc[b, 1] - (acc[a, 1] if a >= 0 else 0.0)
    qz = acc[b, 2] - (acc[a, 2] if a >= 0 else 0.0)
    vn = rx * nx + ry * ny + rz * nz
    qn = qx * nx + qy * ny + qz * nz
    vt = math.sqrt((rx - vn * nx) ** 2 + (ry - vn * ny) ** 2 + (rz - vn * nz) ** 2)
    at = math.sqrt((qx - qn * nx) ** 2 + (qy - qn * ny) ** 2 + (qz - qn * nz) ** 2)
    if vt == 0.0 and at == 0.0:
        return math.inf
    return float(gk.first_root(math.sqrt(radius * margin), -vt, -0.5 * at, math.inf))


def _rest(
    c: int,
    a: int,
    b: int,
    nx: float,
    ny: float,
    nz: float,
    kind: Any,
    vel: Any,
    ext: Any,
    ima: Any,
    acc: Any,
    sup: Any,
    nsup: Any,
    s_kind: Any,
    rest: Any,
    touching: Any,
    rest_speed: float,
    ledger: Any,
) -> int:
    """Make pair ``c`` a resting contact if it is one (phase 2 of the module docstring): returns
    1 if it did, 2 if it did not but stopped a slow approach or lift-off (the bodies' velocities
    changed), 0 if it changed nothing (then it returns 0 again while neither body's velocity,
    acceleration or supports change)."""
    ima_a = ima[a] if a >= 0 else 0.0
    rx = vel[b, 0] - (vel[a, 0] if a >= 0 else 0.0)
    ry = vel[b, 1] - (vel[a, 1] if a >= 0 else 0.0)
    rz = vel[b, 2] - (vel[a, 2] if a >= 0 else 0.0)
    vn = rx * nx + ry * ny + rz * nz
    pressing = 0.0
    for k in range(3):
        pressing += (acc[b, k] - (acc[a, k] if a >= 0 else 0.0)) * (nx if k == 0 else ny if k == 1 else nz)
    if abs(vn) > rest_speed or pressing >= 0.0:
        return 0
    radius = _curvature(kind, ext, s_kind, a, b, nx, ny, nz)
    if radius < math.inf:
        tx = rx - nx * vn
        ty = ry - ny * vn
        tz = rz - nz * vn
        if (tx * tx + ty * ty + tz * tz) / radius > -pressing:
            return 0  # too fast to follow the curve: it leaves the surface
    kicked = 0
    if vn != 0.0:  # a slow approach or lift-off is stopped (e = 0): resting, not an impact
        ej._kick(a, b, nx, ny, nz, vn, 0.0, vel, ima, sup, nsup, ledger, False)
        kicked = 2
    ax = ay = az = 0.0
    inv_a = 0.0
    if a >= 0 and ima_a > 0.0:
        ax, ay, az, inv_a, _ = ej._response(a, -nx, -ny, -nz, ima, sup, nsup, False)
    bx = by = bz = 0.0
    inv_b = 0.0
    if ima[b] > 0.0:
        bx, by, bz, inv_b, _ = ej._response(b, nx, ny, nz, ima, sup, nsup, False)
    if inv_a + inv_b <= 0.0:
        return kicked
    force = -pressing / (inv_a + inv_b)
    if inv_a > 0.0:
        acc[a, 0] += ax * force * ima_a
        acc[a, 1] += ay * force * ima_a
        acc[a, 2] += az * force * ima_a
    if inv_b > 0.0:
        acc[b, 0] += bx * force * ima[b]
        acc[b, 1] += by * force * ima[b]
        acc[b, 2] += bz * force * ima[b]
    # What rests on a support that holds (a static, a kinematic body, a supported body) is
    # supported too, along this contact's normal.
    if a < 0 or ima_a == 0.0 or nsup[a] > 0:
        if nsup[b] < MAX_SUPPORTS and ima[b] > 0.0:
            sup[b, nsup[b], 0] = nx
            sup[b, nsup[b], 1] = ny
            sup[b, nsup[b], 2] = nz
            nsup[b] += 1
    elif (ima[b] == 0.0 or nsup[b] > 0) and nsup[a] < MAX_SUPPORTS:
        sup[a, nsup[a], 0] = -nx
        sup[a, nsup[a], 1] = -ny
        sup[a, nsup[a], 2] = -nz
        nsup[a] += 1
    rest[c] = 1
    touching[c] = 1
    return 1


def _unchanged_since(seen: Any, changed: Any, c: int, a: int, b: int, start: int) -> bool:
    """Whether pair ``c`` (bodies ``a``, ``b``) was looked at since tick ``start`` and neither
    body changed since: :func:`_rest` would then return 0 again (it did, or the pair would
    rest or a body would have changed)."""
    if seen[c] < start or changed[b] >= seen[c]:
        return False
    return bool(a < 0 or changed[a] < seen[c])


def _base_accelerations(acc: Any, ima: Any, gravity: Any, nsup: Any) -> None:
    """:func:`_base_acceleration` for every body."""
    for i in range(acc.shape[0]):
        _base_acceleration(i, acc, ima, gravity, nsup)


def _rest_passes(
    order: Any,
    n_near: int,
    seen: Any,
    changed_at: Any,
    ca: Any,
    cb: Any,
    normals: Any,
    kind: Any,
    vel: Any,
    ext: Any,
    ima: Any,
    acc: Any,
    sup: Any,
    nsup: Any,
    s_kind: Any,
    rest: Any,
    touching: Any,
    rest_speed: float,
    ledger: Any,
) -> None:
    """Phase 2's passes over the pairs in contact, in ``order`` (the first ``n_near``), until one
    changes nothing (a stack of k bodies settles in k passes). A pair is looked at again only once
    one of its bodies changed since (:func:`_rest` returns 0 again otherwise)."""
    n = vel.shape[0]
    for i in range(n):
        changed_at[i] = 0
    stamp = 0
    for _pass in range(n + 1):
        changed = False
        for u in range(n_near):
            c = order[u]
            if rest[c] == 1:
                continue
            a = ca[c]
            b = cb[c]
            if seen[c] > 0 and changed_at[b] < seen[c] and (a < 0 or changed_at[a] < seen[c]):
                continue
            stamp += 1
            seen[c] = stamp
            done = _rest(
                c, a, b, normals[c, 0], normals[c, 1], normals[c, 2], kind, vel, ext, ima, acc, sup, nsup, s_kind,
                rest, touching, rest_speed, ledger,
            )  # fmt: skip
            if done != 0:
                changed_at[b] = stamp
                if a >= 0:
                    changed_at[a] = stamp
                changed = changed or done == 1
        if not changed:
            break
