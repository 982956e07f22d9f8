"""A shape as a row of the engine's arrays (:mod:`.state`): its kind code, extents, corners or
point and normal. Apart from :mod:`.state`, which builds whole worlds from a scenario, so that
the time-of-impact queries (:mod:`collisionlab.toi`), which fill one row per shape, stay in the
collision layer: this module reaches the shapes and the kernels' kind codes, nothing above."""

from __future__ import annotations

from ..shapes import AABB, Circle, Line, Plane, Shape
from . import pair_separation as ps

__all__ = ["Triple", "body_row", "static_row"]

#: Three floats: an extent, a corner, a point or a normal.
Triple = tuple[float, float, float]


def body_row(shape: Shape) -> tuple[int, Triple]:
    """A moving shape's ``kind`` and half extents ``ext`` (its centre is its ``pos``).

    >>> body_row(AABB((0, 0), (2, 4)))[1], body_row(Circle((0, 0), 0.5))[1]
    ((1.0, 2.0, 0.0), (0.5, 0.5, 0.5))
    """
    if isinstance(shape, AABB):
        return (ps.BOX_2D if shape.dim == 2 else ps.BOX_3D), shape.half_size.as_tuple()
    if isinstance(shape, (Line, Plane)):
        raise TypeError(f"a {type(shape).__name__} cannot move: it is a static obstacle")
    return (ps.BALL_2D if isinstance(shape, Circle) else ps.BALL_3D), (shape.radius,) * 3


def static_row(shape: Shape) -> tuple[int, Triple, Triple]:
    """A static shape's ``s_kind``, ``s_a`` and ``s_b``: a box's two corners, or a line's or
    plane's point and unit normal."""
    if isinstance(shape, AABB):
        return ps.STATIC_BOX, shape.min_corner.as_tuple(), shape.max_corner.as_tuple()
    if isinstance(shape, (Line, Plane)):
        return ps.STATIC_BOUNDARY, shape.point.as_tuple(), shape.unit_normal.as_tuple()
    raise TypeError(f"a {type(shape).__name__} cannot be a static obstacle")
