"""``Vector3D``: an immutable 3-vector with the projections of the lab's part I.

2D work uses ``z = 0``. Every component is a finite float: NaN and inf are refused at
construction, so they cannot enter any shape or any simulation state. A component is never
``-0.0`` (it is stored as ``0.0``), so no output prints a signed zero.

A vector is a good numpy citizen: ``np.asarray(v)`` is a float64 array of shape ``(3,)``, and a
vector is built from any sequence or array of 2 or 3 numbers (numpy scalars included).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from math import isfinite
from typing import Any, overload

import numpy as np
from numpy.typing import NDArray

from .errors import InvalidInputError, OutOfRangeError
from .textformat import format_float
from .tolerances import ISCLOSE_REL_TOL
from .validate import finite_number

__all__ = ["Vector3D", "VectorLike", "as_vector", "as_vector_3d"]


@dataclass(frozen=True, slots=True, init=False, repr=False)
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

    One argument builds a vector from a sequence or an array; a vector indexes, unpacks,
    formats and converts to numpy:

    >>> import numpy as np
    >>> v = Vector3D(np.array([3.0, 4.0]))
    >>> v, v[1], abs(v), f"{v:.2f}"
    (Vector3D(x=3.0, y=4.0, z=0.0), 4.0, 5.0, '(3.00, 4.00, 0.00)')
    >>> x, y, z = v
    >>> np.asarray(v)
    array([3., 4., 0.])
    >>> Vector3D(0.1 + 0.2, 0) == Vector3D(0.3, 0), Vector3D(0.1 + 0.2, 0).isclose((0.3, 0))
    (False, True)
    >>> Vector3D(0, -0.0), f"{Vector3D(-1e-9, 2):.3f}"     # no signed zeros in output
    (Vector3D(x=0.0, y=0.0, z=0.0), '(0.000, 2.000, 0.000)')
    """

    x: float
    y: float
    z: float

    # numpy defers to our operators (``np.float64(2) * v`` and ``array + v`` give a Vector3D);
    # ufuncs need an explicit ``np.asarray(v)``.
    __array_ufunc__ = None

    def __init__(self, x: float | VectorLike | NDArray[Any], y: float | None = None, z: float = 0.0) -> None:
        if y is None:
            if isinstance(x, numbers.Real) or (isinstance(x, np.ndarray) and x.ndim == 0):
                raise InvalidInputError("y", "is missing: give Vector3D(x, y[, z]) or one list of 2 or 3 numbers")
            x, y, z = as_vector_components(x, "vector")
        # Fast path for the common case (floats from arithmetic); the checks are the rule.
        elif not (
            type(x) is float and type(y) is float and type(z) is float and isfinite(x) and isfinite(y) and isfinite(z)
        ):
            x = finite_number(x, "x")
            y = finite_number(y, "y")
            z = finite_number(z, "z")
        # ``+ 0.0`` turns -0.0 into 0.0 and changes nothing else.
        object.__setattr__(self, "x", x + 0.0)
        object.__setattr__(self, "y", y + 0.0)
        object.__setattr__(self, "z", z + 0.0)

    def __repr__(self) -> str:
        return f"Vector3D(x={self.x!r}, y={self.y!r}, z={self.z!r})"

    def __format__(self, spec: str) -> str:
        """Each component formatted with ``spec`` (a float format such as ``.3f``), in
        parentheses; a component that rounds to zero never shows as ``-0``.

        >>> format(Vector3D(1, -0.00001, 2.5), ".2f")
        '(1.00, 0.00, 2.50)'
        """
        if not spec:
            return repr(self)
        return "(" + ", ".join(format_float(c, spec) for c in (self.x, self.y, self.z)) + ")"

    def isclose(self, other: VectorLike, rel_tol: float = ISCLOSE_REL_TOL, abs_tol: float = 0.0) -> bool:
        """Whether ``|self - other| <= max(rel_tol * max(|self|, |other|), abs_tol)``: the rule of
        :func:`math.isclose` applied to the vectors' lengths, so it does not depend on the axes.

        >>> Vector3D(1, 1e-12).isclose((1, 0)), Vector3D(0, 1e-12).isclose((0, 0))
        (True, False)
        >>> Vector3D(0, 1e-12).isclose((0, 0), abs_tol=1e-9)
        True
        """
        o = as_vector(other, "other")
        rel = finite_number(rel_tol, "rel_tol")
        tol = finite_number(abs_tol, "abs_tol")
        if rel < 0.0 or tol < 0.0:
            raise InvalidInputError("rel_tol" if rel < 0.0 else "abs_tol", "must be >= 0", got=min(rel, tol))
        gap = math.hypot(self.x - o.x, self.y - o.y, self.z - o.z)
        scale = max(math.hypot(self.x, self.y, self.z), math.hypot(o.x, o.y, o.z))
        return gap <= max(rel * scale, tol)

    def __array__(self, dtype: Any = None, copy: bool | None = None) -> NDArray[Any]:
        """numpy's array protocol (numpy 2 signature): a new float64 array of shape ``(3,)``.
        ``copy=False`` is refused, as numpy asks, since the array is always a new one."""
        if copy is False:
            raise ValueError("a Vector3D is not backed by an array: converting it always copies")
        return np.array((self.x, self.y, self.z), dtype=np.float64 if dtype is None else dtype)

    # --- container protocol -------------------------------------------------------------
    def __iter__(self) -> Iterator[float]:
        yield self.x
        yield self.y
        yield self.z

    def __len__(self) -> int:
        return 3

    @overload
    def __getitem__(self, index: int) -> float: ...
    @overload
    def __getitem__(self, index: slice) -> tuple[float, ...]: ...
    def __getitem__(self, index: int | slice) -> float | tuple[float, ...]:
        return (self.x, self.y, self.z)[index]

    def __abs__(self) -> float:
        """The length, ``|v|``."""
        return self.length()

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
        if not isinstance(scalar, numbers.Real):
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
    """A :class:`Vector3D` from a ``Vector3D`` or a sequence (or array) of 2 or 3 finite numbers.

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
    return Vector3D(*as_vector_components(value, field))


def as_vector_3d(value: object, field: str, owner: str) -> Vector3D:
    """A :class:`Vector3D` for a 3D shape (``owner``: "a sphere"): a ``Vector3D`` as it is, or a
    sequence (or array) of exactly three finite numbers; two are refused, never padded with z = 0.

    >>> as_vector_3d((1, 2, 3), "center", "a sphere")
    Vector3D(x=1.0, y=2.0, z=3.0)
    >>> as_vector_3d((1, 2), "center", "a sphere")
    Traceback (most recent call last):
    ...
    collisionlab.errors.InvalidInputError: center: a sphere needs three numbers (x, y, z), \
not 2 (got (1, 2))
    """
    if isinstance(value, Vector3D):
        return value
    sequence = _sequence(value, field)
    if len(sequence) != 3:
        raise InvalidInputError(field, f"{owner} needs three numbers (x, y, z), not {len(sequence)}", got=value)
    return Vector3D(*as_vector_components(sequence, field))


def _sequence(value: object, field: str) -> Sequence[object]:
    """``value`` as a sequence (numpy arrays and other array-likes as lists), or refused."""
    if isinstance(value, np.ndarray):
        value = value.tolist()  # plain floats (nested lists for a 2-D array, refused later)
    elif not isinstance(value, (str, bytes, Sequence)) and hasattr(value, "__len__") and hasattr(value, "__getitem__"):
        value = list(value)  # type: ignore[call-overload]  # other array-likes
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence):
        raise InvalidInputError(field, "must be a list of 2 or 3 numbers, like [x, y, z]", got=value)
    return value


def as_vector_components(value: object, field: str) -> tuple[float, float, float]:
    """The three finite components of a sequence or array of 2 or 3 numbers (z = 0 for 2)."""
    if isinstance(value, Vector3D):
        return (value.x, value.y, value.z)
    value = _sequence(value, field)
    if len(value) not in (2, 3):
        raise InvalidInputError(field, "must have 2 or 3 components, like [x, y] or [x, y, z]", got=value)
    components = [finite_number(c, f"{field}[{i}]") for i, c in enumerate(value)]
    return (components[0], components[1], components[2] if len(components) == 3 else 0.0)


def _operand(value: object) -> Vector3D | None:
    """The other operand of ``+`` or ``-`` as a vector, or ``None`` when it is not vector-like
    (so that Python raises its usual ``TypeError``). A malformed sequence is still refused."""
    if isinstance(value, Vector3D):
        return value
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or not hasattr(value, "__getitem__"):
        return None
    return as_vector(value, "other")
