"""The reference time of impact, kept for tests only: the exact interval solver that
``collisionlab.toi`` used before it called the engine's kernel (conservative advancement,
:func:`collisionlab.engine.pair_time_of_impact._time_of_impact`). It is an independent oracle: every
touch is a root of a polynomial in ``t`` solved in closed form (degree <= 2) or by monotone
pieces and bisection to adjacent doubles (degree 3-4), with no tolerance.

Its original module text follows.

Time of impact (continuous collision detection) for translating shapes (Ericson, Real-Time
Collision Detection, section 5.5, "Dynamic intersection tests").

Shapes only translate. Everything depends on the motion of B seen from A: the relative velocity
``v = v_b - v_a`` and the relative acceleration ``g = acc_b - acc_a``, so that B's offset from
its start is ``d(t) = v t + g t^2 / 2`` (a straight line, or a parabola under constant gravity;
both exact). Each pair is written once, as ``time_of_impact_<a>_<b>(a, b, relative_velocity,
relative_acceleration, max_time)``, in the pair order of :mod:`collisionlab.narrowphase`; the
mirrored order is derived with :meth:`Impact.flipped` (the relative motion negated, the normal
negated). :func:`time_of_impact` dispatches on the shapes' types, in either order.

Semantics (the same for every pair)
-----------------------------------
The answer is the first time ``t`` in ``[0, max_time]`` (both ends included) at which the shapes
come into touch while approaching: the signed distance reaches 0 coming from > 0. A graze, where
the distance touches 0 at a single instant and grows again, counts (it is a touch); it is found
when the rounded discriminant (or the rounded minimum of the distance polynomial) is <= 0.

At ``t = 0`` the shapes may already touch or overlap (narrowphase distance <= 0). With ``n`` the
narrowphase normal at ``t = 0`` (from A to B), they are *separating* when ``v.n > 0``, or when
``v.n == 0`` exactly and ``g.n > 0``; otherwise (approaching, or at rest relative to each other,
or sliding along each other) they are *not separating* and the result is
``Impact(0.0, n, initially_overlapping=True)``. When they overlap but are separating, the present
contact is ignored and the result is the next touch while approaching, if any: possible only with
acceleration, e.g. a ball leaving a floor upwards under gravity and falling back.

Method: the set of times at which the shapes touch or overlap is a finite union of closed
intervals, each bounded by roots of polynomials in ``t`` of degree <= 2 (linear motion) or <= 4
(accelerated motion through a squared distance). The result is the start of the first interval
(skipping the one that contains ``t = 0`` when separating). Quadratics are solved in closed form
with the stable ``q = -(b + sign(b) sqrt(b^2 - 4ac)) / 2``, roots ``q / a`` and ``c / q``
(Ericson 5.5.3-5.5.5; Numerical Recipes 5.6); cubics and quartics are split into monotone pieces
at the roots of their derivative (found recursively) and each sign change is bisected to adjacent
doubles, i.e. full double precision. No tolerance is used.

The contact normal at the impact follows narrowphase's conventions: unit, from A to B; a line or
plane's normal points to the side the other shape arrives from. The returned time is the exact
touching time rounded to a double: moved to it, the shapes are touching up to rounding (the
narrowphase distance is 0 to within a few ulp of the coordinates, of either sign).

For a stepper that moves bodies to the returned time and resolves: called again from that
touching state, an approaching pair reports time 0 (``initially_overlapping`` True, or False if
rounding left a gap), and a pair whose velocity was resolved to separate is not reported again
unless acceleration brings it back. A pair in resting or sliding contact (``v.n == 0`` and
``g.n <= 0``, e.g. a ball lying on a floor under gravity) is *not* separating: it reports time 0
on every call, and the stepper must treat that as a resting contact rather than an event to
advance to. Two balls under the same gravity have ``g = 0`` and take the closed form; any other
relative acceleration of two balls is supported too (a quartic).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable

from collisionlab.contact import Separation
from collisionlab.errors import OutOfRangeError
from collisionlab.narrowphase import separation
from collisionlab.shapes import AABB, Circle, Line, Plane, Shape, Sphere
from collisionlab.toi import Impact  # the result type only: the search below is its own
from collisionlab.tolerances import FALLBACK_NORMAL
from collisionlab.vector import Vector3D, VectorLike, as_vector

__all__ = ["Impact", "time_of_impact"]

_FALLBACK = Vector3D(*FALLBACK_NORMAL)
_AXES = (Vector3D(1, 0, 0), Vector3D(0, 1, 0), Vector3D(0, 0, 1))


# --- polynomials in t (ascending coefficients) and sets of times -----------------------------------
Poly = tuple[float, ...]
Interval = tuple[float, float]


def _trim(p: Poly) -> Poly:
    """Drop exactly-zero leading coefficients (keep at least the constant)."""
    n = len(p)
    while n > 1 and p[n - 1] == 0.0:
        n -= 1
    return p[:n]


def _eval(p: Poly, t: float) -> float:
    result = 0.0
    for c in reversed(p):
        result = result * t + c
    return result


def _derivative(p: Poly) -> Poly:
    return tuple(i * c for i, c in enumerate(p))[1:] or (0.0,)


def _too_large() -> OutOfRangeError:
    return OutOfRangeError(
        "time of impact: the motion's numbers are too large to solve (a squared distance overflows); "
        "see collisionlab.limits for the range that can be simulated"
    )


def _finite(p: Poly) -> Poly:
    """``p`` when every coefficient is finite: an overflowed one would silently lose a root."""
    if not all(math.isfinite(c) for c in p):
        raise _too_large()
    return p


def _add(*ps: Poly) -> Poly:
    size = max(len(p) for p in ps)
    try:
        return _finite(tuple(math.fsum(p[i] for p in ps if i < len(p)) for i in range(size)))
    except (OverflowError, ValueError):  # fsum: "intermediate overflow", or inf - inf
        raise _too_large() from None


def _square(p: Poly) -> Poly:
    out = [0.0] * (2 * len(p) - 1)
    for i, ci in enumerate(p):
        for j, cj in enumerate(p):
            out[i + j] += ci * cj
    return _finite(tuple(out))


def _motion(start: float, velocity: float, acceleration: float) -> Poly:
    """``x(t) = x0 + v t + g t^2 / 2``."""
    return (start, velocity, 0.5 * acceleration)


def _bisect(p: Poly, lo: float, hi: float, lo_negative: bool) -> float:
    """The root in ``[lo, hi]`` of ``p`` (which changes sign there), to adjacent doubles."""
    while True:
        mid = lo + 0.5 * (hi - lo)
        if mid <= lo or mid >= hi:
            return lo if abs(_eval(p, lo)) <= abs(_eval(p, hi)) else hi
        value = _eval(p, mid)
        if value == 0.0:
            return mid
        if (value < 0.0) == lo_negative:
            lo = mid
        else:
            hi = mid


def _roots(p: Poly, lo: float, hi: float) -> list[float]:
    """The real roots of ``p`` in ``[lo, hi]``, ascending (an identically zero ``p`` has none)."""
    p = _trim(p)
    degree = len(p) - 1
    found: list[float]
    if degree == 0:
        found = []
    elif degree == 1:
        found = [-p[0] / p[1]]
    elif degree == 2:
        c, b, a = p
        if c == 0.0:
            found = [0.0, -b / a]
        else:
            disc = b * b - 4.0 * a * c
            if disc < 0.0:
                found = []
            elif disc == 0.0:
                found = [-0.5 * b / a]
            else:
                q = -0.5 * (b + math.copysign(math.sqrt(disc), b))  # never 0: c != 0
                found = [q / a, c / q]
    else:
        # Monotone pieces between the roots of p', then bisection of each sign change.
        cuts = [lo, *(x for x in _roots(_derivative(p), lo, hi) if lo < x < hi), hi]
        found = []
        for x0, x1 in itertools.pairwise(cuts):
            f0, f1 = _eval(p, x0), _eval(p, x1)
            if f0 == 0.0:
                found.append(x0)
            elif f1 != 0.0 and (f0 < 0.0) != (f1 < 0.0):
                found.append(_bisect(p, x0, x1, f0 < 0.0))
        if _eval(p, hi) == 0.0:
            found.append(hi)
    return sorted({x for x in found if lo <= x <= hi})


def _merge(pieces: list[Interval]) -> list[Interval]:
    """Sorted, disjoint closed intervals covering the same times."""
    merged: list[Interval] = []
    for start, end in sorted(pieces):
        if merged and start <= merged[-1][1]:
            merged[-1] = (merged[-1][0], max(merged[-1][1], end))
        else:
            merged.append((start, end))
    return merged


def _nonpositive(p: Poly, max_time: float) -> list[Interval]:
    """The times in ``[0, max_time]`` where ``p(t) <= 0``, as closed intervals. Membership of
    ``t = 0`` is decided by the exact constant ``p[0]``; each root is a member (a graze)."""
    p = _trim(p)
    if len(p) == 1:
        return [(0.0, max_time)] if p[0] <= 0.0 else []
    roots = [r for r in _roots(p, 0.0, max_time) if 0.0 < r < max_time]
    pieces: list[Interval] = [(r, r) for r in roots]
    if p[0] <= 0.0:
        pieces.append((0.0, 0.0))
    if _eval(p, max_time) <= 0.0:
        pieces.append((max_time, max_time))
    for x0, x1 in itertools.pairwise([0.0, *roots, max_time]):
        if x1 > x0 and _eval(p, x0 + 0.5 * (x1 - x0)) <= 0.0:
            pieces.append((x0, x1))
    return _merge(pieces)


def _intersect(xs: list[Interval], ys: list[Interval]) -> list[Interval]:
    out: list[Interval] = []
    i = j = 0
    while i < len(xs) and j < len(ys):
        start, end = max(xs[i][0], ys[j][0]), min(xs[i][1], ys[j][1])
        if start <= end:
            out.append((start, end))
        if xs[i][1] < ys[j][1]:
            i += 1
        else:
            j += 1
    return out


def _intersect_all(sets: list[list[Interval]]) -> list[Interval]:
    result = sets[0]
    for other in sets[1:]:
        result = _intersect(result, other)
    return result


# --- the common driver ------------------------------------------------------------------------------
def _separating(normal: Vector3D, velocity: Vector3D, acceleration: Vector3D) -> bool:
    """Whether the distance grows at ``t = 0``: ``v.n > 0``, or ``v.n == 0`` and ``g.n > 0``."""
    normal_speed = normal.dot(velocity)
    if normal_speed != 0.0:
        return normal_speed > 0.0
    return normal.dot(acceleration) > 0.0


def _first_impact(
    start: Separation,
    velocity: Vector3D,
    acceleration: Vector3D,
    contact_times: Callable[[], list[Interval]],
    normal_at: Callable[[float], Vector3D],
) -> Impact | None:
    overlapping = start.distance <= 0.0
    separating = _separating(start.normal, velocity, acceleration)
    if overlapping and not separating:
        return Impact(0.0, start.normal, True)
    for begin, _ in contact_times():
        if begin == 0.0:
            # Touching at t = 0 by the interval arithmetic (narrowphase may round the other way).
            if separating:
                continue
            return Impact(0.0, start.normal, overlapping)
        return Impact(begin, normal_at(begin), False)
    return None


def _unit_or_fallback(v: Vector3D) -> Vector3D:
    length = v.length()
    return v / length if length > 0.0 else _FALLBACK


def _position(start: Vector3D, motion: tuple[Vector3D, Vector3D], t: float, sign: float = 1.0) -> Vector3D:
    velocity, acceleration = motion
    return start + (velocity * t + acceleration * (0.5 * t * t)) * sign


# --- kernels ------------------------------------------------------------------------------------------
def _balls(
    ca: Vector3D, ra: float, cb: Vector3D, rb: float, v: Vector3D, g: Vector3D, max_time: float, dims: int
) -> tuple[Callable[[], list[Interval]], Callable[[float], Vector3D]]:
    """Ball-ball (Ericson 5.5.5): with ``p(t) = (c_b - c_a) + v t + g t^2/2`` they touch when
    ``|p(t)|^2 - (r_a + r_b)^2 = 0``. For ``g = 0`` this is the quadratic
    ``(v.v) t^2 + 2 (p.v) t + (p.p - R^2) = 0`` solved in closed form; otherwise a quartic,
    solved by monotone pieces and bisection. Normal ``p(t)/|p(t)|``."""
    p0 = cb - ca
    radius = ra + rb
    components = [_motion(p0.as_tuple()[i], v.as_tuple()[i], g.as_tuple()[i]) for i in range(dims)]
    squared = _add(*(_square(c) for c in components), (-radius * radius,))

    def times() -> list[Interval]:
        return _nonpositive(squared, max_time)

    def normal_at(t: float) -> Vector3D:
        return _unit_or_fallback(_position(p0, (v, g), t))

    return times, normal_at


def _boundary(
    unit_normal: Vector3D, lowest: float, highest: float, v: Vector3D, g: Vector3D, max_time: float
) -> tuple[Callable[[], list[Interval]], Callable[[float], Vector3D]]:
    """A line or plane and a moving ball or box (Ericson 5.5.3 and 5.5.4). Along the unit normal
    ``n`` the shape spans ``[s_low, s_high]`` relative to the boundary: ``s0 -+ r`` for a ball
    with ``s0 = n.(c - P)``; for a box, ``n.(V - P)`` at its lowest and highest vertices ``V``
    (the centre -+ the projected radius ``h = sum_i |n_i| e_i``, taken from the corners as
    narrowphase does). Both move by ``(n.v) t + (n.g) t^2 / 2``; the shapes touch while
    ``s_low(t) <= 0 <= s_high(t)``: two linear or quadratic conditions. The normal is ``+n`` when
    the shape arrives from the ``+n`` side (``s_low`` reaching 0), else ``-n``."""
    speed, half_acceleration = unit_normal.dot(v), 0.5 * unit_normal.dot(g)
    low = (lowest, speed, half_acceleration)
    high = (highest, speed, half_acceleration)

    def times() -> list[Interval]:
        return _intersect(_nonpositive(low, max_time), _nonpositive(tuple(-c for c in high), max_time))

    def normal_at(t: float) -> Vector3D:
        below, above = abs(_eval(low, t)), abs(_eval(high, t))
        if below != above:
            side = above - below  # > 0: s_low is at the boundary, the shape is on the +n side
        else:  # a flat box (h = 0) meets the boundary: the side it arrives from
            rate = _eval(_derivative(low), t)
            side = -rate if rate != 0.0 else (half_acceleration if half_acceleration != 0.0 else 1.0)
        return -unit_normal if side < 0.0 else unit_normal

    return times, normal_at


def _ball_span(origin: Vector3D, unit_normal: Vector3D, center: Vector3D, radius: float) -> tuple[float, float]:
    s = unit_normal.dot(center - origin)
    return s - radius, s + radius


def _box_span(origin: Vector3D, unit_normal: Vector3D, box: AABB) -> tuple[float, float]:
    """``n.(V - P)`` at the box's lowest and highest vertices along ``n`` (narrowphase's vertex)."""
    corners = zip(box.center, box.min_corner, box.max_corner, unit_normal, strict=True)
    low, high = [], []
    for c, lo, hi, n in corners:
        low.append((lo if n > 0.0 else hi) if n != 0.0 else c)
        high.append((hi if n > 0.0 else lo) if n != 0.0 else c)
    return unit_normal.dot(Vector3D(*low) - origin), unit_normal.dot(Vector3D(*high) - origin)


def _boxes(
    a: AABB, b: AABB, v: Vector3D, g: Vector3D, max_time: float
) -> tuple[Callable[[], list[Interval]], Callable[[float], Vector3D]]:
    """AABB-AABB (Ericson 5.5.8): on each axis ``i`` B's offset is ``d_i(t) = v_i t + g_i t^2/2``
    and the boxes overlap on that axis while ``b_lo + d <= a_hi`` and ``a_lo <= b_hi + d`` (two
    linear or quadratic conditions). They touch while every axis overlaps: the first contact is
    the largest per-axis entry time, if no axis has exited by then. The normal is along the axis
    that entered last (ties: x before y before z), towards B."""
    dims = a.dim
    a_lo, a_hi = a.min_corner.as_tuple(), a.max_corner.as_tuple()
    b_lo, b_hi = b.min_corner.as_tuple(), b.max_corner.as_tuple()
    vs, gs = v.as_tuple(), g.as_tuple()
    plus = [(b_lo[i] - a_hi[i], vs[i], 0.5 * gs[i]) for i in range(dims)]
    minus = [(a_lo[i] - b_hi[i], -vs[i], -0.5 * gs[i]) for i in range(dims)]
    per_axis: list[list[Interval]] = []

    def times() -> list[Interval]:
        per_axis[:] = [
            _intersect(_nonpositive(plus[i], max_time), _nonpositive(minus[i], max_time)) for i in range(dims)
        ]
        return _intersect_all(per_axis)

    def normal_at(t: float) -> Vector3D:
        entries = [max((s for s, e in axis_times if s <= t <= e), default=-math.inf) for axis_times in per_axis]
        axis = max(range(dims), key=lambda i: (entries[i], -i))
        p_value, m_value = _eval(plus[axis], t), _eval(minus[axis], t)
        if p_value == m_value:
            offset = (b.center - a.center).as_tuple()[axis] + _eval(_motion(0.0, vs[axis], gs[axis]), t)
            sign = -1.0 if offset < 0.0 else 1.0
        else:
            sign = 1.0 if p_value > m_value else -1.0
        return _AXES[axis] * sign

    return times, normal_at


def _ball_box(
    center: Vector3D, radius: float, box: AABB, v: Vector3D, g: Vector3D, max_time: float, dims: int
) -> tuple[Callable[[], list[Interval]], Callable[[float], Vector3D]]:
    """A moving ball (A) and a box (B) (Ericson 5.5.7): in the box's frame the ball's centre moves
    as ``c(t) = c0 - v t - g t^2/2`` and touches when it enters the box grown by ``r`` (the
    Minkowski sum), which is the union of: for each axis, the box grown by ``r`` along that axis
    only (faces: linear/quadratic conditions); the balls of radius ``r`` about the corners
    (``|c(t) - corner|^2 <= r^2``); in 3D, the cylinders of radius ``r`` about the 12 edges, cut
    to the edge's length. With ``g = 0`` every condition is a quadratic; otherwise the corner and
    edge conditions are quartics (monotone pieces and bisection). Normal: from the centre to its
    closest point ``q`` on the box, ``(q - c)/|q - c|``."""
    lo, hi = box.min_corner.as_tuple(), box.max_corner.as_tuple()
    c0, vs, gs = center.as_tuple(), v.as_tuple(), g.as_tuple()
    moving = [_motion(c0[i], -vs[i], -gs[i]) for i in range(dims)]

    def slab(axis: int, grow: float) -> list[Interval]:
        x = moving[axis]
        below = (lo[axis] - grow - x[0], -x[1], -x[2])  # lo - grow - c(t) <= 0
        above = (x[0] - hi[axis] - grow, x[1], x[2])  # c(t) - hi - grow <= 0
        return _intersect(_nonpositive(below, max_time), _nonpositive(above, max_time))

    def offset_squared(axes: list[tuple[int, float]]) -> Poly:
        return _add(*(_square((moving[i][0] - at, *moving[i][1:])) for i, at in axes), (-radius * radius,))

    def times() -> list[Interval]:
        exact = [slab(i, 0.0) for i in range(dims)]
        grown = [slab(i, radius) for i in range(dims)]
        if not _intersect_all(grown):  # never near the box (which holds all the pieces below)
            return []
        pieces: list[list[Interval]] = []
        for k in range(dims):  # faces
            pieces.append(_intersect_all([grown[i] if i == k else exact[i] for i in range(dims)]))
        for corner in sorted(set(itertools.product(*((lo[i], hi[i]) for i in range(dims))))):
            pieces.append(_nonpositive(offset_squared(list(enumerate(corner))), max_time))
        if dims == 3:  # edges along axis k
            for k in range(3):
                i, j = (axis for axis in range(3) if axis != k)
                for ei, ej in sorted(set(itertools.product((lo[i], hi[i]), (lo[j], hi[j])))):
                    tube = _nonpositive(offset_squared([(i, ei), (j, ej)]), max_time)
                    pieces.append(_intersect(tube, exact[k]))
        return _merge([interval for piece in pieces for interval in piece])

    def normal_at(t: float) -> Vector3D:
        c = _position(center, (v, g), t, -1.0)
        q = Vector3D(*(min(max(x, low), high) for x, low, high in zip(c, box.min_corner, box.max_corner, strict=True)))
        return _unit_or_fallback(q - c)

    return times, normal_at


# --- the pairs (valid input only: the tests give it nothing else) -------------------------------------
Pieces = tuple[Callable[[], list[Interval]], Callable[[float], Vector3D]]


def _pieces(a: Shape, b: Shape, v: Vector3D, g: Vector3D, t: float) -> Pieces | None:
    """The touching times and normal of the pair in this order, or None for the other order."""
    balls = (Circle, Sphere)
    if isinstance(a, balls) and isinstance(b, balls):
        return _balls(a.center, a.radius, b.center, b.radius, v, g, t, 2 if isinstance(a, Circle) else 3)
    if isinstance(a, AABB) and isinstance(b, AABB):
        return _boxes(a, b, v, g, t)
    if isinstance(a, (Line, Plane)) and isinstance(b, balls):
        return _boundary(a.unit_normal, *_ball_span(a.point, a.unit_normal, b.center, b.radius), v, g, t)
    if isinstance(a, (Line, Plane)) and isinstance(b, AABB):
        return _boundary(a.unit_normal, *_box_span(a.point, a.unit_normal, b), v, g, t)
    if isinstance(a, balls) and isinstance(b, AABB):
        return _ball_box(a.center, a.radius, b, v, g, t, 2 if isinstance(a, Circle) else 3)
    return None


def time_of_impact(
    a: Shape,
    b: Shape,
    velocity_a: VectorLike,
    velocity_b: VectorLike,
    max_time: float,
    acceleration_a: VectorLike = (0.0, 0.0, 0.0),
    acceleration_b: VectorLike = (0.0, 0.0, 0.0),
) -> Impact | None:
    """The first touch of ``a`` and ``b`` (the module docstring's semantics), normal from a to b."""
    va, vb, ga, gb = (as_vector(x, "motion") for x in (velocity_a, velocity_b, acceleration_a, acceleration_b))
    pieces = _pieces(a, b, vb - va, gb - ga, max_time)
    if pieces is not None:
        return _first_impact(separation(a, b), vb - va, gb - ga, *pieces)
    pieces = _pieces(b, a, va - vb, ga - gb, max_time)
    assert pieces is not None, (a, b)
    impact = _first_impact(separation(b, a), va - vb, ga - gb, *pieces)
    return None if impact is None else impact.flipped()
