"""Time of impact (continuous collision detection) for translating shapes (Ericson, Real-Time
Collision Detection, section 5.5, "Dynamic intersection tests").

Shapes only translate. Everything depends on the motion of B seen from A: the relative velocity
``v = v_b - v_a`` and the relative acceleration ``g = acc_b - acc_a``, so that B's offset from
its start is ``d(t) = v t + g t^2 / 2`` (a straight line, or a parabola under constant gravity;
both exact). Each pair is written once, as ``time_of_impact_<a>_<b>(a, b, relative_velocity,
relative_acceleration, max_time)``, in the pair order of :mod:`collisionlab.narrowphase`; the
mirrored order is derived with :meth:`Impact.flipped` (the relative motion negated, the normal
negated). :func:`time_of_impact` dispatches on the shapes' types, in either order.

Written once: the search is the exact stepper's own time of impact
(:func:`collisionlab.engine.pair_time_of_impact._time_of_impact`, conservative advancement along
the separating normal, with the closed form for two balls in straight flight), run on a two-body
state: A at rest at the origin (a line or plane as a static obstacle), B moving with the
relative motion (:mod:`collisionlab.toi_search`). What ``collisionlab run --mode exact`` computes
for a pair is what this returns.

Semantics (the same for every pair)
-----------------------------------
The answer is the first time ``t`` in ``[0, max_time]`` (both ends included) at which the shapes
come into touch while approaching: the signed distance reaches 0 coming from > 0, to the
precision of doubles (the returned time rounds the touching time; moved to it, the narrowphase
distance is 0 to within ``TOI_TOUCH`` of the pair's size). A graze, where the distance touches 0
at a single instant, counts when its closed form finds it (two balls in straight flight, a ball
or box along a line's or plane's normal); elsewhere a graze is at the edge of rounding.

At ``t = 0`` the shapes may already touch or overlap (narrowphase distance <= 0). With ``n`` the
narrowphase normal at ``t = 0`` (from A to B), they are *separating* when ``v.n > 0``, or when
``v.n == 0`` exactly and ``g.n > 0``; otherwise (approaching, or at rest relative to each other,
or sliding along each other) they are *not separating* and the result is
``Impact(0.0, n, initially_overlapping=True)``. When they overlap but are separating, the present
contact is ignored and the result is the time the gap along ``n`` closes again, if it does:
possible only with acceleration, e.g. a ball leaving a floor upwards under gravity and falling
back.

The contact normal at the impact follows narrowphase's conventions: unit, from A to B; a line or
plane's normal points to the side the other shape arrives from.

Range: the search runs in a frame scaled by powers of two (exact) so that the pair's size (B's
offset from A and the shapes' extents) is about 1 and ``max_time`` is about 1. A motion that
covers more than ``2^500`` such sizes within ``max_time`` (``2^1000`` by acceleration alone),
or a shape smaller than ``2^-250`` of it, is refused with
:class:`~collisionlab.errors.OutOfRangeError` (its squares would overflow or vanish, and a
touch could be missed silently).

For a stepper that moves bodies to the returned time and resolves: called again from that
touching state, an approaching pair reports time 0 (``initially_overlapping`` True), and a pair
whose velocity was resolved to separate is not reported again unless acceleration brings it
back. A pair in resting or sliding contact (``v.n == 0`` and ``g.n <= 0``, e.g. a ball lying on
a floor under gravity) is *not* separating: it reports time 0 on every call.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from .errors import InvalidInputError, UnsupportedPairError
from .narrowphase import (
    separation_aabb_aabb,
    separation_circle_aabb,
    separation_circle_circle,
    separation_line_aabb,
    separation_line_circle,
    separation_plane_aabb,
    separation_plane_sphere,
    separation_sphere_aabb,
    separation_sphere_sphere,
)
from .shapes import AABB, Circle, Line, Plane, Shape, Sphere
from .toi_search import Impact, first_impact, too_large
from .validate import non_negative
from .vector import Vector3D, VectorLike, as_vector

__all__ = [
    "Impact",
    "time_of_impact",
    "time_of_impact_aabb_aabb",
    "time_of_impact_circle_aabb",
    "time_of_impact_circle_circle",
    "time_of_impact_line_aabb",
    "time_of_impact_line_circle",
    "time_of_impact_plane_aabb",
    "time_of_impact_plane_sphere",
    "time_of_impact_sphere_aabb",
    "time_of_impact_sphere_sphere",
    "toi_supported_pairs",
]


# --- input checks -----------------------------------------------------------------------------------
def _checked(
    velocity: VectorLike, acceleration: VectorLike, max_time: float, planar: bool
) -> tuple[Vector3D, Vector3D, float]:
    v = as_vector(velocity, "relative_velocity")
    g = as_vector(acceleration, "relative_acceleration")
    t = non_negative(max_time, "max_time")
    if planar:
        for field, value in (("relative_velocity", v), ("relative_acceleration", g)):
            _require_planar_motion(field, value)
    return v, g, t


def _require_planar_motion(field: str, value: Vector3D) -> None:
    if value.z != 0.0:
        raise InvalidInputError(field, "must have z = 0 for a 2D pair of shapes", got=value.as_tuple())


def _is_planar(shape: Shape) -> bool:
    return isinstance(shape, (Circle, Line)) or (isinstance(shape, AABB) and shape.dim == 2)


# --- one function per pair ----------------------------------------------------------------------------
def time_of_impact_circle_circle(
    a: Circle, b: Circle, relative_velocity: VectorLike, relative_acceleration: VectorLike, max_time: float
) -> Impact | None:
    """Circle-circle (Ericson 5.5.5): ``|p + v t + g t^2/2| = r_a + r_b``; with ``g = 0`` the
    quadratic ``(v.v) t^2 + 2 (p.v) t + (p.p - R^2) = 0`` in closed form.

    >>> impact = time_of_impact_circle_circle(Circle((0, 0), 1), Circle((5, 0), 1), (-2, 0), (0, 0), 10)
    >>> impact.time, impact.normal   # the gap 5 - 2 = 3 closes at 2 per unit time: t = 1.5
    (1.5, Vector3D(x=1.0, y=0.0, z=0.0))
    """
    v, g, t = _checked(relative_velocity, relative_acceleration, max_time, planar=True)
    start = separation_circle_circle(a, b)
    return first_impact(a, b, start, v, g, t)


def time_of_impact_sphere_sphere(
    a: Sphere, b: Sphere, relative_velocity: VectorLike, relative_acceleration: VectorLike, max_time: float
) -> Impact | None:
    """Sphere-sphere (Ericson 5.5.5): ``|p + v t + g t^2/2| = r_a + r_b``.

    >>> a, b = Sphere((0, 0, 0), 1), Sphere((0, 3, 4), 1.5)
    >>> impact = time_of_impact_sphere_sphere(a, b, (0, -3, -4), (0, 0, 0), 1)
    >>> impact.time, impact.normal   # |p| = 5 closes at 5 per unit time to 2.5: t = 0.5; normal p/|p|
    (0.5, Vector3D(x=0.0, y=0.6, z=0.8))
    >>> time_of_impact_sphere_sphere(a, b, (0, 3, 4), (0, 0, 0), 1) is None   # moving apart
    True
    """
    v, g, t = _checked(relative_velocity, relative_acceleration, max_time, planar=False)
    start = separation_sphere_sphere(a, b)
    return first_impact(a, b, start, v, g, t)


def time_of_impact_aabb_aabb(
    a: AABB, b: AABB, relative_velocity: VectorLike, relative_acceleration: VectorLike, max_time: float
) -> Impact | None:
    """AABB-AABB in 2D or 3D (Ericson 5.5.8): every axis's intervals overlap; the normal is along
    the axis that closed last.

    >>> impact = time_of_impact_aabb_aabb(AABB((0, 0), (1, 1)), AABB((3, 0.5), (4, 1.5)), (-1, 0), (0, 0), 5)
    >>> impact.time, impact.normal   # x gap 3 - 1 = 2 at speed 1; y already overlaps
    (2.0, Vector3D(x=1.0, y=0.0, z=0.0))
    >>> time_of_impact_aabb_aabb(AABB((0, 0), (1, 1)), AABB((3, 2), (4, 3)), (-1, 0), (0, 0), 5) is None
    True
    """
    v, g, t = _checked(relative_velocity, relative_acceleration, max_time, planar=a.dim == 2 and b.dim == 2)
    start = separation_aabb_aabb(a, b)  # refuses a 2D box with a 3D box
    return first_impact(a, b, start, v, g, t)


def time_of_impact_line_circle(
    a: Line, b: Circle, relative_velocity: VectorLike, relative_acceleration: VectorLike, max_time: float
) -> Impact | None:
    """Line-circle (Ericson 5.5.3 in 2D): ``|s0 + (n.v) t + (n.g) t^2/2| = r``.

    >>> impact = time_of_impact_line_circle(Line((0, 0), (1, 0)), Circle((0, 5), 1), (3, -2), (0, 0), 10)
    >>> impact.time, impact.normal   # s0 = 5, n.v = -2: 5 - 2t = 1 at t = 2
    (2.0, Vector3D(x=0.0, y=1.0, z=0.0))
    """
    v, g, t = _checked(relative_velocity, relative_acceleration, max_time, planar=True)
    start = separation_line_circle(a, b)
    return first_impact(a, b, start, v, g, t)


def time_of_impact_plane_sphere(
    a: Plane, b: Sphere, relative_velocity: VectorLike, relative_acceleration: VectorLike, max_time: float
) -> Impact | None:
    """Plane-sphere (Ericson 5.5.3): ``|s0 + (n.v) t + (n.g) t^2/2| = r``.

    A ball dropped from rest with its centre at height 5.9, radius 1, under g = 9.8: it touches
    when ``4.9 t^2 = 4.9``, at t = 1.

    >>> floor = Plane((0, 0, 0), (0, 0, 1))
    >>> impact = time_of_impact_plane_sphere(floor, Sphere((0, 0, 5.9), 1), (0, 0, 0), (0, 0, -9.8), 2)
    >>> round(impact.time, 15), impact.normal
    (1.0, Vector3D(x=0.0, y=0.0, z=1.0))
    """
    v, g, t = _checked(relative_velocity, relative_acceleration, max_time, planar=False)
    start = separation_plane_sphere(a, b)
    return first_impact(a, b, start, v, g, t)


def time_of_impact_circle_aabb(
    a: Circle, b: AABB, relative_velocity: VectorLike, relative_acceleration: VectorLike, max_time: float
) -> Impact | None:
    """Circle-AABB in 2D (Ericson 5.5.7): the circle's centre meets the box grown by ``r`` (faces,
    and circles of radius ``r`` about the corners).

    >>> box = AABB((2, -1), (4, 1))
    >>> impact = time_of_impact_circle_aabb(Circle((0, 0), 1), box, (-1, 0), (0, 0), 5)
    >>> impact.time, impact.normal   # the face x = 2 meets the circle's rim x = 1 at t = 1
    (1.0, Vector3D(x=1.0, y=0.0, z=0.0))
    >>> impact = time_of_impact_circle_aabb(Circle((-1, 5), 1), box, (-3, 4), (0, 0), 5)
    >>> impact.time   # centre (-1 + 3t, 5 - 4t) to corner (2, 1): 25 (1 - t)^2 = 1 at t = 0.8
    0.8
    >>> [round(c, 12) for c in impact.normal]   # from the centre (1.4, 1.8) to the corner
    [0.6, -0.8, 0.0]
    """
    v, g, t = _checked(relative_velocity, relative_acceleration, max_time, planar=True)
    start = separation_circle_aabb(a, b)  # refuses a 3D box
    return first_impact(a, b, start, v, g, t)


def time_of_impact_sphere_aabb(
    a: Sphere, b: AABB, relative_velocity: VectorLike, relative_acceleration: VectorLike, max_time: float
) -> Impact | None:
    """Sphere-AABB (Ericson 5.5.7): the centre meets the box grown by ``r`` (faces, edges'
    cylinders, corners' balls); a 2D box is the flat box at z = 0.

    >>> box = AABB((-1, -1, -1), (1, 1, 1))
    >>> impact = time_of_impact_sphere_aabb(Sphere((0, 0, 5), 1), box, (0, 0, 2), (0, 0, 0), 5)
    >>> impact.time, impact.normal   # gap 5 - 1 - 1 = 3 at speed 2
    (1.5, Vector3D(x=0.0, y=0.0, z=-1.0))
    """
    v, g, t = _checked(relative_velocity, relative_acceleration, max_time, planar=False)
    start = separation_sphere_aabb(a, b)
    return first_impact(a, b, start, v, g, t)


def time_of_impact_line_aabb(
    a: Line, b: AABB, relative_velocity: VectorLike, relative_acceleration: VectorLike, max_time: float
) -> Impact | None:
    """Line-AABB in 2D: the box's support distance ``h = |n_x| e_x + |n_y| e_y`` (Ericson 5.5.4).

    >>> impact = time_of_impact_line_aabb(Line((0, 0), (1, 0)), AABB((0, 4), (2, 6)), (0, -2), (0, 0), 5)
    >>> impact.time   # centre y = 5, h = 1: 5 - 2t = 1 at t = 2
    2.0
    """
    v, g, t = _checked(relative_velocity, relative_acceleration, max_time, planar=True)
    start = separation_line_aabb(a, b)  # refuses a 3D box
    return first_impact(a, b, start, v, g, t)


def time_of_impact_plane_aabb(
    a: Plane, b: AABB, relative_velocity: VectorLike, relative_acceleration: VectorLike, max_time: float
) -> Impact | None:
    """Plane-AABB (Ericson 5.5.4): ``|s(t)| = h`` with ``h = sum_i |n_i| e_i``.

    >>> plane = Plane((0, 0, 0), (1, 1, 0))
    >>> impact = time_of_impact_plane_aabb(plane, AABB((4, 4, 0), (6, 6, 2)), (-1, -1, 0), (0, 0, 0), 5)
    >>> round(impact.time, 12)   # s0 = 10/sqrt2, h = 2/sqrt2, n.v = -2/sqrt2: t = (10 - 2)/2 = 4
    4.0
    """
    v, g, t = _checked(relative_velocity, relative_acceleration, max_time, planar=False)
    start = separation_plane_aabb(a, b)
    return first_impact(a, b, start, v, g, t)


# --- dispatch -----------------------------------------------------------------------------------------
_TABLE: dict[tuple[type, type], Callable[[Any, Any, Vector3D, Vector3D, float], Impact | None]] = {
    (Circle, Circle): time_of_impact_circle_circle,
    (Sphere, Sphere): time_of_impact_sphere_sphere,
    (AABB, AABB): time_of_impact_aabb_aabb,
    (Line, Circle): time_of_impact_line_circle,
    (Plane, Sphere): time_of_impact_plane_sphere,
    (Circle, AABB): time_of_impact_circle_aabb,
    (Sphere, AABB): time_of_impact_sphere_aabb,
    (Line, AABB): time_of_impact_line_aabb,
    (Plane, AABB): time_of_impact_plane_aabb,
}


def toi_supported_pairs() -> list[tuple[str, str]]:
    """The shape pairs that have a time-of-impact query (each also works in the mirrored order)."""
    return [(a.__name__, b.__name__) for a, b in _TABLE]


def time_of_impact(
    a: Shape,
    b: Shape,
    velocity_a: VectorLike,
    velocity_b: VectorLike,
    max_time: float,
    acceleration_a: VectorLike = (0.0, 0.0, 0.0),
    acceleration_b: VectorLike = (0.0, 0.0, 0.0),
) -> Impact | None:
    """The first touch of ``a`` and ``b`` moving with constant velocities (and accelerations)
    within ``[0, max_time]``, with the contact normal from ``a`` to ``b``, or ``None``.

    See the module docstring for the exact semantics. For a 2D pair (circles, lines and 2D
    boxes only) every velocity and acceleration must have ``z = 0``.

    >>> time_of_impact(Sphere((0, 0, 10), 1), Plane((0, 0, 0), (0, 0, 1)), (0, 0, -1e6), (0, 0, 0), 1).time
    9e-06
    >>> time_of_impact(Sphere((0, 0, 1), 1), Plane((0, 0, 0), (0, 0, 1)), (0, 0, 0), (0, 0, 0), 1)
    Impact(time=0.0, normal=Vector3D(x=0.0, y=0.0, z=-1.0), initially_overlapping=True)
    >>> time_of_impact(Circle((0, 0), 1), Sphere((0, 0, 0), 1), (0, 0), (0, 0), 1)
    Traceback (most recent call last):
    ...
    collisionlab.errors.UnsupportedPairError: no time-of-impact query for Circle and Sphere; supported pairs: \
Circle-Circle, Sphere-Sphere, AABB-AABB, Line-Circle, Plane-Sphere, Circle-AABB, Sphere-AABB, \
Line-AABB, Plane-AABB (either order)
    """
    va = as_vector(velocity_a, "velocity_a")
    vb = as_vector(velocity_b, "velocity_b")
    t = non_negative(max_time, "max_time")
    ga = as_vector(acceleration_a, "acceleration_a")
    gb = as_vector(acceleration_b, "acceleration_b")
    if _is_planar(a) and _is_planar(b):
        for field, value in (("velocity_a", va), ("velocity_b", vb), ("acceleration_a", ga), ("acceleration_b", gb)):
            _require_planar_motion(field, value)
    query = _TABLE.get((type(a), type(b)))
    mirrored = _TABLE.get((type(b), type(a)))
    try:
        if query is not None:
            return query(a, b, vb - va, gb - ga, t)
        if mirrored is not None:
            impact = mirrored(b, a, va - vb, ga - gb, t)
            return None if impact is None else impact.flipped()
    except InvalidInputError as error:  # a position or normal at the impact overflowed to inf
        if isinstance(error.got, float) and not math.isfinite(error.got):
            raise too_large() from None
        raise
    except (OverflowError, ZeroDivisionError, ValueError):  # no raw arithmetic error escapes
        raise too_large() from None
    names = ", ".join(f"{x}-{y}" for x, y in toi_supported_pairs())
    raise UnsupportedPairError(
        f"no time-of-impact query for {type(a).__name__} and {type(b).__name__}; supported pairs: {names} "
        "(either order)"
    )
