"""Hypothesis strategies for collisionlab's values, shared by every test module.

Coordinates are bounded (``|x| <= COORD``) and radii and box edges lie in ``[SIZE_MIN, SIZE_MAX]``
so that floating point stays sane: sums and products of a few such numbers are exact to about
1e-12 relative, far from overflow and from the subnormal range.

    from tests.strategies import circles, spheres, aabbs, lines, planes, vectors, shape_pairs
"""

from __future__ import annotations

from hypothesis import strategies as st

from collisionlab import AABB, Circle, Line, Plane, Sphere, Vector3D

__all__ = [
    "COORD",
    "DIRECTION_MIN",
    "PAIR_NAMES",
    "SIZE_MAX",
    "SIZE_MIN",
    "aabbs",
    "circles",
    "coords",
    "directions",
    "lines",
    "masses",
    "planes",
    "radii",
    "restitutions",
    "shape_pairs",
    "shapes_2d",
    "spheres",
    "vectors",
]

COORD = 1e3
SIZE_MIN = 1e-2
SIZE_MAX = 1e2
#: Directions and normals are at least this long, so normalising them is well conditioned.
DIRECTION_MIN = 1e-3


def coords(bound: float = COORD) -> st.SearchStrategy[float]:
    """A finite float in ``[-bound, bound]``."""
    return st.floats(-bound, bound, allow_nan=False, allow_infinity=False)


def radii() -> st.SearchStrategy[float]:
    """A radius in ``[SIZE_MIN, SIZE_MAX]``."""
    return st.floats(SIZE_MIN, SIZE_MAX, allow_nan=False, allow_infinity=False)


def vectors(dim: int = 3, bound: float = COORD) -> st.SearchStrategy[Vector3D]:
    """A :class:`Vector3D` with components in ``[-bound, bound]``; ``z = 0`` when ``dim == 2``."""
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, not {dim!r}")
    if dim == 2:
        return st.builds(Vector3D, coords(bound), coords(bound))
    return st.builds(Vector3D, coords(bound), coords(bound), coords(bound))


def directions(dim: int = 3) -> st.SearchStrategy[Vector3D]:
    """A non-zero vector (length >= ``DIRECTION_MIN``), for a line direction or a normal."""
    return vectors(dim, bound=10.0).filter(lambda v: v.length() >= DIRECTION_MIN)


def circles(bound: float = COORD) -> st.SearchStrategy[Circle]:
    return st.builds(Circle, vectors(2, bound), radii())


def spheres(bound: float = COORD) -> st.SearchStrategy[Sphere]:
    return st.builds(Sphere, vectors(3, bound), radii())


@st.composite
def aabbs(draw: st.DrawFn, dim: int = 3, bound: float = COORD) -> AABB:
    """A box with its min corner in ``[-bound, bound]`` and every edge in ``[SIZE_MIN, SIZE_MAX]``;
    ``dim`` is 2 (z = 0) or 3."""
    low = draw(vectors(dim, bound))
    edges = [draw(radii()) for _ in range(dim)] + [0.0] * (3 - dim)
    high = Vector3D(*(lo + edge for lo, edge in zip(low, edges, strict=True)))
    return AABB(low, high)


def lines(bound: float = COORD) -> st.SearchStrategy[Line]:
    return st.builds(Line, vectors(2, bound), directions(2))


def planes(bound: float = COORD) -> st.SearchStrategy[Plane]:
    return st.builds(Plane, vectors(3, bound), directions(3))


def masses(ratio: float = 1e3) -> st.SearchStrategy[float]:
    """A finite mass in ``[1, ratio]``, so any two differ by a factor of at most ``ratio``."""
    return st.floats(1.0, ratio, allow_nan=False, allow_infinity=False)


def restitutions() -> st.SearchStrategy[float]:
    """A coefficient of restitution in ``[0, 1]``, the ends included as likely examples."""
    return st.one_of(st.sampled_from([0.0, 1.0]), st.floats(0.0, 1.0, allow_nan=False))


def shapes_2d(bound: float = COORD) -> st.SearchStrategy[Circle | AABB]:
    return st.one_of(circles(bound), aabbs(2, bound))


#: Every supported pair, as (name, strategy of A, strategy of B), in the dispatch table's order.
def _pair_strategies(bound: float) -> dict[str, tuple[st.SearchStrategy[object], st.SearchStrategy[object]]]:
    return {
        "circle-circle": (circles(bound), circles(bound)),
        "sphere-sphere": (spheres(bound), spheres(bound)),
        "aabb2-aabb2": (aabbs(2, bound), aabbs(2, bound)),
        "aabb3-aabb3": (aabbs(3, bound), aabbs(3, bound)),
        "line-circle": (lines(bound), circles(bound)),
        "plane-sphere": (planes(bound), spheres(bound)),
        "circle-aabb2": (circles(bound), aabbs(2, bound)),
        "sphere-aabb3": (spheres(bound), aabbs(3, bound)),
        "sphere-aabb2": (spheres(bound), aabbs(2, bound)),
        "line-aabb2": (lines(bound), aabbs(2, bound)),
        "plane-aabb3": (planes(bound), aabbs(3, bound)),
        "plane-aabb2": (planes(bound), aabbs(2, bound)),
    }


PAIR_NAMES = tuple(_pair_strategies(COORD))


@st.composite
def shape_pairs(draw: st.DrawFn, bound: float = 10.0, mirrored: bool = True) -> tuple[object, object]:
    """A supported pair ``(a, b)`` of shapes, in either order when ``mirrored``.

    The default ``bound`` is small (10) so that shapes of radius/edge up to 100 are often in
    contact; pass ``COORD`` for spread-out scenes.
    """
    name = draw(st.sampled_from(PAIR_NAMES))
    first, second = _pair_strategies(bound)[name]
    a, b = draw(first), draw(second)
    if mirrored and draw(st.booleans()):
        return b, a
    return a, b
