"""The shapes: frozen dataclasses, validated at construction.

Moving shapes are :class:`Circle` (2D, in the x-y plane), :class:`Sphere` and :class:`AABB`
(2D or 3D); boundaries are :class:`Line` (2D, infinite) and :class:`Plane` (infinite). Every
constructor accepts a :class:`~collisionlab.vector.Vector3D` or a list or numpy array of numbers
where a vector is expected, and numpy scalars (or 0-d arrays) where a number is; it raises
:class:`~collisionlab.errors.InvalidInputError` naming the field.

Component counts, as in scenario files: a 3D shape (a sphere, a plane, a 3D box) needs three
numbers ``(x, y, z)``; two are refused, never padded with ``z = 0``. A 2D shape (a circle, a
line, a 2D box) takes ``(x, y)`` or ``(x, y, 0)``: a third number is accepted when it is 0 (any
other z is refused, the shape lives in the x-y plane). A ``Vector3D`` always has three components
and is taken as it is. Every shape has the
queries as methods: ``a.intersects(b)``, ``a.contact(b)``, ``a.distance(b)``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import cast

from .contact import Contact
from .errors import InvalidInputError
from .tolerances import COLLINEAR_SINE
from .validate import positive
from .vector import Vector3D, VectorLike, as_vector, as_vector_3d

__all__ = ["AABB", "Circle", "Line", "Plane", "Shape", "Sphere"]


# The queries the methods below are: collisionlab.narrowphase's contact, distance and
# intersects, handed down by narrowphase when it is imported (_use_queries). narrowphase imports
# these shapes (its dispatch table is keyed on them), so importing it from here would be an import
# circle (issue 30). Importing any collisionlab module runs collisionlab/__init__.py first, which
# imports narrowphase, so the queries are in place before a shape can be built.
@dataclass(frozen=True)
class _PairQueries:
    contact: Callable[[Shape, Shape], Contact | None]
    distance: Callable[[Shape, Shape], float]
    intersects: Callable[[Shape, Shape], bool]


_queries: _PairQueries | None = None


def _use_queries(
    contact: Callable[[Shape, Shape], Contact | None],
    distance: Callable[[Shape, Shape], float],
    intersects: Callable[[Shape, Shape], bool],
) -> None:
    """Called once, by :mod:`collisionlab.narrowphase`: the functions behind the methods."""
    global _queries
    _queries = _PairQueries(contact, distance, intersects)


def _pair_queries() -> _PairQueries:
    if _queries is None:  # cannot happen through the package (see above)
        raise RuntimeError("collisionlab.narrowphase is not loaded: import collisionlab")
    return _queries


class _Queries:
    """The collision queries as methods: each calls the free function of the same name in
    :mod:`collisionlab.narrowphase`, so ``a.contact(b) == contact(a, b)``, and a pair with no
    query raises the same :class:`~collisionlab.errors.UnsupportedPairError`."""

    __slots__ = ()

    def intersects(self, other: Shape) -> bool:
        """Whether this shape and ``other`` touch or overlap (:func:`~collisionlab.narrowphase.intersects`).

        >>> Sphere((0, 0.5, 0), 1).intersects(Plane((0, 0, 0), (0, 1, 0)))
        True
        """
        return _pair_queries().intersects(cast("Shape", self), other)

    def contact(self, other: Shape) -> Contact | None:
        """The contact with ``other``, normal from this shape to ``other``, or ``None``
        (:func:`~collisionlab.narrowphase.contact`).

        >>> Circle((0, 0), 1).contact(Circle((1.5, 0), 1)).depth
        0.5
        """
        return _pair_queries().contact(cast("Shape", self), other)

    def distance(self, other: Shape) -> float:
        """Signed distance to ``other``: the gap, or minus the depth when overlapping
        (:func:`~collisionlab.narrowphase.distance`).

        >>> AABB((0, 0), (1, 1)).distance(Circle((3, 0.5), 1))
        1.0
        >>> Circle((0, 0), 1).distance(Sphere((0, 0, 0), 1))
        Traceback (most recent call last):
        ...
        collisionlab.errors.UnsupportedPairError: no collision query for Circle and Sphere; supported pairs: \
Circle-Circle, Sphere-Sphere, AABB-AABB, Line-Circle, Plane-Sphere, Circle-AABB, Sphere-AABB, \
Line-AABB, Plane-AABB (either order)
        """
        return _pair_queries().distance(cast("Shape", self), other)


def _vector(owner: object, name: str, value: object) -> Vector3D:
    vector = as_vector(value, name)
    object.__setattr__(owner, name, vector)
    return vector


def _vector_3d(owner: object, name: str, value: object, what: str) -> Vector3D:
    vector = as_vector_3d(value, name, what)
    object.__setattr__(owner, name, vector)
    return vector


def _given_2d(value: object) -> bool:
    """Whether ``value`` (already a valid vector) was given as two raw numbers (not a ``Vector3D``)."""
    return not isinstance(value, Vector3D) and len(value) == 2  # type: ignore[arg-type]


def _require_planar(value: Vector3D, field: str) -> None:
    if value.z != 0.0:
        raise InvalidInputError(field, "must lie in the x-y plane (z = 0) for a 2D shape", got=value.as_tuple())


@dataclass(frozen=True, slots=True)
class Circle(_Queries):
    """A circle in the x-y plane (``center.z`` must be 0).

    >>> Circle((1, 2), 0.5)
    Circle(center=Vector3D(x=1.0, y=2.0, z=0.0), radius=0.5)
    >>> Circle((0, 0), 0)
    Traceback (most recent call last):
    ...
    collisionlab.errors.InvalidInputError: radius: must be > 0 (got 0.0)
    """

    center: Vector3D
    radius: float

    def __post_init__(self) -> None:
        _require_planar(_vector(self, "center", self.center), "center")
        object.__setattr__(self, "radius", positive(self.radius, "radius"))

    def moved_to(self, center: Vector3D) -> Circle:
        return Circle(center, self.radius)


@dataclass(frozen=True, slots=True)
class Sphere(_Queries):
    """A sphere; its ``center`` needs three numbers.

    >>> Sphere((0, 0, 1), 2).radius
    2.0
    >>> Sphere((1, 2), 1)
    Traceback (most recent call last):
    ...
    collisionlab.errors.InvalidInputError: center: a sphere needs three numbers (x, y, z), not 2 (got (1, 2))
    """

    center: Vector3D
    radius: float

    def __post_init__(self) -> None:
        _vector_3d(self, "center", self.center, "a sphere")
        object.__setattr__(self, "radius", positive(self.radius, "radius"))

    def moved_to(self, center: Vector3D) -> Sphere:
        return Sphere(center, self.radius)


@dataclass(frozen=True, slots=True)
class AABB(_Queries):
    """An axis-aligned box given by two opposite corners (lab eqs. 4 and 5).

    The box is 2D when both corners have ``z == 0`` (a box with no extent in z at z = 0, which is
    what 2-component corners give); otherwise it is 3D, and then each corner needs three numbers
    (a 2-number corner of a 3D box is refused, never padded). ``min_corner <= max_corner`` on every
    axis; equal bounds (a flat box) are allowed.

    >>> box = AABB.from_center_size((0, 0, 0), (2, 4, 6))
    >>> box.min_corner, box.max_corner, box.dim
    (Vector3D(x=-1.0, y=-2.0, z=-3.0), Vector3D(x=1.0, y=2.0, z=3.0), 3)
    >>> AABB((0, 0), (1, 1)).dim
    2
    >>> AABB((0, 2), (1, 1))
    Traceback (most recent call last):
    ...
    collisionlab.errors.InvalidInputError: max_corner: must be >= min_corner on every axis; y is 1.0 < 2.0
    """

    min_corner: Vector3D
    max_corner: Vector3D

    def __post_init__(self) -> None:
        given = {"min_corner": self.min_corner, "max_corner": self.max_corner}
        low = _vector(self, "min_corner", self.min_corner)
        high = _vector(self, "max_corner", self.max_corner)
        if low.z != 0.0 or high.z != 0.0:  # a 3D box
            for name, value in given.items():
                if _given_2d(value):
                    raise InvalidInputError(name, "a 3D box needs three numbers (x, y, z), not 2", got=value)
        for axis, lo, hi in zip("xyz", low, high, strict=True):
            if hi < lo:
                raise InvalidInputError("max_corner", f"must be >= min_corner on every axis; {axis} is {hi!r} < {lo!r}")

    @staticmethod
    def from_center_size(center: VectorLike, size: VectorLike) -> AABB:
        """A box from its centre and its full edge lengths (2 or 3 numbers, each > 0).

        The box is 2D when ``size`` has 2 components, or has ``z == 0`` about a centre with
        ``z == 0`` (so a 2D box's own ``center`` and ``2 * half_size`` rebuild it).

        >>> AABB.from_center_size((1, 1), (2, 2))
        AABB(min_corner=Vector3D(x=0.0, y=0.0, z=0.0), max_corner=Vector3D(x=2.0, y=2.0, z=0.0))
        >>> AABB.from_center_size(Vector3D(1, 1), Vector3D(2, 2)).dim
        2
        """
        c = as_vector(center, "center")
        s = as_vector(size, "size")
        sizes = list(s)
        is_2d = s.z == 0.0 and (_given_2d(size) or c.z == 0.0)
        if not is_2d and _given_2d(center):
            raise InvalidInputError("center", "a 3D box needs three numbers (x, y, z), not 2", got=center)
        for axis, edge in zip("xyz", sizes[: 2 if is_2d else 3], strict=False):
            positive(edge, f"size.{axis}")
        if is_2d:
            _require_planar(c, "center")
        half = s * 0.5
        return AABB(c - half, c + half)

    @property
    def dim(self) -> int:
        return 2 if self.min_corner.z == 0.0 and self.max_corner.z == 0.0 else 3

    @property
    def center(self) -> Vector3D:
        return (self.min_corner + self.max_corner) * 0.5

    @property
    def half_size(self) -> Vector3D:
        return (self.max_corner - self.min_corner) * 0.5

    def moved_to(self, center: Vector3D) -> AABB:
        half = self.half_size
        return AABB(center - half, center + half)


@dataclass(frozen=True, slots=True)
class Line(_Queries):
    """An infinite line in the x-y plane through ``point`` along ``direction`` (lab part IV.A).

    ``direction`` is kept as given (any non-zero length); ``unit_direction`` and ``unit_normal``
    (the direction turned +90 degrees about z) are derived.

    >>> Line((0, 0), (2, 0)).unit_normal
    Vector3D(x=0.0, y=1.0, z=0.0)
    >>> Line((0, 0), (0, 0))
    Traceback (most recent call last):
    ...
    collisionlab.errors.InvalidInputError: direction: must not be the zero vector (got (0.0, 0.0, 0.0))
    """

    point: Vector3D
    direction: Vector3D

    def __post_init__(self) -> None:
        _require_planar(_vector(self, "point", self.point), "point")
        direction = _vector(self, "direction", self.direction)
        _require_planar(direction, "direction")
        direction.normalized("direction")

    @property
    def unit_direction(self) -> Vector3D:
        return self.direction.normalized("direction")

    @property
    def unit_normal(self) -> Vector3D:
        d = self.unit_direction
        return Vector3D(-d.y, d.x, 0.0)


@dataclass(frozen=True, slots=True)
class Plane(_Queries):
    """An infinite plane through ``point`` with normal ``normal`` (lab part IV.B); each needs
    three numbers.

    >>> Plane.from_points((0, 0, 0), (1, 0, 0), (0, 0, 1)).unit_normal
    Vector3D(x=0.0, y=-1.0, z=0.0)
    >>> Plane((0, 0, 0), (0, 0, 0))
    Traceback (most recent call last):
    ...
    collisionlab.errors.InvalidInputError: normal: must not be the zero vector (got (0.0, 0.0, 0.0))
    """

    point: Vector3D
    normal: Vector3D

    def __post_init__(self) -> None:
        _vector_3d(self, "point", self.point, "a plane")
        _vector_3d(self, "normal", self.normal, "a plane").normalized("normal")

    @property
    def unit_normal(self) -> Vector3D:
        return self.normal.normalized("normal")

    @staticmethod
    def from_points(a: VectorLike, b: VectorLike, c: VectorLike) -> Plane:
        """The plane through three non-collinear points, normal ``(b - a) x (c - a)``
        (right-hand rule: counter-clockwise ``a, b, c`` seen from the side the normal points to).

        Points are collinear (refused, field ``points``) when the sine of the angle between
        ``b - a`` and ``c - a`` is at most ``COLLINEAR_SINE``; a relative test, so it does not
        depend on the scale of the points. Coincident points are collinear.

        >>> Plane.from_points((0, 0, 0), (1, 0, 0), (0, 1, 0)).normal
        Vector3D(x=0.0, y=0.0, z=1.0)
        >>> Plane.from_points((0, 0, 0), (1, 1, 1), (2, 2, 2))
        Traceback (most recent call last):
        ...
        collisionlab.errors.InvalidInputError: points: the three points must not be collinear or coincident
        """
        pa = as_vector_3d(a, "points[0]", "a plane")
        pb = as_vector_3d(b, "points[1]", "a plane")
        pc = as_vector_3d(c, "points[2]", "a plane")
        ab = pb - pa
        ac = pc - pa
        normal = ab.cross(ac)
        scale = ab.length() * ac.length()
        if scale == 0.0 or normal.length() <= COLLINEAR_SINE * scale:
            raise InvalidInputError("points", "the three points must not be collinear or coincident")
        # Normalise through the unit edges so tiny or huge coordinates cannot under/overflow.
        unit_normal = ab.normalized("points").cross(ac.normalized("points")).normalized("points")
        return Plane(pa, unit_normal)


Shape = Circle | Sphere | AABB | Line | Plane
