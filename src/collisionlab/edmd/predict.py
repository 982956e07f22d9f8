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

>>> pair_time(3.0, 0.0, 0.0, -1.0, 0.0, 0.0, 4.0, math.inf)   # gap 3 - 2 = 1 closed at speed 1
1.0
>>> round(floor_time(3.0, 0.0, 1.0, 2.0), 12)                   # fall 2 under g = 2: sqrt(2)
1.414213562373
"""

from __future__ import annotations

import math

from .compile import jit_inline

__all__ = ["ceiling_time", "contact_time", "floor_time", "leave_time", "pair_time", "wall_time"]


@jit_inline
def pair_time(dx: float, dy: float, dz: float, dvx: float, dvy: float, dvz: float, sigma2: float, tmin: float) -> float:
    """Time until two balls ``sigma = sqrt(sigma2)`` apart (centre to centre) touch, given their
    relative position ``dr`` and velocity ``dv``; ``inf`` if they miss, move apart, or cannot
    meet before ``tmin``. Touching or overlapping and approaching: 0 (collide now)."""
    b = dx * dvx + dy * dvy + dz * dvz
    if b >= 0.0:
        return math.inf
    a = dx * dx + dy * dy + dz * dz - sigma2
    # The root is at least a / (-2 b) (the square root is at most -b): prune without it.
    if a > -2.0 * b * tmin:
        return math.inf
    v2 = dvx * dvx + dvy * dvy + dvz * dvz
    disc = b * b - v2 * a
    if disc <= 0.0:
        return math.inf
    if a <= 0.0:
        return 0.0
    return a / (-b + math.sqrt(disc))


@jit_inline
def contact_time(dx: float, dy: float, dz: float, dvx: float, dvy: float, dvz: float, sigma2: float) -> float:
    """:func:`pair_time` with no ``tmin`` (the same value as ``pair_time(..., inf)``), computed
    without branches: the event loop tests every neighbour, and whether a pair approaches is a
    coin toss the processor cannot predict, so a mispredicted branch cost more than always taking
    the square root and the division. A pruned pair (see :func:`pair_time`) meets later than
    ``tmin``, so testing it in full never changes which neighbour is soonest.

    >>> contact_time(3.0, 0.0, 0.0, -1.0, 0.0, 0.0, 4.0), contact_time(3.0, 0.0, 0.0, 1.0, 0.0, 0.0, 4.0)
    (1.0, inf)
    """
    b = dx * dvx + dy * dvy + dz * dvz
    a = dx * dx + dy * dy + dz * dz - sigma2
    v2 = dvx * dvx + dvy * dvy + dvz * dvz
    disc = b * b - v2 * a
    # max(): a miss (disc < 0) would take the root of a negative; its time is discarded below.
    root = a / (-b + math.sqrt(max(disc, 0.0)))
    t = 0.0 if a <= 0.0 else root
    return t if (b < 0.0) & (disc > 0.0) else math.inf


@jit_inline
def wall_time(x: float, v: float, lo: float, hi: float) -> float:
    """Time until a centre at ``x`` moving at ``v`` reaches ``lo`` (moving down) or ``hi``
    (moving up): straight flight. 0 if it is already past the wall and still moving out."""
    if v > 0.0:
        t = (hi - x) / v
    elif v < 0.0:
        t = (lo - x) / v
    else:
        return math.inf
    return t if t > 0.0 else 0.0


@jit_inline
def floor_time(y: float, vy: float, g: float, lo: float) -> float:
    """Time until a centre at height ``y`` with upward speed ``vy`` under gravity ``g > 0``
    comes down to ``lo``: the root of ``y + vy t - g t^2 / 2 = lo`` at which it moves down.

    A centre below ``lo`` by rounding that still moves up turns at its apex, ``t = vy / g``,
    and is met there (where it starts to move into the floor).
    """
    h = y - lo
    if h <= 0.0 and vy <= 0.0:
        return 0.0
    disc = vy * vy + 2.0 * g * h
    if disc < 0.0:
        return vy / g
    root = math.sqrt(disc)
    if vy > 0.0:
        return (vy + root) / g
    return 2.0 * h / (root - vy)


@jit_inline
def ceiling_time(y: float, vy: float, g: float, hi: float) -> float:
    """Time until a centre at ``y`` rising at ``vy`` under gravity ``g > 0`` reaches ``hi``
    (the first root of ``y + vy t - g t^2 / 2 = hi``); ``inf`` if it turns back below it."""
    h = hi - y
    if vy <= 0.0:
        return math.inf
    if h <= 0.0:
        return 0.0
    disc = vy * vy - 2.0 * g * h
    if disc < 0.0:
        return math.inf
    return 2.0 * h / (vy + math.sqrt(disc))


@jit_inline
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
