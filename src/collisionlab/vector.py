"""``Vector3D``: an immutable 3-vector with the projections of the lab's part I.

2D work uses ``z = 0``. Every component is a finite float: NaN and inf are refused at
construction, so they cannot enter any shape or any simulation state.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from math import isfinite

from .errors import InvalidInputError, OutOfRangeError
from .validate import finite_number

__all__ = ["Vector3D", "VectorLike", "as_vector"]


@dataclass(frozen=True, slots=True)
class Vector3D:
    """An immutable vector ``(x, y, z)`` of finite floats.

    >>> a = Vector3D(1, 2, 3)
    >>> b = Vector3D(4, 5, 6)
    >>> a + b, b - a, 2 * a, a / 2, -a
    (Vector3D(x=5.0, y=7.0, z=9.0), Vector3D(x=3.0, y=3.0, z=3.0), Vector3D(x=2.0, y=4.0, z=6.0), \
Vector3D(x=0.5, y=1.0, z=1.5), Vector3D(x=-1.0, y=-2.0, z=-3.0))
    >>> a.dot(b), tuple(a.cross(b))
    (32.0, (-3.0, 6.0, -3.0))
    >>> Vector3D(3, 4).length()
    5.0

    Wherever a vector is expected (``+``, ``-``, ``dot``, ``cross``, the projections), a
    sequence of 2 or 3 numbers is accepted too:

    >>> Vector3D(1, 2) + (1, 1), (3, 3) - Vector3D(1, 2), Vector3D(1, 2).dot((3, 4))
    (Vector3D(x=2.0, y=3.0, z=0.0), Vector3D(x=2.0, y=1.0, z=0.0), 11.0)
    """

    x: float
    y: float
    z: float = 0.0

    def __post_init__(self) -> None:
        x, y, z = self.x, self.y, self.z
        # Fast path for the common case (floats from arithmetic); the checks below are the rule.
        if type(x) is float and type(y) is float and type(z) is float and isfinite(x) and isfinite(y) and isfinite(z):
            return
        object.__setattr__(self, "x", finite_number(self.x, "x"))
        object.__setattr__(self, "y", finite_number(self.y, "y"))
        object.__setattr__(self, "z", finite_number(self.z, "z"))

    # --- container protocol -------------------------------------------------------------
    def __iter__(self) -> Iterator[float]:
        yield self.x
        yield self.y
        yield self.z

    def __len__(self) -> int:
        return 3

    def as_tuple(self) -> tuple[float, float, float]:
        return (self.x, self.y, self.z)

    # --- arithmetic ----------------------------------------------------------------------
    def __add__(self, other: VectorLike) -> Vector3D:
        o = _operand(other)
        if o is None:
            return NotImplemented
        return Vector3D(self.x + o.x, self.y + o.y, self.z + o.z)

    __radd__ = __add__

    def __sub__(self, other: VectorLike) -> Vector3D:
        o = _operand(other)
        if o is None:
            return NotImplemented
        return Vector3D(self.x - o.x, self.y - o.y, self.z - o.z)

    def __rsub__(self, other: VectorLike) -> Vector3D:
        o = _operand(other)
        if o is None:
            return NotImplemented
        return Vector3D(o.x - self.x, o.y - self.y, o.z - self.z)

    def __mul__(self, scalar: float) -> Vector3D:
        if not isinstance(scalar, (int, float)):
            return NotImplemented  # Vector3D * Vector3D is ambiguous: use dot or cross
        return Vector3D(self.x * scalar, self.y * scalar, self.z * scalar)

    __rmul__ = __mul__

    def __truediv__(self, scalar: float) -> Vector3D:
        if scalar == 0:
            raise InvalidInputError("divisor", "must not be zero", got=scalar)
        return Vector3D(self.x / scalar, self.y / scalar, self.z / scalar)

    def __neg__(self) -> Vector3D:
        return Vector3D(-self.x, -self.y, -self.z)

    def dot(self, other: VectorLike) -> float:
        """``x x' + y y' + z z'``; a product too large for a double raises :class:`OutOfRangeError`.

        >>> Vector3D(1e308, 0).dot((10, 0))
        Traceback (most recent call last):
        ...
        collisionlab.errors.OutOfRangeError: dot product: overflows (the vectors are too long)
        """
        o = as_vector(other, "other")
        result = self.x * o.x + self.y * o.y + self.z * o.z
        if not isfinite(result):
            raise OutOfRangeError("dot product: overflows (the vectors are too long)")
        return result

    def cross(self, other: VectorLike) -> Vector3D:
        """The cross product ``self x other`` (lab part I.A.3).

        >>> Vector3D(1, 0, 0).cross(Vector3D(0, 1, 0))
        Vector3D(x=0.0, y=0.0, z=1.0)
        >>> Vector3D(1, 0).cross((0, 1))
        Vector3D(x=0.0, y=0.0, z=1.0)
        """
        other = as_vector(other, "other")
        return Vector3D(
            self.y * other.z - self.z * other.y,
            self.z * other.x - self.x * other.z,
            self.x * other.y - self.y * other.x,
        )

    def length_squared(self) -> float:
        return self.dot(self)

    def length(self) -> float:
        # hypot avoids overflow/underflow of the squares for very large or small components.
        result = math.hypot(self.x, self.y, self.z)
        if result == math.inf:  # only above 1.8e308: (1.7e308, 1.7e308) has no double length
            raise OutOfRangeError("length: overflows (the vector is too long)")
        return result

    def normalized(self, field: str = "vector") -> Vector3D:
        """The unit vector along ``self``; a zero vector is refused, naming ``field``.

        >>> Vector3D(0, 3, 4).normalized()
        Vector3D(x=0.0, y=0.6, z=0.8)
        >>> Vector3D(0, 1.7e308, 1.7e308).normalized()   # scaled first: no overflow to inf
        Vector3D(x=0.0, y=0.7071067811865476, z=0.7071067811865476)
        >>> Vector3D(0, 0, 0).normalized("direction")
        Traceback (most recent call last):
        ...
        collisionlab.errors.InvalidInputError: direction: must not be the zero vector \
(got (0.0, 0.0, 0.0))
        """
        largest = max(abs(self.x), abs(self.y), abs(self.z))
        if largest == 0.0:
            raise InvalidInputError(field, "must not be the zero vector", got=self.as_tuple())
        # Scaled first by a power of two (exact) to a largest component in [0.5, 1): the length
        # of (0, 1.7e308, 1.7e308) would overflow to inf, and that of a subnormal vector round
        # too coarsely; the scaled length lies in [0.5, 1.8) and the quotients are unit.
        exponent = math.frexp(largest)[1]
        x, y, z = (math.ldexp(c, -exponent) for c in self.as_tuple())
        length = math.hypot(x, y, z)
        return Vector3D(x / length, y / length, z / length)

    # --- lab part I ------------------------------------------------------------------------
    def parallel_projection(self, onto: VectorLike) -> Vector3D:
        """The component of ``self`` along ``onto``: ``Proj_onto(v) = (v.onto / |onto|^2) onto``
        (lab eq. 22).

        >>> Vector3D(3, 4).parallel_projection((1, 0))
        Vector3D(x=3.0, y=0.0, z=0.0)
        >>> Vector3D(1, 1, 0).parallel_projection((2, 2, 0))
        Vector3D(x=1.0, y=1.0, z=0.0)
        >>> Vector3D(1, 1).parallel_projection((1e-200, 0))   # |onto|^2 would underflow to 0
        Vector3D(x=1.0, y=0.0, z=0.0)

        ``onto`` is first scaled by a power of two (exact in floating point) to a largest
        component in [0.5, 1), so that very short or very long ``onto`` neither underflows nor
        overflows; the value is the formula's up to rounding.
        """
        return self._projection(as_vector(onto, "onto"), "onto")

    def _projection(self, axis: Vector3D, field: str) -> Vector3D:
        largest = max(abs(axis.x), abs(axis.y), abs(axis.z))
        if largest == 0.0:
            raise InvalidInputError(field, "must not be the zero vector", got=axis.as_tuple())
        exponent = math.frexp(largest)[1]
        axis = Vector3D(*(math.ldexp(c, -exponent) for c in axis))
        return axis * (self.dot(axis) / axis.length_squared())

    def perpendicular_projection(self, onto: VectorLike) -> Vector3D:
        """``self`` minus its parallel projection onto ``onto``.

        >>> Vector3D(3, 4).perpendicular_projection((1, 0))
        Vector3D(x=0.0, y=4.0, z=0.0)
        """
        return self - self.parallel_projection(onto)

    @staticmethod
    def closest_point_on_line(point_on_line: VectorLike, direction: VectorLike, point: VectorLike) -> Vector3D:
        """Closest point ``S`` on the line through ``P`` with direction ``d`` to the point ``Q``:
        ``S = P + Proj_d(PQ)`` (lab eq. 6; Ericson 5.1.2). Works for 2D points with z = 0.

        >>> Vector3D.closest_point_on_line((0, 0), (1, 0), (3, 4))
        Vector3D(x=3.0, y=0.0, z=0.0)
        >>> Vector3D.closest_point_on_line((1, 1), (2, 2), (0, 2))   # P + ((-1,1).(2,2)/8)(2,2) = P
        Vector3D(x=1.0, y=1.0, z=0.0)
        """
        p = as_vector(point_on_line, "point_on_line")
        d = as_vector(direction, "direction")
        q = as_vector(point, "point")
        return p + (q - p)._projection(d, "direction")

    @staticmethod
    def closest_point_on_plane(point_on_plane: VectorLike, normal: VectorLike, point: VectorLike) -> Vector3D:
        """Closest point ``S`` on the plane through ``P`` with normal ``n`` to ``Q``:
        ``S = Q - Proj_n(PQ)`` (lab eq. 8; Ericson 5.1.1).

        >>> Vector3D.closest_point_on_plane((0, 0, 0), (0, 0, 2), (1, 2, 5))
        Vector3D(x=1.0, y=2.0, z=0.0)
        """
        p = as_vector(point_on_plane, "point_on_plane")
        n = as_vector(normal, "normal")
        q = as_vector(point, "point")
        return q - (q - p)._projection(n, "normal")


VectorLike = Vector3D | Sequence[float]


def as_vector(value: object, field: str) -> Vector3D:
    """A :class:`Vector3D` from a ``Vector3D`` or a sequence of 2 or 3 finite numbers.

    >>> as_vector((1, 2), "velocity")
    Vector3D(x=1.0, y=2.0, z=0.0)
    >>> as_vector((1, 2, 3, 4), "velocity")
    Traceback (most recent call last):
    ...
    collisionlab.errors.InvalidInputError: velocity: must have 2 or 3 components, \
like [x, y] or [x, y, z] (got (1, 2, 3, 4))
    """
    if isinstance(value, Vector3D):
        return value
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence):
        if hasattr(value, "__len__") and hasattr(value, "__getitem__") and not isinstance(value, (str, bytes)):
            value = list(value)  # type: ignore[call-overload]  # numpy arrays and similar
        else:
            raise InvalidInputError(field, "must be a list of 2 or 3 numbers, like [x, y, z]", got=value)
    assert isinstance(value, Sequence)
    if len(value) not in (2, 3):
        raise InvalidInputError(field, "must have 2 or 3 components, like [x, y] or [x, y, z]", got=value)
    components = [finite_number(c, f"{field}[{i}]") for i, c in enumerate(value)]
    return Vector3D(*components)


def _operand(value: object) -> Vector3D | None:
    """The other operand of ``+`` or ``-`` as a vector, or ``None`` when it is not vector-like
    (so that Python raises its usual ``TypeError``). A malformed sequence is still refused."""
    if isinstance(value, Vector3D):
        return value
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or not hasattr(value, "__getitem__"):
        return None
    return as_vector(value, "other")
