"""Collision queries: golden values, the touching policy at +-1 ulp, degenerate contacts,
unsupported pairs, and hypothesis properties over random shapes of every supported pair."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from typing import Any

import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from collisionlab import (
    AABB,
    Circle,
    Contact,
    Line,
    Plane,
    Separation,
    Sphere,
    UnsupportedPairError,
    Vector3D,
    contact,
    distance,
    intersects,
    separation,
    supported_pairs,
)
from collisionlab.errors import OutOfRangeError
from collisionlab.narrowphase import (
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
from collisionlab.tolerances import FALLBACK_NORMAL
from tests.strategies import COORD, shape_pairs, vectors

R2 = math.sqrt(2.0)
R3 = math.sqrt(3.0)
up = math.nextafter


def vec_close(got: Vector3D, expected: tuple[float, ...] | Vector3D, tol: float = 1e-15) -> bool:
    e = Vector3D(*expected)
    return (got - e).length() <= tol * (1.0 + e.length())


def check(sep: Separation, dist: float, normal: tuple[float, ...], point: tuple[float, ...]) -> None:
    assert sep.distance == pytest.approx(dist, rel=1e-15, abs=1e-15)
    assert vec_close(sep.normal, normal), sep.normal
    assert vec_close(sep.point, point), sep.point


# --- golden values, worked by hand ------------------------------------------------------------------
def test_circle_circle_golden() -> None:
    # |(3,4) - (0,0)| = 5, minus 1 + 2: gap 2, normal (3,4)/5. Surface points (0.6, 0.8) on A and
    # (3,4) - 2(0.6,0.8) = (1.8, 2.4) on B; midway (1.2, 1.6)
    check(separation_circle_circle(Circle((0, 0), 1), Circle((3, 4), 2)), 2.0, (0.6, 0.8), (1.2, 1.6))
    # centres 1 apart, radii 2 + 2: overlap 3; surface points (2,0) and (-1,0), midway (0.5, 0)
    check(separation_circle_circle(Circle((0, 0), 2), Circle((1, 0), 2)), -3.0, (1, 0), (0.5, 0))


def test_sphere_sphere_golden() -> None:
    # centres 2.5 apart along z, radii 1 + 2: overlap 0.5; surface points z = 4 (A) and 3.5 (B)
    check(separation_sphere_sphere(Sphere((1, 2, 3), 1), Sphere((1, 2, 5.5), 2)), -0.5, (0, 0, 1), (1, 2, 3.75))
    # (2,3,6) has length 7: gap 7 - (1 + 1) = 5, normal (2,3,6)/7
    s = separation_sphere_sphere(Sphere((0, 0, 0), 1), Sphere((2, 3, 6), 1))
    assert s.distance == 5.0
    assert vec_close(s.normal, (2 / 7, 3 / 7, 6 / 7))


def test_aabb_aabb_golden() -> None:
    # x: max(0 - 3, 1.5 - 2) = -0.5, y: max(0 - 3, 1 - 2) = -1; least overlap x, 0.5;
    # B's centre x 2.25 > A's 1: +x. Overlap region [1.5,2]x[1,2], middle (1.75, 1.5)
    check(separation_aabb_aabb(AABB((0, 0), (2, 2)), AABB((1.5, 1), (3, 3))), -0.5, (1, 0), (1.75, 1.5))
    # 3D, apart: gaps x 4 - 1 = 3, y 5 - 1 = 4, z overlapping: distance 5 (3-4-5), normal (0.6, 0.8, 0);
    # middle x (1+4)/2, y (1+5)/2, z of the shared [0,1]
    check(
        separation_aabb_aabb(AABB((0, 0, 0), (1, 1, 1)), AABB((4, 5, 0), (5, 6, 1))), 5.0, (0.6, 0.8, 0), (2.5, 3, 0.5)
    )
    # B below-left of A: gaps 0 - (-2) = 2 in x, 0 - (-4) = 4 in y: sqrt(4 + 16) = 2 sqrt(5), normal (-1,-2)/sqrt(5)
    s = separation_aabb_aabb(AABB((0, 0), (1, 1)), AABB((-3, -5), (-2, -4)))
    assert s.distance == pytest.approx(2 * math.sqrt(5), rel=1e-15)
    assert vec_close(s.normal, (-1 / math.sqrt(5), -2 / math.sqrt(5)))
    # 3D overlap, least along z: x overlap 2, y overlap 2, z overlap 0.5; B's centre lower in z: -z
    check(
        separation_aabb_aabb(AABB((0, 0, 0), (2, 2, 2)), AABB((0, 0, -1), (2, 2, 0.5))), -0.5, (0, 0, -1), (1, 1, 0.25)
    )


def test_line_circle_golden() -> None:
    # Line through 0 along (1,1): unit normal (-1,1)/sqrt2. Q = (0,2): s = 2/sqrt2 = sqrt2,
    # gap sqrt2 - 1. S = Q - sqrt2 n = (1, 1) (lab eq. 6); circle's near point Q - n = (1/sqrt2, 2 - 1/sqrt2);
    # midway ((1 + 1/sqrt2)/2, (3 - 1/sqrt2)/2)
    k = 1 / R2
    check(
        separation_line_circle(Line((0, 0), (1, 1)), Circle((0, 2), 1)),
        R2 - 1,
        (-k, k),
        ((1 + k) / 2, (3 - k) / 2),
    )
    # circle 0.5 below the x axis, radius 1: overlap 0.5, normal -y; S = (3, 0), near point (3, 0.5)
    check(separation_line_circle(Line((0, 0), (1, 0)), Circle((3, -0.5), 1)), -0.5, (0, -1), (3, 0.25))


def test_plane_sphere_golden() -> None:
    # plane z = 1 from three points (normal (1,0,0) x (0,1,0) = +z); centre 3 above, radius 2: gap 1;
    # S = (5,5,1) (lab eq. 8), near point (5,5,2), midway (5,5,1.5)
    plane = Plane.from_points((0, 0, 1), (1, 0, 1), (0, 1, 1))
    check(separation_plane_sphere(plane, Sphere((5, 5, 4), 2)), 1.0, (0, 0, 1), (5, 5, 1.5))
    # tilted: n = (1,1,1)/sqrt3, centre (1,1,1) at height 3/sqrt3 = sqrt3, radius 1: gap sqrt3 - 1
    s = separation_plane_sphere(Plane((0, 0, 0), (1, 1, 1)), Sphere((1, 1, 1), 1))
    assert s.distance == pytest.approx(R3 - 1, rel=1e-15)


def test_circle_aabb_golden() -> None:
    # clamp (0,0) to [2,4]x[-1,1] -> (2,0): 2 - 1 = gap 1; midway between (1,0) and (2,0)
    check(separation_circle_aabb(Circle((0, 0), 1), AABB((2, -1), (4, 1))), 1.0, (1, 0), (1.5, 0))
    # nearest point is the corner (3,4): 5 - 1 = 4, normal (0.6, 0.8); midway (0.6,0.8)..(3,4)
    check(separation_circle_aabb(Circle((0, 0), 1), AABB((3, 4), (5, 6))), 4.0, (0.6, 0.8), (1.8, 2.4))
    # exactly touching at the corner: |(3,4)| = 5 = r, depth 0 (a diagonal contact is not in the
    # +-1 ulp table: the rounded square root cannot resolve 1 ulp of a coordinate)
    touching = contact(Circle((0, 0), 5), AABB((3, 4), (4, 5)))
    assert touching is not None and touching.depth == 0.0
    # centre inside [0,4]^2 at (1, 0.5): face distances x- 1, x+ 3, y- 0.5, y+ 3.5 -> y- face;
    # depth 1 + 0.5, box pushed +y; circle's far point (1, 1.5), face point (1, 0): midway (1, 0.75)
    check(separation_circle_aabb(Circle((1, 0.5), 1), AABB((0, 0), (4, 4))), -1.5, (0, 1), (1, 0.75))


def test_sphere_aabb_golden() -> None:
    # clamp (0,0,3) to [-1,1]^3 -> (0,0,1): 2 - 1 = 1, normal -z; midway (0,0,2)..(0,0,1)
    check(separation_sphere_aabb(Sphere((0, 0, 3), 1), AABB((-1, -1, -1), (1, 1, 1))), 1.0, (0, 0, -1), (0, 0, 1.5))
    # a 2D box is the flat box z = 0: clamp (1,1,0.5) -> (1,1,0), 0.5 - 1 = -0.5;
    # near point (1,1,-0.5), midway with (1,1,0)
    check(separation_sphere_aabb(Sphere((1, 1, 0.5), 1), AABB((0, 0), (2, 2))), -0.5, (0, 0, -1), (1, 1, -0.25))


def test_line_aabb_golden() -> None:
    # x axis, box [0,2]x[1,3]: centre height 2, half height 1: gap 1; nearest vertex (1, 1)
    # (x from the centre, n_x = 0), midway to the line (1, 0.5)
    check(separation_line_aabb(Line((0, 0), (1, 0)), AABB((0, 1), (2, 3))), 1.0, (0, 1), (1, 0.5))
    # line y = -x: unit normal (-d_y, d_x) = (1,1)/sqrt2; box [1,2]^2: centre 3/sqrt2, projected
    # half size (0.5 + 0.5)/sqrt2: gap 2/sqrt2 = sqrt2, the height of the vertex (1,1)
    s = separation_line_aabb(Line((0, 0), (1, -1)), AABB((1, 1), (2, 2)))
    assert s.distance == pytest.approx(R2, rel=1e-15)
    assert vec_close(s.normal, (1 / R2, 1 / R2))
    assert vec_close(s.point, (0.5, 0.5))  # (1,1) - n sqrt2 / 2


def test_plane_aabb_golden() -> None:
    # z = 0, box z in [-0.25, 1]: centre 0.375, half height 0.625: overlap 0.25; vertex (0.5,0.5,-0.25)
    check(
        separation_plane_aabb(Plane((0, 0, 0), (0, 0, 1)), AABB((0, 0, -0.25), (1, 1, 1))),
        -0.25,
        (0, 0, 1),
        (0.5, 0.5, -0.125),
    )
    # box below the plane z = 2: centre 0.5 < 2, normal -z; nearest vertex top z = 1: gap 1; midway z 1.5
    check(
        separation_plane_aabb(Plane((0, 0, 2), (0, 0, 1)), AABB((0, 0, 0), (1, 1, 1))), 1.0, (0, 0, -1), (0.5, 0.5, 1.5)
    )
    # n = (1,1,1)/sqrt3, box [1,2]^3: nearest vertex (1,1,1) at height sqrt3; midway (0.5,0.5,0.5)
    check(separation_plane_aabb(Plane((0, 0, 0), (1, 1, 1)), AABB((1, 1, 1), (2, 2, 2))), R3, (1 / R3,) * 3, (0.5,) * 3)


def test_dispatch_either_order_golden() -> None:
    ball, box = Circle((0, 0), 1), AABB((2, -1), (4, 1))  # gap 1 along +x (see above)
    assert distance(ball, box) == distance(box, ball) == 1.0
    assert not intersects(ball, box) and not intersects(box, ball)
    assert contact(ball, box) is None
    sphere, plane = Sphere((0, 0, 0.25), 1), Plane((0, 0, 0), (0, 0, 1))  # overlap 0.75
    assert contact(plane, sphere) == Contact(Vector3D(0, 0, 1), 0.75, Vector3D(0, 0, -0.375))
    # from the sphere's side the normal points down, depth and point unchanged
    assert contact(sphere, plane) == Contact(Vector3D(0, 0, -1), 0.75, Vector3D(0, 0, -0.375))
    assert intersects(sphere, plane) and distance(sphere, plane) == -0.75


def test_billiard_rail_detection() -> None:
    # the lab's figure 1: a ball of radius 0.5 at (2, 0.4) against the rail y = 0 along x:
    # |QS| = 0.4 <= 0.5, a collision (lab eq. 7) of depth 0.1, normal from rail to ball +y
    found = contact(Line((0, 0), (1, 0)), Circle((2, 0.4), 0.5))
    assert found is not None
    assert found.depth == pytest.approx(0.1, rel=1e-14)
    assert vec_close(found.normal, (0, 1))


def test_supported_pairs_lists_the_nine_pairs() -> None:
    assert supported_pairs() == [
        ("Circle", "Circle"),
        ("Sphere", "Sphere"),
        ("AABB", "AABB"),
        ("Line", "Circle"),
        ("Plane", "Sphere"),
        ("Circle", "AABB"),
        ("Sphere", "AABB"),
        ("Line", "AABB"),
        ("Plane", "AABB"),
    ]


# --- touching policy: exactly touching is a contact of depth 0, at +-1 ulp -----------------------------
# Each row: make(t) builds the pair with a coordinate t; t_touch touches exactly, t_apart and
# t_overlap are 1 ulp away from it on either side. The rows are chosen so that the 1 ulp survives
# the subtraction of the other shape's coordinate (e.g. 5 - 3 is exact at +-1 ulp of 5, but
# (1 - 1 ulp) - 3 rounds back to -2): a step finer than the rounding of the inputs cannot be seen.
TouchRow = tuple[Callable[[float], tuple[Any, Any]], float, float, float]


def _touch(make: Callable[[float], tuple[Any, Any]], touch: float, apart_dir: float) -> TouchRow:
    return (make, touch, up(touch, apart_dir * math.inf), up(touch, -apart_dir * math.inf))


TOUCHING: dict[str, TouchRow] = {
    "circle-circle": _touch(lambda t: (Circle((0, 0), 1), Circle((t, 0), 1)), 2.0, +1),
    "circle-circle-offset": _touch(lambda t: (Circle((10, -7), 0.5), Circle((t, -7), 0.75)), 11.25, +1),
    "sphere-sphere": _touch(lambda t: (Sphere((1, 2, 3), 1.5), Sphere((1, 2, t), 0.5)), 5.0, +1),
    "aabb2-aabb2": _touch(lambda t: (AABB((0, 0), (1, 1)), AABB((t, 0.5), (2, 3))), 1.0, +1),
    "aabb3-aabb3": _touch(lambda t: (AABB((0, 0, 0), (1, 1, 1)), AABB((-1, -1, -3), (2, 2, t))), 0.0, -1),
    "aabb2-corner": _touch(lambda t: (AABB((0, 0), (1, 1)), AABB((t, t), (2, 2))), 1.0, +1),
    "line-circle": _touch(lambda t: (Line((0, 1), (1, 0)), Circle((5, t), 2)), 3.0, +1),
    "line-circle-below": _touch(lambda t: (Line((0, 5), (-3, 0)), Circle((5, t), 2)), 3.0, -1),
    "line-circle-vertical": _touch(lambda t: (Line((2, 0), (0, 1)), Circle((t, 9), 0.5)), 2.5, +1),
    "plane-sphere": _touch(lambda t: (Plane((0, 0, 1), (0, 0, 1)), Sphere((2, 3, t), 2)), 3.0, +1),
    "plane-sphere-below": _touch(lambda t: (Plane((0, 0, 5), (0, 0, 5)), Sphere((2, 3, t), 2)), 3.0, -1),
    "circle-aabb": _touch(lambda t: (Circle((0, 0), 1), AABB((t, -1), (3, 1))), 1.0, +1),
    "sphere-aabb": _touch(lambda t: (Sphere((0, 0, 0), 1), AABB((-1, -1, t), (1, 1, 3))), 1.0, +1),
    "sphere-aabb2": _touch(lambda t: (Sphere((0.5, 0.5, t), 1), AABB((0, 0), (1, 1))), 1.0, +1),
    "line-aabb": _touch(lambda t: (Line((0, 1), (1, 0)), AABB((0, t), (1, 3))), 1.0, +1),
    "line-aabb-below": _touch(lambda t: (Line((0, 1), (1, 0)), AABB((0, -3), (1, t))), 1.0, -1),
    "plane-aabb": _touch(lambda t: (Plane((0, 0, 1), (0, 0, 1)), AABB((0, 0, t), (1, 1, 3))), 1.0, +1),
    "plane-aabb-below": _touch(lambda t: (Plane((0, 0, 1), (0, 0, 1)), AABB((0, 0, -3), (1, 1, t))), 1.0, -1),
    "plane-aabb-at-zero": _touch(lambda t: (Plane((0, 0, 0), (0, 0, 1)), AABB((0, 0, t), (1, 1, 1))), 0.0, +1),
    "plane-aabb2": _touch(lambda t: (Plane((0, 1, 0), (0, 1, 0)), AABB((0, t), (1, 3))), 1.0, +1),
}


def test_touching_table_covers_every_pair() -> None:
    covered = set()
    for make, touch, _, _ in TOUCHING.values():
        a, b = make(touch)
        covered.add((type(a).__name__, type(b).__name__))
    assert covered == set(supported_pairs())


@pytest.mark.parametrize("swap", [False, True], ids=["ab", "ba"])
@pytest.mark.parametrize("row", TOUCHING.values(), ids=TOUCHING.keys())
def test_touching_policy_at_plus_minus_one_ulp(row: TouchRow, swap: bool) -> None:
    make, t_touch, t_apart, t_overlap = row

    def pair(t: float) -> tuple[Any, Any]:
        a, b = make(t)
        return (b, a) if swap else (a, b)

    a, b = pair(t_touch)
    touching = contact(a, b)
    assert intersects(a, b)
    assert distance(a, b) == 0.0
    assert touching is not None and touching.depth == 0.0

    a, b = pair(t_apart)
    assert not intersects(a, b)
    assert contact(a, b) is None
    assert distance(a, b) > 0.0

    a, b = pair(t_overlap)
    overlapping = contact(a, b)
    assert intersects(a, b)
    assert distance(a, b) < 0.0
    assert overlapping is not None and overlapping.depth > 0.0


# --- degenerate contacts: coincident features give a finite unit fallback normal and the full depth ----
_X = tuple(FALLBACK_NORMAL)
DEGENERATE: dict[str, tuple[Any, Any, tuple[float, ...], float]] = {
    # equal centres: FALLBACK_NORMAL, depth r_a + r_b
    "circle-circle": (Circle((1, 2), 1), Circle((1, 2), 3), _X, 4.0),
    "sphere-sphere": (Sphere((-1, 2, 5), 0.5), Sphere((-1, 2, 5), 0.5), _X, 1.0),
    # equal box centres: least overlap x (tie with y: x first), +x; depth 2
    "aabb2-same": (AABB((0, 0), (2, 2)), AABB((0, 0), (2, 2)), (1, 0, 0), 2.0),
    # equal centres, overlaps x 3, y 3, z 3.5: x, depth 3
    "aabb3-cross": (AABB((-1, -2, -3), (1, 2, 3)), AABB((-2, -1, -0.5), (2, 1, 0.5)), (1, 0, 0), 3.0),
    # equal centres; gaps max(0 - 3, 1 - 4) = -3 in x and z, max(0 - 1.5, 0.5 - 2) = -1.5 in y: +y, 1.5
    "aabb3-y": (AABB((0, 0, 0), (4, 2, 4)), AABB((1, 0.5, 1), (3, 1.5, 3)), (0, 1, 0), 1.5),
    # centre on the line: the line's own normal (-1,1)/sqrt2, depth r
    "line-circle": (Line((0, 0), (1, 1)), Circle((2, 2), 1), (-1 / R2, 1 / R2, 0), 1.0),
    "plane-sphere": (Plane((0, 0, 3), (0, 0, 2)), Sphere((7, -1, 3), 2), (0, 0, 1), 2.0),
    # ball centre at the box centre: faces all 1 away, x- first: box pushed +x, depth r + 1
    "circle-aabb": (Circle((1, 1), 0.5), AABB((0, 0), (2, 2)), (1, 0, 0), 1.5),
    "sphere-aabb": (Sphere((0, 0, 0), 1), AABB((-1, -1, -1), (1, 1, 1)), (1, 0, 0), 2.0),
    # centre on the x+ face: that face is 0 away: box pushed -x, depth r
    "sphere-aabb-on-face": (Sphere((1, 0, 0), 1), AABB((-1, -1, -1), (1, 1, 1)), (-1, 0, 0), 1.0),
    # sphere centre in a 2D (flat) box: the z faces are 0 away, z- first: box pushed +z, depth r
    "sphere-aabb2-inside": (Sphere((1, 1, 0), 0.5), AABB((0, 0), (2, 2)), (0, 0, 1), 0.5),
    # box centre on the line / plane: the boundary's normal, depth = projected half size
    "line-aabb": (Line((1, 1), (1, 0)), AABB((0, 0), (2, 2)), (0, 1, 0), 1.0),
    "plane-aabb": (Plane((0, 0, 0), (1, 1, 1)), AABB((-1, -1, -1), (1, 1, 1)), (1 / R3, 1 / R3, 1 / R3), R3),
}


@pytest.mark.parametrize("row", DEGENERATE.values(), ids=DEGENERATE.keys())
def test_degenerate_contacts_use_the_documented_fallback(row: tuple[Any, Any, tuple[float, ...], float]) -> None:
    a, b, normal, depth = row
    same_type = type(a) is type(b)
    for first, second, expected_normal in ((a, b, normal), (b, a, normal if same_type else tuple(-c for c in normal))):
        found = contact(first, second)
        assert found is not None
        assert found.depth == pytest.approx(depth, rel=1e-15)
        assert vec_close(found.normal, expected_normal)
        assert math.isclose(found.normal.length(), 1.0, abs_tol=1e-15)
        assert all(math.isfinite(c) for c in found.point)


# --- unsupported pairs: a clear error, never False ------------------------------------------------------
UNSUPPORTED: dict[str, tuple[object, object]] = {
    "circle-sphere": (Circle((0, 0), 1), Sphere((0, 0, 0), 1)),
    "circle-plane": (Circle((0, 0), 1), Plane((0, 0, 0), (0, 0, 1))),
    "sphere-line": (Sphere((0, 0, 0), 1), Line((0, 0), (1, 0))),
    "line-line": (Line((0, 0), (1, 0)), Line((0, 1), (0, 1))),
    "plane-plane": (Plane((0, 0, 0), (0, 0, 1)), Plane((0, 0, 0), (1, 0, 0))),
    "line-plane": (Line((0, 0), (1, 0)), Plane((0, 0, 0), (0, 0, 1))),
    "circle-aabb3": (Circle((0, 0), 1), AABB((0, 0, 0), (1, 1, 1))),
    "line-aabb3": (Line((0, 0), (1, 0)), AABB((0, 0, 0), (1, 1, 1))),
    "aabb2-aabb3": (AABB((0, 0), (1, 1)), AABB((0, 0, 0), (1, 1, 1))),
    "circle-int": (Circle((0, 0), 1), 3),
    "none-sphere": (None, Sphere((0, 0, 0), 1)),
    "circle-tuple": (Circle((0, 0), 1), (0, 0)),
}


@pytest.mark.parametrize("query", [separation, contact, intersects, distance])
@pytest.mark.parametrize("swap", [False, True], ids=["ab", "ba"])
@pytest.mark.parametrize("pair", UNSUPPORTED.values(), ids=UNSUPPORTED.keys())
def test_unsupported_pair_raises(pair: tuple[object, object], swap: bool, query: Callable[..., object]) -> None:
    a, b = (pair[1], pair[0]) if swap else pair
    with pytest.raises(UnsupportedPairError) as info:
        query(a, b)
    assert isinstance(info.value, TypeError)
    message = str(info.value)
    for shape in (a, b):
        if type(shape).__name__ in {"Circle", "Sphere", "Line", "Plane"}:
            assert type(shape).__name__.lower() in message.lower()


# --- properties ------------------------------------------------------------------------------------------
def _center(shape: Any) -> Vector3D:
    if isinstance(shape, (Circle, Sphere, AABB)):
        return shape.center
    return shape.point


def _scale(a: Any, b: Any) -> float:
    """A length scale of the scene, for tolerances."""
    sizes = []
    for s in (a, b):
        sizes.append(_center(s).length())
        if isinstance(s, (Circle, Sphere)):
            sizes.append(s.radius)
        if isinstance(s, AABB):
            sizes.append(s.half_size.length())
    return 1.0 + max(sizes)


def _boundary_heights(boundary: Line | Plane, box: AABB) -> list[float]:
    n = boundary.unit_normal
    return [
        n.dot(Vector3D(*corner) - boundary.point)
        for corner in itertools.product(*zip(box.min_corner, box.max_corner, strict=True))
    ]


def reference_distance(a: Any, b: Any) -> float:
    """An independent (slower, simpler) signed distance for every supported pair."""
    if isinstance(b, (Line, Plane)) or (isinstance(a, AABB) and isinstance(b, (Circle, Sphere))):
        a, b = b, a
    if isinstance(a, (Circle, Sphere)) and isinstance(b, (Circle, Sphere)):
        return math.dist(a.center, b.center) - a.radius - b.radius
    if isinstance(a, (Line, Plane)) and isinstance(b, (Circle, Sphere)):
        return abs(a.unit_normal.dot(b.center - a.point)) - b.radius
    if isinstance(a, (Line, Plane)):  # and a box: the lowest corner on the centre's side
        heights = _boundary_heights(a, b)
        return min(heights) if a.unit_normal.dot(b.center - a.point) >= 0.0 else -max(heights)
    if isinstance(a, AABB):  # two boxes
        gaps = [
            max(al - bh, bl - ah)
            for al, ah, bl, bh in zip(a.min_corner, a.max_corner, b.min_corner, b.max_corner, strict=True)
        ]
        gaps = gaps[: a.dim]
        if max(gaps) > 0.0:
            return math.hypot(*(max(g, 0.0) for g in gaps))
        return max(gaps)
    # a ball and a box
    dims = 2 if isinstance(a, Circle) else 3
    c, lo, hi = a.center, b.min_corner, b.max_corner
    outside = math.hypot(*(max(lo_i - c_i, 0.0, c_i - hi_i) for c_i, lo_i, hi_i in zip(c, lo, hi, strict=True)))
    if outside > 0.0:
        return outside - a.radius
    inside = min(min(c_i - lo_i, hi_i - c_i) for c_i, lo_i, hi_i in list(zip(c, lo, hi, strict=True))[:dims])
    return -(a.radius + inside)


def _flip_exempt(a: Any, b: Any) -> bool:
    """The documented exceptions to ``contact(b, a) == contact(a, b).flipped()``."""
    if isinstance(a, (Circle, Sphere)) and type(a) is type(b):
        return bool(a.center == b.center)
    if isinstance(a, AABB) and isinstance(b, AABB):
        offset = b.center - a.center
        return distance(a, b) <= 0.0 and 0.0 in offset.as_tuple()[: a.dim]
    return False


@given(shape_pairs())
def test_intersects_is_symmetric(pair: tuple[Any, Any]) -> None:
    a, b = pair
    assert intersects(a, b) == intersects(b, a)
    assert distance(a, b) == distance(b, a)


@given(shape_pairs())
def test_contact_reversed_is_contact_flipped(pair: tuple[Any, Any]) -> None:
    a, b = pair
    assume(not _flip_exempt(a, b))
    forward, backward = contact(a, b), contact(b, a)
    if forward is None:
        assert backward is None
    else:
        assert backward == forward.flipped()


@given(shape_pairs())
def test_normals_are_unit_and_everything_is_finite(pair: tuple[Any, Any]) -> None:
    a, b = pair
    sep = separation(a, b)
    assert math.isfinite(sep.distance)
    assert all(math.isfinite(c) for c in (*sep.normal, *sep.point))
    assert math.isclose(sep.normal.length(), 1.0, abs_tol=1e-12)
    found = contact(a, b)
    if found is not None:
        assert math.isclose(found.normal.length(), 1.0, abs_tol=1e-12)
        assert math.isfinite(found.depth)


@given(shape_pairs())
def test_queries_agree_with_each_other(pair: tuple[Any, Any]) -> None:
    a, b = pair
    d = distance(a, b)
    found = contact(a, b)
    assert intersects(a, b) == (d <= 0.0) == (found is not None)
    if found is not None:
        assert found.depth >= 0.0
        assert found.depth == -d
        assert found.normal == separation(a, b).normal


@given(st.sampled_from([10.0, COORD]).flatmap(lambda bound: shape_pairs(bound=bound)))
def test_distance_matches_an_independent_reference(pair: tuple[Any, Any]) -> None:
    a, b = pair
    assert distance(a, b) == pytest.approx(reference_distance(a, b), rel=1e-9, abs=1e-9 * _scale(a, b))


def _translated(shape: Any, t: Vector3D) -> Any:
    if isinstance(shape, (Circle, Sphere)):
        return type(shape)(shape.center + t, shape.radius)
    if isinstance(shape, AABB):
        return AABB(shape.min_corner + t, shape.max_corner + t)
    return type(shape)(shape.point + t, shape.normal if isinstance(shape, Plane) else shape.direction)


def _is_2d(shape: Any) -> bool:
    return isinstance(shape, (Circle, Line)) or (isinstance(shape, AABB) and shape.dim == 2)


def _well_conditioned(a: Any, b: Any, margin: float) -> bool:
    """Whether the normal (and which case of each query applies) is stable under a rounding
    change of ``margin``: no features nearly coincide and no boundary case is nearly met."""
    if isinstance(b, (Line, Plane)) or (isinstance(a, AABB) and isinstance(b, (Circle, Sphere))):
        a, b = b, a
    if isinstance(a, (Circle, Sphere)) and isinstance(b, (Circle, Sphere)):
        return (b.center - a.center).length() > margin
    if isinstance(a, (Line, Plane)):
        return abs(a.unit_normal.dot(_center(b) - a.point)) > margin
    if isinstance(a, AABB):  # two boxes
        dims = a.dim
        gaps = [
            max(al - bh, bl - ah)
            for al, ah, bl, bh in zip(a.min_corner, a.max_corner, b.min_corner, b.max_corner, strict=True)
        ]
        gaps = gaps[:dims]
        if any(abs(g) <= margin for g in gaps):
            return False
        if max(gaps) > 0.0:
            return True
        ordered = sorted(gaps, reverse=True)
        axis = gaps.index(ordered[0])
        offset = abs((b.center - a.center).as_tuple()[axis])
        return (dims == 1 or ordered[0] - ordered[1] > margin) and offset > margin
    # a ball and a box: the centre is not near any face plane, nor (inside) equally near two faces
    dims = 2 if isinstance(a, Circle) else 3
    c = a.center.as_tuple()
    faces = [face for i in range(3) for face in (c[i] - b.min_corner.as_tuple()[i], b.max_corner.as_tuple()[i] - c[i])]
    if any(abs(f) <= margin for f in faces[: 2 * dims]):
        return False
    if all(f > 0.0 for f in faces[: 2 * dims]):  # inside
        ordered = sorted(faces[: 2 * dims])
        return ordered[1] - ordered[0] > margin
    return True


@given(
    st.sampled_from([10.0, COORD]).flatmap(lambda bound: shape_pairs(bound=bound)),
    vectors(3, bound=COORD),
)
def test_translating_the_scene_changes_nothing(pair: tuple[Any, Any], shift: Vector3D) -> None:
    a, b = pair
    if _is_2d(a) or _is_2d(b):
        shift = Vector3D(shift.x, shift.y, 0.0)
    moved_a, moved_b = _translated(a, shift), _translated(b, shift)
    tol = 1e-9 * (_scale(a, b) + shift.length())
    before, after = separation(a, b), separation(moved_a, moved_b)
    assert after.distance == pytest.approx(before.distance, abs=tol)
    if abs(before.distance) > tol:
        assert intersects(moved_a, moved_b) == intersects(a, b)
    assume(_well_conditioned(a, b, margin=1e-6 * (_scale(a, b) + shift.length())))
    assert vec_close(after.normal, before.normal, tol=1e-6)
    assert vec_close(after.point, before.point + shift, tol=tol)


@pytest.mark.parametrize(
    "a, b",
    [
        (Sphere((0, 0, 0), 1.7e308), Sphere((0, 0, 0), 1e308)),  # r_a + r_b overflows: depth inf
        (Sphere((-1.7e308, -1.7e308, -1e15), 1.608e308), Sphere((-1e15, 3, -1e15), 1.608e308)),  # nan
    ],
)
def test_a_separation_that_overflows_is_out_of_range_not_inf_or_nan(a: Sphere, b: Sphere) -> None:
    # Found by a fuzz harness (issue 28, escape 4): contact() returned depth inf, or nan and a
    # zero normal.
    with pytest.raises(OutOfRangeError, match="too large or too far apart"):
        contact(a, b)
