"""Collision queries: one function per shape pair and one dispatch table.

Each pair is written once, as ``separation_<a>_<b>(a, b) -> Separation``; the mirrored order
``(b, a)`` is derived by :meth:`Separation.flipped`. :func:`contact`, :func:`intersects` and
:func:`distance` dispatch on the shapes' types, in either order. A pair with no query raises
:class:`~collisionlab.errors.UnsupportedPairError`; it never returns ``False``.

Touching policy, the same for every pair: shapes whose distance is exactly 0 are in contact
(depth 0), as in the lab's eqs. 7 and 9 (``<= r``). A line or plane is the whole infinite line
or plane; its contact normal points to the side the other shape's centre is on.

Degenerate policy: when the features that define the normal coincide the normal is a fixed
axis and the depth is the full depth along it: ``FALLBACK_NORMAL`` for two balls with equal
centres; the boundary's own normal for a ball centre or box centre exactly on a line or plane;
the + direction of the axis of least overlap for two boxes whose centres are level along that
axis; minus the outward normal of the nearest face (first in x-, x+, y-, y+, z-, z+ order on a
tie) for a ball centre inside or on a box. For the two same-type cases only (equal ball
centres, box centres level along the axis of least overlap), ``contact(b, a)`` is not the flip
of ``contact(a, b)``: both report the same axis. Every mixed pair is computed once and
mirrored, so ``contact(b, a) == contact(a, b).flipped()`` always holds for it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from . import shapes
from .contact import Contact, Separation
from .engine import geometry_kernels as gk
from .errors import OutOfRangeError, UnsupportedPairError
from .shapes import AABB, Circle, Line, Plane, Shape, Sphere
from .vector import Vector3D

__all__ = [
    "contact",
    "distance",
    "intersects",
    "separation",
    "separation_aabb_aabb",
    "separation_circle_aabb",
    "separation_circle_circle",
    "separation_line_aabb",
    "separation_line_circle",
    "separation_plane_aabb",
    "separation_plane_sphere",
    "separation_sphere_aabb",
    "separation_sphere_sphere",
    "supported_pairs",
]


# --- the kernels (written once, in collisionlab.engine.geometry_kernels) ----------------------
def _separation(values: tuple[float, ...]) -> Separation:
    """The kernel's numbers as a :class:`Separation`; numbers that overflowed (two shapes near
    the largest double: a depth of inf, a normal of nan) raise :class:`OutOfRangeError`, so
    no inf or NaN comes out of a query.

    >>> _separation((float("inf"), 1.0, 0.0, 0.0, 0.0, 0.0, 0.0))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    collisionlab.errors.OutOfRangeError: the shapes are too large ... overflows (distance inf)
    """
    if not all(math.isfinite(v) for v in values):
        raise OutOfRangeError(
            f"the shapes are too large or too far apart to compute: their separation overflows (distance {values[0]})"
        )
    distance, nx, ny, nz, px, py, pz = values
    return Separation(distance, Vector3D(nx, ny, nz), Vector3D(px, py, pz))


def _corners(box: AABB) -> tuple[float, float, float, float, float, float]:
    return (*box.min_corner.as_tuple(), *box.max_corner.as_tuple())


def _balls(ca: Vector3D, ra: float, cb: Vector3D, rb: float) -> Separation:
    """Two balls (lab eqs. 1-2; Ericson 4.3.1)."""
    return _separation(gk.separation_ball_ball(ca.x, ca.y, ca.z, ra, cb.x, cb.y, cb.z, rb))


def _boundary_ball(origin: Vector3D, unit_normal: Vector3D, center: Vector3D, radius: float) -> Separation:
    """A line or plane and a ball (lab eqs. 6-9)."""
    return _separation(
        gk.separation_boundary_ball(*origin.as_tuple(), *unit_normal.as_tuple(), *center.as_tuple(), radius)
    )


def _boundary_box(origin: Vector3D, unit_normal: Vector3D, box: AABB) -> Separation:
    """A line or plane and a box (Ericson 5.2.3)."""
    return _separation(gk.separation_boundary_box(*origin.as_tuple(), *unit_normal.as_tuple(), *_corners(box)))


def _ball_box(center: Vector3D, radius: float, box: AABB, dims: int) -> Separation:
    """A ball and a box (Ericson 5.2.5)."""
    return _separation(gk.separation_ball_box(*center.as_tuple(), radius, *_corners(box), dims))


def _require_2d_box(box: AABB, other: str) -> None:
    if box.dim != 2:
        raise UnsupportedPairError(f"{other} and a 3D AABB: a {other} lives in the x-y plane; use a 2D AABB")


# --- one function per pair ----------------------------------------------------------------------
def separation_circle_circle(a: Circle, b: Circle) -> Separation:
    """Circle-circle (lab part II.A, eqs. 1-3).

    >>> separation_circle_circle(Circle((0, 0), 1), Circle((3, 4), 2)).distance  # 5 - (1 + 2)
    2.0
    """
    return _balls(a.center, a.radius, b.center, b.radius)


def separation_sphere_sphere(a: Sphere, b: Sphere) -> Separation:
    """Sphere-sphere (lab part II.B, eqs. 1-3).

    >>> s = separation_sphere_sphere(Sphere((0, 0, 0), 1), Sphere((0, 0, 1.5), 1))
    >>> s.distance, s.normal, s.point          # 1.5 - 2; midway between z = 1 and z = 0.5
    (-0.5, Vector3D(x=0.0, y=0.0, z=1.0), Vector3D(x=0.0, y=0.0, z=0.75))
    >>> separation_sphere_sphere(Sphere((1, 1, 1), 1), Sphere((1, 1, 1), 2)).normal  # coincident
    Vector3D(x=1.0, y=0.0, z=0.0)
    """
    return _balls(a.center, a.radius, b.center, b.radius)


def separation_aabb_aabb(a: AABB, b: AABB) -> Separation:
    """AABB-AABB in 2D or 3D (lab part III, eqs. 4-5; Ericson 4.2.1).

    Per axis the gap is ``max(a.min - b.max, b.min - a.max)``. When every gap is <= 0 the boxes
    overlap and the contact is along the axis of least overlap (ties: x before y before z), the
    normal's sign from A's centre to B's (+axis when equal). Otherwise the distance is the length
    of the vector of positive gaps.

    >>> s = separation_aabb_aabb(AABB((0, 0), (2, 2)), AABB((1.5, 1), (3, 3)))
    >>> s.distance, s.normal, s.point           # overlaps 0.5 in x, 1 in y
    (-0.5, Vector3D(x=1.0, y=0.0, z=0.0), Vector3D(x=1.75, y=1.5, z=0.0))
    >>> separation_aabb_aabb(AABB((0, 0, 0), (1, 1, 1)), AABB((4, 5, 0), (5, 6, 1))).distance  # 3-4-5
    5.0
    """
    if a.dim != b.dim:
        raise UnsupportedPairError("a 2D AABB and a 3D AABB: both boxes must have the same dimension")
    return _separation(gk.separation_box_box(*_corners(a), *_corners(b), a.dim))


def separation_line_circle(a: Line, b: Circle) -> Separation:
    """Line-circle (lab part IV.A, eqs. 6-7): collision when ``|QS| <= r``.

    >>> s = separation_line_circle(Line((0, 0), (1, 1)), Circle((0, 2), 1))
    >>> round(s.distance, 12), s.normal   # |QS| = sqrt(2); normal (-1, 1)/sqrt(2)
    (0.414213562373, Vector3D(x=-0.7071067811865475, y=0.7071067811865475, z=0.0))
    """
    return _boundary_ball(a.point, a.unit_normal, b.center, b.radius)


def separation_plane_sphere(a: Plane, b: Sphere) -> Separation:
    """Plane-sphere (lab part IV.B, eqs. 8-9): collision when ``|Proj_n PQ| <= r``.

    >>> s = separation_plane_sphere(Plane((0, 0, 0), (0, 1, 0)), Sphere((1, -0.5, 2), 1))
    >>> s.distance, s.normal, s.point   # centre 0.5 below the plane: overlap 0.5, pushed down
    (-0.5, Vector3D(x=0.0, y=-1.0, z=0.0), Vector3D(x=1.0, y=0.25, z=2.0))
    """
    return _boundary_ball(a.point, a.unit_normal, b.center, b.radius)


def separation_circle_aabb(a: Circle, b: AABB) -> Separation:
    """Circle-AABB in 2D (the lab's postlab question 2; Ericson 5.2.5).

    >>> separation_circle_aabb(Circle((0, 0), 1), AABB((2, -1), (4, 1))).distance  # clamp to (2, 0)
    1.0
    >>> s = separation_circle_aabb(Circle((1, 0.5), 1), AABB((0, 0), (4, 4)))  # centre inside
    >>> s.distance, s.normal   # nearest face y = 0 at 0.5: depth 1 + 0.5; box moves +y
    (-1.5, Vector3D(x=0.0, y=1.0, z=0.0))
    """
    _require_2d_box(b, "circle")
    return _ball_box(a.center, a.radius, b, 2)


def separation_sphere_aabb(a: Sphere, b: AABB) -> Separation:
    """Sphere-AABB (Ericson 5.2.5); a 2D box is the flat box at z = 0.

    >>> separation_sphere_aabb(Sphere((0, 0, 3), 1), AABB((-1, -1, -1), (1, 1, 1))).normal
    Vector3D(x=0.0, y=0.0, z=-1.0)
    """
    return _ball_box(a.center, a.radius, b, 3)


def separation_line_aabb(a: Line, b: AABB) -> Separation:
    """Line-AABB in 2D (Ericson 5.2.3).

    >>> separation_line_aabb(Line((0, 0), (1, 0)), AABB((0, 1), (2, 3))).distance  # box 1 above
    1.0
    """
    _require_2d_box(b, "line")
    return _boundary_box(a.point, a.unit_normal, b)


def separation_plane_aabb(a: Plane, b: AABB) -> Separation:
    """Plane-AABB (Ericson 5.2.3).

    >>> s = separation_plane_aabb(Plane((0, 0, 0), (0, 0, 1)), AABB((0, 0, -0.25), (1, 1, 1)))
    >>> s.distance   # centre z = 0.375, projected radius 0.625
    -0.25
    """
    return _boundary_box(a.point, a.unit_normal, b)


# --- dispatch -----------------------------------------------------------------------------------
_TABLE: dict[tuple[type, type], Callable[[Any, Any], Separation]] = {
    (Circle, Circle): separation_circle_circle,
    (Sphere, Sphere): separation_sphere_sphere,
    (AABB, AABB): separation_aabb_aabb,
    (Line, Circle): separation_line_circle,
    (Plane, Sphere): separation_plane_sphere,
    (Circle, AABB): separation_circle_aabb,
    (Sphere, AABB): separation_sphere_aabb,
    (Line, AABB): separation_line_aabb,
    (Plane, AABB): separation_plane_aabb,
}


def supported_pairs() -> list[tuple[str, str]]:
    """The shape pairs that have a query (each also works in the mirrored order)."""
    return [(a.__name__, b.__name__) for a, b in _TABLE]


def separation(a: Shape, b: Shape) -> Separation:
    """The :class:`Separation` of any supported pair, in either order.

    >>> separation(Sphere((0, 0, 3), 1), Plane((0, 0, 0), (0, 0, 1))).normal  # from sphere to plane
    Vector3D(x=0.0, y=0.0, z=-1.0)
    >>> separation(Circle((0, 0), 1), Sphere((0, 0, 0), 1))
    Traceback (most recent call last):
    ...
    collisionlab.errors.UnsupportedPairError: no collision query for Circle and Sphere; supported pairs: \
Circle-Circle, Sphere-Sphere, AABB-AABB, Line-Circle, Plane-Sphere, Circle-AABB, Sphere-AABB, \
Line-AABB, Plane-AABB (either order)
    """
    query = _TABLE.get((type(a), type(b)))
    if query is not None:
        return query(a, b)
    mirrored = _TABLE.get((type(b), type(a)))
    if mirrored is not None:
        return mirrored(b, a).flipped()
    names = ", ".join(f"{x}-{y}" for x, y in supported_pairs())
    raise UnsupportedPairError(
        f"no collision query for {type(a).__name__} and {type(b).__name__}; supported pairs: {names} (either order)"
    )


def contact(a: Shape, b: Shape) -> Contact | None:
    """The :class:`Contact` of ``a`` and ``b`` (normal from ``a`` to ``b``), or ``None``.

    >>> contact(Circle((0, 0), 1), Circle((2, 0), 1))      # exactly touching: a contact, depth 0
    Contact(normal=Vector3D(x=1.0, y=0.0, z=0.0), depth=0.0, point=Vector3D(x=1.0, y=0.0, z=0.0))
    >>> contact(Circle((0, 0), 1), Circle((2.5, 0), 1)) is None
    True
    """
    return separation(a, b).contact()


def intersects(a: Shape, b: Shape) -> bool:
    """Whether ``a`` and ``b`` touch or overlap.

    >>> intersects(AABB((0, 0, 0), (1, 1, 1)), AABB((1, 1, 1), (2, 2, 2)))   # touching corners
    True
    """
    return separation(a, b).distance <= 0.0


def distance(a: Shape, b: Shape) -> float:
    """Signed distance: the gap when apart, 0 when touching, minus the depth when overlapping.

    >>> distance(Plane((0, 0, 0), (0, 0, 1)), Sphere((0, 0, 0.25), 1))
    -0.75
    """
    return separation(a, b).distance


# The shapes' methods (a.contact(b), ...) are these functions, handed to shapes.py here: it cannot
# import this file, which imports it.
shapes._use_queries(contact, distance, intersects)
