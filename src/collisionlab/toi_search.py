"""The search behind :mod:`collisionlab.toi`'s time of impact of two translating shapes: the
exact stepper's own time of impact
(:func:`collisionlab.engine.pair_time_of_impact._time_of_impact`, conservative advancement along
the separating normal, with the closed form for two balls in straight flight) run on a two-body
state, A at rest at the origin (a line or plane as a static obstacle) and B moving with the
relative motion, in a frame scaled by powers of two (exact) so that the pair's size and
``max_time`` are about 1 (:mod:`collisionlab.toi` states the semantics and the range). Owns
:class:`Impact`, the result, and :func:`first_impact`, what every pair's query calls.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .contact import Separation
from .engine import pair_time_of_impact as et
from .engine.shape_rows import body_row, static_row
from .errors import OutOfRangeError, UnsupportedPairError
from .shapes import AABB, Circle, Line, Plane, Shape, Sphere
from .tolerances import TOI_TOUCH
from .vector import Vector3D

__all__ = ["Impact", "first_impact", "too_large"]

#: In the scaled frame (module docstring): the largest offset or speed (the kernel squares them:
#: below 2^1010), the largest acceleration (it only multiplies a gap of about 1), and the
#: smallest extent (its square must not vanish beside the size's).
_LARGEST_SCALED = 2.0**500
_LARGEST_SCALED_ACCELERATION = 2.0**1000
_SMALLEST_SCALED = 2.0**-250
#: Rounds of the kernel's iteration (each at most ``pair_time_of_impact.TOI_ITERATIONS`` steps)
#: before a touch not yet within ``TOI_TOUCH`` is taken as reached: conservative advancement never
#: passes the touch, so the time then is at most rounding early.
_ROUNDS = 16


@dataclass(frozen=True, slots=True)
class Impact:
    """The first touch of two moving shapes.

    ``time`` is in ``[0, max_time]``; ``normal`` is the unit contact normal at that time, from
    shape A to shape B; ``initially_overlapping`` is True when the shapes already touched or
    overlapped at ``t = 0`` (narrowphase distance <= 0) and were not separating (then
    ``time == 0.0``).

    >>> Impact(0.5, Vector3D(0, 1, 0), False).flipped()
    Impact(time=0.5, normal=Vector3D(x=0.0, y=-1.0, z=0.0), initially_overlapping=False)
    """

    time: float
    normal: Vector3D
    initially_overlapping: bool

    def flipped(self) -> Impact:
        """The same impact seen from B: the normal reversed."""
        return Impact(self.time, -self.normal, self.initially_overlapping)


def too_large() -> OutOfRangeError:
    """The error for a motion whose numbers the scaled search cannot hold (module docstring)."""
    return OutOfRangeError(
        "time of impact: the motion's numbers are too large to solve (it covers more than 2^500 times the "
        "pair's size within max_time, or a shape is below 2^-250 of it); see collisionlab.toi for the range"
    )


def _power_of_two(x: float) -> float:
    """The power of two nearest above ``x > 0`` (scaling by it is exact)."""
    return math.ldexp(1.0, math.frexp(x)[1])


def _separating(normal: Vector3D, velocity: Vector3D, acceleration: Vector3D) -> bool:
    """Whether the distance grows at ``t = 0``: ``v.n > 0``, or ``v.n == 0`` and ``g.n > 0``."""
    normal_speed = normal.dot(velocity)
    if normal_speed != 0.0:
        return normal_speed > 0.0
    return normal.dot(acceleration) > 0.0


def first_impact(
    a: Shape, b: Shape, start: Separation, velocity: Vector3D, acceleration: Vector3D, max_time: float
) -> Impact | None:
    """The module docstring's semantics: time 0 for a pair touching and not separating, else the
    kernel's search."""
    if start.distance <= 0.0 and not _separating(start.normal, velocity, acceleration):
        return Impact(0.0, start.normal, True)
    return _search(a, b, velocity, acceleration, max_time)


def _key(shape: Shape) -> tuple[tuple[float, ...], ...]:
    if isinstance(shape, AABB):
        return shape.min_corner.as_tuple(), shape.max_corner.as_tuple()
    if isinstance(shape, (Circle, Sphere)):
        return shape.center.as_tuple(), (shape.radius,)
    return shape.point.as_tuple(), shape.unit_normal.as_tuple()


def _centre(shape: Shape) -> Vector3D:
    if isinstance(shape, (Line, Plane)):
        raise UnsupportedPairError(f"a {type(shape).__name__} cannot be the moving shape B of a pair")
    return shape.center


def _search(a: Shape, b: Shape, velocity: Vector3D, acceleration: Vector3D, max_time: float) -> Impact | None:
    """Run the exact stepper's time of impact on A (at rest, at the origin) and B (moving with
    the relative motion), in the scaled frame of the module docstring. Two shapes of one type are
    taken in one order whichever comes first, so the mirrored query rounds alike."""
    if type(a) is type(b) and _key(b) < _key(a):
        impact = _search(b, a, -velocity, -acceleration, max_time)
        return None if impact is None else impact.flipped()
    static = isinstance(a, (Line, Plane))
    origin = a.point if isinstance(a, (Line, Plane)) else a.center
    kind_a, ext_a = (0, (0.0, 0.0, 0.0)) if static else body_row(a)
    kind_b, ext_b = body_row(b)
    with np.errstate(over="ignore", invalid="ignore"):
        offset = np.subtract(_centre(b).as_tuple(), origin.as_tuple())  # may overflow: checked below
        extents = [*ext_a, *ext_b]
        size = _power_of_two(max(float(np.max(np.abs(offset))), *extents))
        span = _power_of_two(max_time) if max_time > 0.0 else 1.0
        vel = np.array(velocity.as_tuple()) * span / size
        acc = np.array(acceleration.as_tuple()) * (span * span) / size
    smallest = min((x for x in extents if x > 0.0), default=size) / size  # a point box has no extent
    if (
        not np.all(np.abs(np.concatenate([offset / size, vel])) < _LARGEST_SCALED)
        or not np.all(np.abs(acc) < _LARGEST_SCALED_ACCELERATION)
        or smallest < _SMALLEST_SCALED
    ):
        raise too_large()
    rows = 1 if static else 2
    kind = np.full(rows, kind_b, np.int64)
    pos = np.zeros((rows, 3))
    vels = np.zeros((rows, 3))
    accs = np.zeros((rows, 3))
    ext = np.zeros((rows, 3))
    pos[-1], vels[-1], accs[-1], ext[-1] = offset / size, vel, acc, np.divide(ext_b, size)
    s_kind, s_a, s_b = np.zeros(1, np.int64), np.zeros((1, 3)), np.zeros((1, 3))
    if static:
        s_kind[0], _, s_b[0] = static_row(a)  # its point is the origin
    else:
        kind[0], ext[0] = kind_a, np.divide(ext_a, size)
    ia, ib = (-1, 0) if static else (0, 1)
    state = (kind, pos, vels, accs, np.zeros(rows), ext, s_kind, s_a, s_b, ia, ib)
    k2, p2, v2, e2 = np.zeros(2, np.int64), np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 3))
    end = math.nextafter(max_time / span, math.inf)  # max_time itself included
    t = 0.0
    for _ in range(_ROUNDS):
        with np.errstate(all="ignore"):  # a root beyond the range is inf (no touch), as compiled
            reached = et._time_of_impact(*state, t, end, 0.0, -math.inf, -math.inf)
            if reached == math.inf:
                return None
            sep = et._separation_at(*state, reached, k2, p2, v2, e2)
        if not all(math.isfinite(x) for x in sep[:4]):
            raise too_large()
        if sep[0] <= TOI_TOUCH or reached <= t:
            break
        t = reached
    return Impact(min(float(reached) * span, max_time), Vector3D(sep[1], sep[2], sep[3]), False)
