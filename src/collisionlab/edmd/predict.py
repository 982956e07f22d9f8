"""Times of impact, exact, from a body's current state: pairs, walls, and leaving the neighbour list.

Bodies fly on straight lines, or on parabolas under gravity ``g`` along ``-y``. Every body has
the same acceleration, so the *relative* motion of two bodies is a straight line even under
gravity, and a pair's time of impact is the smaller root of one quadratic (Ericson, *Real-Time
Collision Detection*, 5.5.8; Smallenburg, Eur. Phys. J. E 45, 22 (2022), eq. 2):

    |dr + dv t|^2 = sigma^2,   t = (-b - sqrt(b^2 - v^2 a)) / v^2
    with b = dr . dv < 0 (approaching), a = |dr|^2 - sigma^2, v^2 = |dv|^2.

It is evaluated as ``t = a / (-b + sqrt(b^2 - v^2 a))`` (the same root, no cancellation when
``a`` is small: two bodies just apart). A body against a wall solves a linear equation, or
under gravity the wall perpendicular to ``y`` a quadratic whose root is picked by the sign of
the velocity at contact. All functions return a time from now (>= 0), ``inf`` for never.

>>> contact_time(3.0, 0.0, 0.0, -1.0, 0.0, 0.0, 4.0)   # gap 3 - 2 = 1 closed at speed 1
1.0
>>> round(floor_time(3.0, 0.0, 1.0, 2.0), 12)                   # fall 2 under g = 2: sqrt(2)
1.414213562373
"""

from __future__ import annotations

import math

from ..engine import contact_law as cl
from ..engine import geometry_kernels as gk
from .compile import jit_call, jit_inline

__all__ = [
    "ceiling_time",
    "collision_loss",
    "contact_time",
    "floor_time",
    "impulse_magnitude",
    "leave_time",
    "pushed_velocity",
    "wall_time",
]

#: Two balls' time of impact, tested against every neighbour (no ``tmin``: see
#: :func:`~collisionlab.engine.geometry_kernels.time_of_impact_ball_ball`, why without branches),
#: the first root of a gap along a normal (a wall's, in flight or under gravity), and the contact
#: law with its ledger term (what theory says a collision takes): the engine's kernels, written
#: once there, compiled into the loop here.
#: Inlined by numba (never compiled on their own here): the engine's compiled copy of the same
#: source shares numba's cache entry for a function compiled on its own, and a process that
#: loaded this one from it would look for that copy's module.
contact_time = jit_inline(gk.time_of_impact_ball_ball)
first_root = jit_inline(gk.first_root)
impulse_magnitude = jit_inline(cl.impulse_magnitude)
collision_loss = jit_inline(cl.collision_loss)
pushed_velocity = jit_inline(cl.pushed_velocity)


@jit_call
def wall_time(x: float, v: float, lo: float, hi: float) -> float:
    """Time until a centre at ``x`` moving at ``v`` reaches ``lo`` (moving down) or ``hi``
    (moving up): straight flight, the gap to the wall closing at ``|v|`` (the engine's root of a
    gap along a normal, :func:`~collisionlab.engine.geometry_kernels.first_root`). 0 if it is
    already past the wall and still moving out.

    >>> wall_time(1.0, 2.0, 0.5, 4.0), wall_time(1.0, -2.0, 0.5, 4.0), wall_time(5.0, 1.0, 0.5, 4.0)
    (1.5, 0.25, 0.0)
    """
    if v > 0.0:
        gap = hi - x
        closing = -v
    elif v < 0.0:
        gap = x - lo
        closing = v
    else:
        return math.inf
    return first_root(gap, closing, 0.0, math.inf) if gap > 0.0 else 0.0


@jit_call
def floor_time(y: float, vy: float, g: float, lo: float) -> float:
    """Time until a centre at height ``y`` with upward speed ``vy`` under gravity ``g > 0``
    comes down to ``lo``: the root of ``y + vy t - g t^2 / 2 = lo`` at which it moves down (from
    above, the gap's first root: :func:`~collisionlab.engine.geometry_kernels.first_root`).

    A centre below ``lo`` by rounding that still moves up turns at its apex, ``t = vy / g``,
    and is met there (where it starts to move into the floor).

    >>> floor_time(1.0, 0.0, 2.0, 0.0), floor_time(0.0, 2.0, 2.0, 0.0), floor_time(-1.0, -1.0, 2.0, 0.0)
    (1.0, 2.0, 0.0)
    """
    h = y - lo
    if h > 0.0:
        return first_root(h, vy, -0.5 * g, math.inf)
    if vy <= 0.0:
        return 0.0
    disc = vy * vy + 2.0 * g * h
    if disc < 0.0:
        return vy / g
    return (vy + math.sqrt(disc)) / g


@jit_call
def ceiling_time(y: float, vy: float, g: float, hi: float) -> float:
    """Time until a centre at ``y`` rising at ``vy`` under gravity ``g > 0`` reaches ``hi``
    (the first root of ``y + vy t - g t^2 / 2 = hi``:
    :func:`~collisionlab.engine.geometry_kernels.first_root` of the gap ``hi - y``); ``inf`` if
    it turns back below it.

    >>> ceiling_time(0.0, 3.0, 2.0, 2.0), ceiling_time(0.0, 1.0, 2.0, 2.0)   # 3t - t^2 = 2 first at t = 1
    (1.0, inf)
    """
    h = hi - y
    if vy <= 0.0:
        return math.inf
    if h <= 0.0:
        return 0.0
    return first_root(h, -vy, 0.5 * g, math.inf)


@jit_call
def leave_time(dx: float, dy: float, dz: float, vx: float, vy: float, vz: float, g: float, skin: float) -> float:
    """Time until a body ``dr`` from its neighbour-list centre, moving at ``v``, is ``skin``
    from it. Straight flight: the root of ``|dr + v t| = skin``. Under gravity a bound that
    comes no later than the truth: ``|dr| + |v| t + g t^2 / 2 = skin`` (the triangle inequality).
    """
    d2 = dx * dx + dy * dy + dz * dz
    v2 = vx * vx + vy * vy + vz * vz
    q = skin * skin - d2
    if q <= 0.0:
        return 0.0
    if g > 0.0:
        room = skin - math.sqrt(d2)
        if room <= 0.0:
            return 0.0
        v = math.sqrt(v2)
        return 2.0 * room / (v + math.sqrt(v2 + 2.0 * g * room))
    if v2 == 0.0:
        return math.inf
    b = dx * vx + dy * vy + dz * vz
    root = math.sqrt(b * b + v2 * q)
    if b > 0.0:
        return q / (b + root)
    return (root - b) / v2
