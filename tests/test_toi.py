"""Time of impact (collisionlab.toi): hand-worked values for every pair in both orders, the
degenerate cases, high speeds, gravity, and agreement with a brute-force fine-stepping search."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np
import pytest

from collisionlab import AABB, Circle, InvalidInputError, Line, Plane, Sphere, UnsupportedPairError, Vector3D
from collisionlab.errors import OutOfRangeError
from collisionlab.narrowphase import distance, separation
from collisionlab.shapes import Shape
from collisionlab.toi import (
    Impact,
    time_of_impact,
    time_of_impact_aabb_aabb,
    time_of_impact_circle_aabb,
    time_of_impact_circle_circle,
    time_of_impact_line_aabb,
    time_of_impact_line_circle,
    time_of_impact_plane_aabb,
    time_of_impact_plane_sphere,
    time_of_impact_sphere_aabb,
    time_of_impact_sphere_sphere,
    toi_supported_pairs,
)

from . import toi_reference

R2 = math.sqrt(2.0)
R3 = math.sqrt(3.0)
ZERO = (0.0, 0.0, 0.0)


def moved(shape: Shape, offset: Vector3D) -> Shape:
    """``shape`` translated by ``offset``."""
    if isinstance(shape, (Circle, Sphere)):
        return shape.moved_to(shape.center + offset)
    if isinstance(shape, AABB):
        return AABB(shape.min_corner + offset, shape.max_corner + offset)
    if isinstance(shape, Line):
        return Line(shape.point + offset, shape.direction)
    return Plane(shape.point + offset, shape.normal)


def offset_at(velocity: Vector3D, acceleration: Vector3D, t: float) -> Vector3D:
    return velocity * t + acceleration * (0.5 * t * t)


def close(u: Vector3D, v: Vector3D, tol: float = 1e-12) -> bool:
    return (u - v).length() <= tol


# --- hand-worked values, every pair, both orders ------------------------------------------------------
class Golden(NamedTuple):
    """A hand-worked case: ``a`` and ``b`` moving with the given velocities and accelerations touch
    first at ``time`` with ``normal`` (from a to b)."""

    id: str
    a: Shape
    b: Shape
    velocity_b: tuple[float, ...]
    time: float
    normal: Vector3D
    velocity_a: tuple[float, ...] = ZERO
    acceleration_a: tuple[float, ...] = ZERO
    acceleration_b: tuple[float, ...] = ZERO
    max_time: float = 10.0


BOX = AABB((-1, -1, -1), (1, 1, 1))
FLOOR = Plane((0, 0, 0), (0, 0, 1))
GOLDEN: list[Golden] = [
    # gap |5 - 0| - 2 = 3 closes at 2 per unit time: 3 / 2
    Golden("circle-circle", Circle((0, 0), 1), Circle((5, 0), 1), (-2, 0), 1.5, Vector3D(1, 0)),
    # both move: centres 10 apart, radii 1 + 1, closing speed 2: (10 - 2) / 2
    Golden("circle-circle both", Circle((0, 0), 1), Circle((10, 0), 1), (-1, 0), 4.0, Vector3D(1, 0), (1, 0)),
    # |p| = |(0, 3, 4)| = 5 closes at 5 to r_a + r_b = 2.5: t = 0.5; normal p/|p| = (0, 0.6, 0.8)
    Golden("sphere-sphere", Sphere((0, 0, 0), 1), Sphere((0, 3, 4), 1.5), (0, -3, -4), 0.5, Vector3D(0, 0.6, 0.8)),
    # a relative acceleration (the quartic path): B's centre at x = 10 - t^2 reaches 2 at t = sqrt 8
    Golden(
        "sphere-sphere accelerated",
        Sphere((0, 0, 0), 1),
        Sphere((10, 0, 0), 1),
        ZERO,
        math.sqrt(8.0),
        Vector3D(1, 0, 0),
        acceleration_b=(-2, 0, 0),
    ),
    # x gap 3 - 1 = 2 at speed 1; y already overlaps
    Golden("aabb-aabb 2D", AABB((0, 0), (1, 1)), AABB((3, 0.5), (4, 1.5)), (-1, 0), 2.0, Vector3D(1, 0)),
    # x enters at (3 - 1)/1 = 2 (exits at 5), y enters at (2 - 1)/1 = 1 (exits at 3): max entry 2, axis x
    Golden(
        "aabb-aabb 3D", AABB((0, 0, 0), (1, 1, 1)), AABB((3, 2, 0.5), (5, 3, 1.5)), (-1, -1, 0), 2.0, Vector3D(1, 0, 0)
    ),
    # y enters at (5 - 1)/1 = 4 (exits at 6), x enters at 2 and exits at 5: first contact 4 along y
    Golden(
        "aabb-aabb 3D y last",
        AABB((0, 0, 0), (1, 1, 1)),
        AABB((3, 5, 0.5), (5, 6, 1.5)),
        (-1, -1, 0),
        4.0,
        Vector3D(0, 1, 0),
    ),
    # A moves instead of B: B at x in [-4, -3]; A's face x = 0 reaches -3 at speed 2 at t = 1.5
    Golden("aabb-aabb A moves", AABB((0, 0), (1, 1)), AABB((-4, 0), (-3, 1)), ZERO, 1.5, Vector3D(-1, 0), (-2, 0)),
    # line y = 0, circle centre y = 5, r = 1, n.v = -2: 5 - 2t = 1 at t = 2
    Golden("line-circle", Line((0, 0), (1, 0)), Circle((0, 5), 1), (3, -2), 2.0, Vector3D(0, 1)),
    # line y = x (n = (-1, 1)/sqrt2); circle at (3, 0): s0 = -3/sqrt2, n.v = 2/sqrt2 = sqrt2;
    # -3/sqrt2 + sqrt2 t = -1 -> t = 1.5 - 1/sqrt2; the circle is on the -n side: normal (1, -1)/sqrt2
    Golden("line-circle below", Line((0, 0), (1, 1)), Circle((3, 0), 1), (-1, 1), 1.5 - 1 / R2, Vector3D(1, -1) / R2),
    # radius 1 at height 10 at 1e6 towards the plane: (10 - 1) / 1e6
    Golden("plane-sphere fast", FLOOR, Sphere((0, 0, 10), 1), (0, 0, -1e6), 9e-6, Vector3D(0, 0, 1)),
    # dropped from rest at 5.9, r = 1, g = 9.8: 4.9 t^2 = 4.9 -> t = 1
    Golden(
        "plane-sphere gravity", FLOOR, Sphere((0, 0, 5.9), 1), ZERO, 1.0, Vector3D(0, 0, 1), acceleration_b=(0, 0, -9.8)
    ),
    # the plane moves up at 1 towards a sphere at rest 3 above it (r = 1): 2 / 1
    Golden("plane-sphere plane moves", FLOOR, Sphere((1, 1, 3), 1), ZERO, 2.0, Vector3D(0, 0, 1), (0, 0, 1)),
    # face x = 2 meets the rim x = 1: t = 1
    Golden("circle-aabb face", Circle((0, 0), 1), AABB((2, -1), (4, 1)), (-1, 0), 1.0, Vector3D(1, 0)),
    # centre (-1 + 3t, 5 - 4t) against corner (2, 1): 25 (1 - t)^2 = 1 -> t = 0.8; normal (0.6, -0.8)
    Golden("circle-aabb corner", Circle((-1, 5), 1), AABB((2, -1), (4, 1)), ZERO, 0.8, Vector3D(0.6, -0.8), (3, -4)),
    # gap 5 - 1 - 1 = 3 at speed 2
    Golden("sphere-aabb face", Sphere((0, 0, 5), 1), BOX, (0, 0, 2), 1.5, Vector3D(0, 0, -1)),
    # centre (4 - t, 4 - t, 0) against the edge x = y = 1: sqrt2 (3 - t) = 1 -> t = 3 - 1/sqrt2
    Golden("sphere-aabb edge", Sphere((4, 4, 0), 1), BOX, ZERO, 3 - 1 / R2, Vector3D(-1, -1, 0) / R2, (-1, -1, 0)),
    # centre (4 - t)(1, 1, 1) against the corner (1, 1, 1): sqrt3 (3 - t) = 1 -> t = 3 - 1/sqrt3
    Golden("sphere-aabb corner", Sphere((4, 4, 4), 1), BOX, ZERO, 3 - 1 / R3, Vector3D(-1, -1, -1) / R3, (-1, -1, -1)),
    # under gravity onto the top face: centre 5 - 4.9 t^2 reaches 1 + 1 = 2 at t = sqrt(3 / 4.9)
    Golden(
        "sphere-aabb gravity",
        Sphere((0.5, 0, 5), 1),
        BOX,
        ZERO,
        math.sqrt(3 / 4.9),
        Vector3D(0, 0, -1),
        acceleration_a=(0, 0, -9.8),
    ),
    # a flat (2D) box seen by a sphere from above: (3 - 1) at speed 1
    Golden(
        "sphere-aabb flat box", Sphere((0, 0, 3), 1), AABB((-1, -1), (1, 1)), ZERO, 2.0, Vector3D(0, 0, -1), (0, 0, -1)
    ),
    # line y = 0; box centre y = 5, h = 1: 5 - 2t = 1
    Golden("line-aabb", Line((0, 0), (1, 0)), AABB((0, 4), (2, 6)), (0, -2), 2.0, Vector3D(0, 1)),
    # line y = x; box centre (3, -2), half (1, 1): s0 = -5/sqrt2, h = 2/sqrt2, n.v = 2/sqrt2: t = (5 - 2)/2
    Golden("line-aabb below", Line((0, 0), (1, 1)), AABB((2, -3), (4, -1)), (-1, 1), 1.5, Vector3D(1, -1) / R2),
    # n = (1, 1, 0)/sqrt2, centre (5, 5, 1), h = 2/sqrt2, s0 = 10/sqrt2, n.v = -2/sqrt2: t = (10 - 2)/2
    Golden(
        "plane-aabb", Plane((0, 0, 0), (1, 1, 0)), AABB((4, 4, 0), (6, 6, 2)), (-1, -1, 0), 4.0, Vector3D(1, 1, 0) / R2
    ),
    # box centre z = 5, h = 1, dropped under g = 9.8: 5 - 4.9 t^2 = 1 -> t = sqrt(4 / 4.9)
    Golden(
        "plane-aabb gravity",
        FLOOR,
        AABB((-1, -1, 4), (1, 1, 6)),
        ZERO,
        math.sqrt(4 / 4.9),
        Vector3D(0, 0, 1),
        acceleration_b=(0, 0, -9.8),
    ),
    # a flat box (h = 0 along z) coming down to z = 0 from z = 3 at speed 1: t = 3, from above
    Golden("plane-aabb flat box", FLOOR, AABB((0, 0, 3), (1, 1, 3)), (0, 0, -1), 3.0, Vector3D(0, 0, 1)),
]


@pytest.mark.parametrize("case", GOLDEN, ids=[c.id for c in GOLDEN])
@pytest.mark.parametrize("mirrored", [False, True], ids=["a-b", "b-a"])
def test_golden_values(case: Golden, mirrored: bool) -> None:
    a, b, va, vb, ga, gb = case.a, case.b, case.velocity_a, case.velocity_b, case.acceleration_a, case.acceleration_b
    max_time, expected_time, expected_normal = case.max_time, case.time, case.normal
    if mirrored:
        impact = time_of_impact(b, a, vb, va, max_time, gb, ga)
        expected_normal = -expected_normal
    else:
        impact = time_of_impact(a, b, va, vb, max_time, ga, gb)
    assert impact is not None
    assert impact.time == pytest.approx(expected_time, rel=1e-12, abs=0)
    assert close(impact.normal, expected_normal), impact.normal
    assert impact.initially_overlapping is False
    # Moved to the impact time the shapes touch: the narrowphase distance is 0 up to rounding.
    sa = moved(a, offset_at(Vector3D(*va), Vector3D(*ga), impact.time))
    sb = moved(b, offset_at(Vector3D(*vb), Vector3D(*gb), impact.time))
    assert abs(distance(sa, sb)) <= 1e-12 * (1 + max(abs(x) for x in (*va, *vb)))


PER_PAIR: list[tuple[Callable[..., Impact | None], Shape, Shape, tuple[float, ...], float]] = [
    (time_of_impact_circle_circle, Circle((0, 0), 1), Circle((5, 0), 1), (-2, 0), 1.5),
    (time_of_impact_sphere_sphere, Sphere((0, 0, 0), 1), Sphere((0, 3, 4), 1.5), (0, -3, -4), 0.5),
    (time_of_impact_aabb_aabb, AABB((0, 0), (1, 1)), AABB((3, 0.5), (4, 1.5)), (-1, 0), 2.0),
    (time_of_impact_line_circle, Line((0, 0), (1, 0)), Circle((0, 5), 1), (3, -2), 2.0),
    (time_of_impact_plane_sphere, Plane((0, 0, 0), (0, 0, 1)), Sphere((0, 0, 10), 1), (0, 0, -1e6), 9e-6),
    (time_of_impact_circle_aabb, Circle((0, 0), 1), AABB((2, -1), (4, 1)), (-1, 0), 1.0),
    (time_of_impact_sphere_aabb, Sphere((0, 0, 5), 1), AABB((-1, -1, -1), (1, 1, 1)), (0, 0, 2), 1.5),
    (time_of_impact_line_aabb, Line((0, 0), (1, 0)), AABB((0, 4), (2, 6)), (0, -2), 2.0),
    (time_of_impact_plane_aabb, Plane((0, 0, 0), (0, 0, 1)), AABB((0, 0, 3), (1, 1, 5)), (0, 0, -1), 3.0),
]


@pytest.mark.parametrize("case", PER_PAIR, ids=[c[0].__name__ for c in PER_PAIR])
def test_per_pair_functions_take_the_relative_motion(case: tuple[Any, ...]) -> None:
    query, a, b, relative_velocity, expected = case
    impact = query(a, b, relative_velocity, ZERO, 10.0)
    assert impact is not None and impact.time == pytest.approx(expected, rel=1e-12)
    # The public function with the same relative motion split between the two shapes agrees.
    v = Vector3D(*relative_velocity)
    public = time_of_impact(a, b, -v * 0.25, v * 0.75, 10.0)
    assert public is not None and public.time == pytest.approx(expected, rel=1e-12)


def test_every_narrowphase_pair_has_a_time_of_impact() -> None:
    from collisionlab.narrowphase import supported_pairs

    assert toi_supported_pairs() == supported_pairs()


# --- degenerate cases -----------------------------------------------------------------------------------
APART: list[tuple[Shape, Shape]] = [
    (Circle((0, 0), 1), Circle((5, 0), 1)),
    (Sphere((0, 0, 0), 1), Sphere((5, 0, 0), 1)),
    (AABB((0, 0), (1, 1)), AABB((3, 0), (4, 1))),
    (AABB((0, 0, 0), (1, 1, 1)), AABB((3, 0, 0), (4, 1, 1))),
    (Line((0, 0), (1, 0)), Circle((0, 5), 1)),
    (Plane((0, 0, 0), (0, 0, 1)), Sphere((0, 0, 5), 1)),
    (Circle((0, 0), 1), AABB((3, 0), (4, 1))),
    (Sphere((0, 0, 0), 1), AABB((3, 0, 0), (4, 1, 1))),
    (Line((0, 0), (1, 0)), AABB((0, 3), (1, 4))),
    (Plane((0, 0, 0), (0, 0, 1)), AABB((0, 0, 3), (1, 1, 4))),
]


def _velocity(shape: Shape, x: float, y: float, z: float = 0.0) -> tuple[float, float, float]:
    planar = isinstance(shape, (Circle, Line)) or (isinstance(shape, AABB) and shape.dim == 2)
    return (x, y, 0.0 if planar else z)


@pytest.mark.parametrize("pair", APART, ids=[f"{type(a).__name__}-{type(b).__name__}" for a, b in APART])
def test_zero_relative_motion_apart_is_none(pair: tuple[Shape, Shape]) -> None:
    a, b = pair
    same = _velocity(a, 3.0, -2.0, 1.0)
    assert time_of_impact(a, b, ZERO, ZERO, 100.0) is None
    assert time_of_impact(a, b, same, same, 100.0) is None  # moving together
    assert time_of_impact(b, a, same, same, 100.0, same, same) is None  # accelerating together
    assert time_of_impact(a, b, ZERO, ZERO, 0.0) is None  # max_time = 0


@pytest.mark.parametrize("pair", APART, ids=[f"{type(a).__name__}-{type(b).__name__}" for a, b in APART])
def test_zero_relative_motion_overlapping_reports_time_zero(pair: tuple[Shape, Shape]) -> None:
    a, b = pair
    # Move B onto A: B's reference point to A's.
    b_ref = b.center if isinstance(b, (Circle, Sphere, AABB)) else b.point
    a_ref = a.center if isinstance(a, (Circle, Sphere, AABB)) else a.point
    b_on_a = moved(b, a_ref - b_ref)
    expected = separation(a, b_on_a)
    for max_time in (0.0, 1.0):
        impact = time_of_impact(a, b_on_a, (1, 1, 0), (1, 1, 0), max_time)
        assert impact == Impact(0.0, expected.normal, True)


def test_approaching_while_overlapping_is_time_zero_and_separating_is_ignored() -> None:
    a, b = Sphere((0, 0, 0), 1), Sphere((1.5, 0, 0), 1)  # overlapping by 0.5, normal +x
    assert time_of_impact(a, b, ZERO, (-1, 0, 0), 1) == Impact(0.0, Vector3D(1, 0, 0), True)
    assert time_of_impact(a, b, ZERO, (1, 0, 0), 10) is None
    # Mirrored: the normal is flipped, the decision is the same.
    assert time_of_impact(b, a, (-1, 0, 0), ZERO, 1) == Impact(0.0, Vector3D(-1, 0, 0), True)
    assert time_of_impact(b, a, (1, 0, 0), ZERO, 10) is None


def test_exactly_touching_counts_as_overlapping() -> None:
    floor = Plane((0, 0, 0), (0, 0, 1))
    ball = Sphere((0, 0, 1), 1)
    assert time_of_impact(floor, ball, ZERO, (0, 0, -1), 1) == Impact(0.0, Vector3D(0, 0, 1), True)
    # Sliding along the floor (v.n == 0, no acceleration): not separating, so time 0.
    assert time_of_impact(floor, ball, ZERO, (5, 0, 0), 1) == Impact(0.0, Vector3D(0, 0, 1), True)
    # Resting under gravity (v.n == 0, g.n < 0): time 0.
    assert time_of_impact(floor, ball, ZERO, ZERO, 1, ZERO, (0, 0, -9.8)) == Impact(0.0, Vector3D(0, 0, 1), True)
    # Leaving with v.n == 0 but g.n > 0 (pulled away): separating; never returns.
    assert time_of_impact(floor, ball, ZERO, ZERO, 1, ZERO, (0, 0, 9.8)) is None
    # Leaving upwards: separating, no acceleration, so no further touch.
    assert time_of_impact(floor, ball, ZERO, (0, 0, 1), 10) is None


def test_leaving_a_floor_under_gravity_returns_the_landing() -> None:
    floor = Plane((0, 0, 0), (0, 0, 1))
    # Touching, thrown up at 4.9 under g = 9.8: s(t) = 1 + 4.9 t - 4.9 t^2 = 1 again at t = 1.
    impact = time_of_impact(floor, Sphere((0, 0, 1), 1), ZERO, (0, 0, 4.9), 2, ZERO, (0, 0, -9.8))
    assert impact is not None and impact.time == pytest.approx(1.0, rel=1e-14)
    assert impact.normal == Vector3D(0, 0, 1) and impact.initially_overlapping is False
    # Overlapping by 0.5, thrown up: leaves at s = 1 going up and lands when 4.9 t^2 - 4.9 t + 0.5 = 0,
    # the larger root (4.9 + sqrt(4.9^2 - 9.8)) / 9.8.
    impact = time_of_impact(floor, Sphere((0, 0, 0.5), 1), ZERO, (0, 0, 4.9), 2, ZERO, (0, 0, -9.8))
    assert impact is not None
    assert impact.time == pytest.approx((4.9 + math.sqrt(4.9**2 - 9.8)) / 9.8, rel=1e-14)
    # Not back within max_time: None.
    assert time_of_impact(floor, Sphere((0, 0, 1), 1), ZERO, (0, 0, 4.9), 0.99, ZERO, (0, 0, -9.8)) is None


def test_a_graze_is_not_an_impact_but_a_near_graze_is() -> None:
    # p(t) = (-5 + t, 2): |p| reaches 2 = r_a + r_b only at t = 5, moving along x, so v.n = 0 there:
    # no impulse would act, and the exact stepper (whose search this is) passes it by.
    assert time_of_impact(Circle((0, 0), 1), Circle((-5, 2), 1), ZERO, (1, 0), 10) is None
    # 1e-9 closer: (5 - t)^2 + (2 - d)^2 = 4 at t = 5 - sqrt(4 d - d^2) = 5 - 6.32455e-5.
    d = 1e-9
    impact = time_of_impact(Circle((0, 0), 1), Circle((-5, 2 - d), 1), ZERO, (1, 0), 10)
    assert impact is not None and impact.time == pytest.approx(5 - math.sqrt(4 * d - d * d), rel=1e-12)
    # A ball thrown up at 6 under g = 2 peaks at 9, just touching a ceiling 10 above its centre
    # with r = 1: -10 + 6t - t^2 = -1 -> (t - 3)^2 = 0, with v.n = 0 at t = 3: no impact.
    ceiling = Plane((0, 0, 10), (0, 0, 1))
    assert time_of_impact(ceiling, Sphere((0, 0, 0), 1), ZERO, (0, 0, 6), 10, ZERO, (0, 0, -2)) is None
    # Thrown at 6.1 it reaches the ceiling: 9 - 6.1 t + t^2 = 0, t = (6.1 - sqrt(37.21 - 36)) / 2 = 2.5.
    impact = time_of_impact(ceiling, Sphere((0, 0, 0), 1), ZERO, (0, 0, 6.1), 10, ZERO, (0, 0, -2))
    assert impact is not None and impact.time == pytest.approx(2.5, rel=1e-14)
    # Box sliding in x with its bottom face level with the top face of A: they meet corner to corner
    # at t = 2, approaching along x, which is an impact.
    impact = time_of_impact(AABB((0, 0), (1, 1)), AABB((3, 1), (4, 2)), ZERO, (-1, 0), 10)
    assert impact == Impact(2.0, Vector3D(1, 0), False)
    # A box passing exactly along a plane's level: the touching plane counts at once (time 0, overlapping).
    impact = time_of_impact(Plane((0, 0, 0), (0, 0, 1)), AABB((0, 0, 0), (1, 1, 1)), ZERO, (1, 0, 0), 10)
    assert impact == Impact(0.0, Vector3D(0, 0, 1), True)


def test_a_box_of_no_extent_is_a_point() -> None:
    # A point box at the origin falls at speed 1 onto a plane 5 below: t = 5, from above.
    point = AABB((0, 0, 1), (0, 0, 1))
    impact = time_of_impact(Plane((0, 0, -4), (0, 0, 1)), point, ZERO, (0, 0, -1), 10)
    assert impact == Impact(5.0, Vector3D(0, 0, 1), False)
    # Against a ball of radius 1 centred 3 below: the gap 3 - 1 = 2 closes at 1, t = 2; B is above A.
    impact = time_of_impact(Sphere((0, 0, -2), 1), point, ZERO, (0, 0, -1), 10)
    assert impact == Impact(2.0, Vector3D(0, 0, 1), False)


def test_max_time_bounds_are_inclusive() -> None:
    a, b = Circle((0, 0), 1), Circle((5, 0), 1)
    impact = time_of_impact(a, b, ZERO, (-2, 0), 1.5)
    assert impact is not None and impact.time == 1.5
    assert time_of_impact(a, b, ZERO, (-2, 0), 1.4999999) is None
    assert time_of_impact(a, b, ZERO, (-2, 0), 0.0) is None


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"velocity_a": (math.nan, 0, 0)}, "velocity_a[0]"),
        ({"velocity_b": (0, math.inf, 0)}, "velocity_b[1]"),
        ({"velocity_b": "fast"}, "velocity_b"),
        ({"acceleration_a": (0, 0, math.nan)}, "acceleration_a[2]"),
        ({"acceleration_b": (1, 2, 3, 4)}, "acceleration_b"),
        ({"max_time": -1.0}, "max_time"),
        ({"max_time": math.nan}, "max_time"),
        ({"max_time": math.inf}, "max_time"),
    ],
)
def test_bad_inputs_name_the_field(kwargs: dict[str, Any], field: str) -> None:
    args: dict[str, Any] = {"velocity_a": ZERO, "velocity_b": ZERO, "max_time": 1.0}
    args.update(kwargs)
    with pytest.raises(InvalidInputError) as info:
        time_of_impact(Sphere((0, 0, 0), 1), Sphere((5, 0, 0), 1), **args)
    assert info.value.field == field


def test_planar_pairs_refuse_motion_out_of_the_plane() -> None:
    with pytest.raises(InvalidInputError) as info:
        time_of_impact(Circle((0, 0), 1), Circle((5, 0), 1), ZERO, (0, 0, 1), 1)
    assert info.value.field == "velocity_b"
    with pytest.raises(InvalidInputError) as info:
        time_of_impact(Line((0, 0), (1, 0)), AABB((0, 3), (1, 4)), ZERO, ZERO, 1, (0, 0, -9.8))
    assert info.value.field == "acceleration_a"
    with pytest.raises(InvalidInputError) as info:
        time_of_impact_circle_circle(Circle((0, 0), 1), Circle((5, 0), 1), (0, 0, 1), ZERO, 1)
    assert info.value.field == "relative_velocity"
    with pytest.raises(InvalidInputError) as info:
        time_of_impact_plane_sphere(Plane((0, 0, 0), (0, 0, 1)), Sphere((0, 0, 5), 1), ZERO, ZERO, -1)
    assert info.value.field == "max_time"
    # A sphere against a flat (2D) box is a 3D pair: motion in z is allowed.
    assert time_of_impact(Sphere((0, 0, 3), 1), AABB((-1, -1), (1, 1)), (0, 0, -1), ZERO, 5) is not None


def test_unsupported_pairs_raise() -> None:
    with pytest.raises(UnsupportedPairError, match="no time-of-impact query for Circle and Sphere"):
        time_of_impact(Circle((0, 0), 1), Sphere((0, 0, 0), 1), ZERO, ZERO, 1)
    with pytest.raises(UnsupportedPairError):
        time_of_impact(Line((0, 0), (1, 0)), Plane((0, 0, 0), (0, 0, 1)), ZERO, ZERO, 1)
    with pytest.raises(UnsupportedPairError):
        time_of_impact(AABB((0, 0), (1, 1)), AABB((0, 0, 0), (1, 1, 1)), ZERO, ZERO, 1)
    with pytest.raises(UnsupportedPairError):
        time_of_impact(Circle((0, 0), 1), AABB((0, 0, 0), (1, 1, 1)), ZERO, ZERO, 1)


# --- high speed and gravity -----------------------------------------------------------------------------
FAST_TARGETS: list[tuple[str, Shape]] = [
    ("plane", Plane((0, 0, 0), (0, 0, 1))),
    ("sphere", Sphere((0, 0, -1), 1)),
    ("box", AABB((-1, -1, -2), (1, 1, 0))),
    ("flat box", AABB((-1, -1), (1, 1))),
]


@pytest.mark.parametrize("target", FAST_TARGETS, ids=[t[0] for t in FAST_TARGETS])
@pytest.mark.parametrize("speed", [1.0, 1e3, 1e6, 3.7e6])
@pytest.mark.parametrize("height", [10.0, 1.5, 1e3])
def test_high_speed_never_tunnels(target: tuple[str, Shape], speed: float, height: float) -> None:
    # A sphere of radius 1 whose centre is `height` above the target's top (z = 0) moves at `speed`
    # down through it within one step (long enough to end 1 step beyond): the impact is (height - 1) / speed.
    _, shape = target
    ball = Sphere((0.0, 0.0, height) if isinstance(shape, Sphere) else (0.25, -0.5, height), 1)
    impact = time_of_impact(ball, shape, (0, 0, -speed), ZERO, 2 * height / speed)
    assert impact is not None
    assert impact.time == pytest.approx((height - 1) / speed, rel=1e-13)
    assert close(impact.normal, Vector3D(0, 0, -1), 1e-12) or isinstance(shape, Sphere)
    landed = moved(ball, Vector3D(0, 0, -speed * impact.time))
    assert abs(distance(landed, shape)) <= 1e-12 * height


def test_high_speed_in_2d() -> None:
    for speed in (1.0, 1e6):
        step = 20 / speed
        impact = time_of_impact(Circle((0, 10), 1), Line((0, 0), (1, 0)), (0, -speed), ZERO, step)
        assert impact is not None and impact.time == pytest.approx(9 / speed, rel=1e-14)
        impact = time_of_impact(Circle((0, 10), 1), AABB((-1, -1), (1, 0)), (0, -speed), ZERO, step)
        assert impact is not None and impact.time == pytest.approx(9 / speed, rel=1e-14)
        impact = time_of_impact(Circle((0, 10), 1), Circle((0, -1), 1), (0, -speed), ZERO, step)
        assert impact is not None and impact.time == pytest.approx(9 / speed, rel=1e-13)


@pytest.mark.parametrize("height", [1.0, 1.5, 2.0, 10.0, 123.4])
@pytest.mark.parametrize("g", [1.0, 9.81])
def test_dropped_ball_lands_at_sqrt_2_h_minus_r_over_g(height: float, g: float) -> None:
    # The ball falls under g, the floor is static: the relative acceleration (floor seen from the ball) is +g.
    floor = Plane((0, 0, 0), (0, 0, 1))
    ball = Sphere((3, 4, height), 0.5)
    impact = time_of_impact(ball, floor, ZERO, ZERO, 100, (0, 0, -g), ZERO)
    assert impact is not None
    assert impact.time == pytest.approx(math.sqrt(2 * (height - 0.5) / g), rel=1e-14)
    assert impact.normal == Vector3D(0, 0, -1)
    # The same in 2D, against a line, and against a box's top face.
    circle = Circle((3, height), 0.5)
    impact = time_of_impact(circle, Line((0, 0), (-1, 0)), ZERO, ZERO, 100, (0, -g), ZERO)
    assert impact is not None and impact.time == pytest.approx(math.sqrt(2 * (height - 0.5) / g), rel=1e-14)
    impact = time_of_impact(ball, AABB((0, 0, -1), (5, 5, 0)), ZERO, ZERO, 100, (0, 0, -g), ZERO)
    assert impact is not None and impact.time == pytest.approx(math.sqrt(2 * (height - 0.5) / g), rel=1e-12)
    # Two balls under the same gravity: the relative acceleration is 0 and nothing happens.
    other = Sphere((3, 4, -5), 0.5)
    assert time_of_impact(ball, other, ZERO, ZERO, 100, (0, 0, -g), (0, 0, -g)) is None


# --- brute force ----------------------------------------------------------------------------------------
SUBSTEPS = 100_000


def _brute_distance(a: Shape, b: Shape, offsets: np.ndarray) -> np.ndarray:
    """Signed distance of ``a`` and ``b`` moved by each row of ``offsets`` (vectorised narrowphase)."""
    if isinstance(a, (Circle, Sphere)) and isinstance(b, (Circle, Sphere)):
        p = np.array(b.center.as_tuple()) + offsets - np.array(a.center.as_tuple())
        return np.asarray(np.linalg.norm(p, axis=1) - (a.radius + b.radius))
    if isinstance(a, (Line, Plane)):
        n = np.array(a.unit_normal.as_tuple())
        if isinstance(b, AABB):
            center, half = np.array(b.center.as_tuple()), np.array(b.half_size.as_tuple())
            extent = float(np.abs(n) @ half)
        else:
            assert isinstance(b, (Circle, Sphere))
            center, extent = np.array(b.center.as_tuple()), b.radius
        return np.asarray(np.abs((center + offsets - np.array(a.point.as_tuple())) @ n) - extent)
    if isinstance(a, AABB) and isinstance(b, AABB):
        dims = a.dim
        a_lo, a_hi = np.array(a.min_corner.as_tuple())[:dims], np.array(a.max_corner.as_tuple())[:dims]
        b_lo = np.array(b.min_corner.as_tuple())[:dims] + offsets[:, :dims]
        b_hi = np.array(b.max_corner.as_tuple())[:dims] + offsets[:, :dims]
        gaps = np.maximum(a_lo - b_hi, b_lo - a_hi)
        outside = np.linalg.norm(np.maximum(gaps, 0.0), axis=1)
        return np.asarray(np.where(gaps.max(axis=1) > 0.0, outside, gaps.max(axis=1)))
    assert isinstance(a, (Circle, Sphere)) and isinstance(b, AABB)
    c = np.array(a.center.as_tuple())
    lo = np.array(b.min_corner.as_tuple()) + offsets
    hi = np.array(b.max_corner.as_tuple()) + offsets
    q = np.clip(c, lo, hi)
    gap = np.linalg.norm(q - c, axis=1)
    dims = 2 if isinstance(a, Circle) else 3
    inside = np.minimum(c - lo, hi - c)[:, :dims].min(axis=1)
    return np.asarray(np.where(gap > 0.0, gap - a.radius, -(a.radius + inside)))


def _random_case(kind: str, rng: np.random.Generator, accelerated: bool) -> tuple[Shape, Shape, Vector3D, Vector3D]:
    dims = 2 if kind in ("circle-circle", "aabb-aabb-2d", "line-circle", "circle-aabb", "line-aabb") else 3

    def vec(scale: float) -> np.ndarray:
        v = rng.uniform(-scale, scale, 3)
        if dims == 2:
            v[2] = 0.0
        return v

    def ball(cls: type[Circle] | type[Sphere]) -> Shape:
        return cls(Vector3D(*vec(5.0)), float(rng.uniform(0.2, 2.0)))

    def box() -> AABB:
        centre, half = vec(5.0), np.abs(vec(2.0)) + 0.1
        if dims == 2:
            half[2] = 0.0
        return AABB(tuple(centre - half), tuple(centre + half))

    first, second = kind.split("-")[:2]
    makers: dict[str, Callable[[], Shape]] = {
        "circle": lambda: ball(Circle),
        "sphere": lambda: ball(Sphere),
        "aabb": box,
        "line": lambda: Line(Vector3D(*vec(5.0)), Vector3D(*(vec(1.0) + np.array([0.05, 0, 0])))),
        "plane": lambda: Plane(Vector3D(*vec(5.0)), Vector3D(*(vec(1.0) + np.array([0.05, 0, 0])))),
    }
    while True:
        a, b = makers[first](), makers[second]()
        if distance(a, b) <= 0.0:
            continue
        a_ref = a.point if isinstance(a, (Line, Plane)) else a.center
        b_ref = b.center if isinstance(b, (Circle, Sphere, AABB)) else b.point
        # Head B at A's reference point (arriving around t = 0.5), with noise; sometimes a miss.
        aim = (np.array(a_ref.as_tuple()) - np.array(b_ref.as_tuple())) / rng.uniform(0.3, 1.5)
        velocity = Vector3D(*(aim + vec(3.0)))
        acceleration = Vector3D(*vec(20.0)) if accelerated else Vector3D(0, 0, 0)
        return a, b, velocity, acceleration


KINDS = [
    "circle-circle",
    "sphere-sphere",
    "aabb-aabb-2d",
    "aabb-aabb-3d",
    "line-circle",
    "plane-sphere",
    "circle-aabb",
    "sphere-aabb",
    "line-aabb",
    "plane-aabb",
]


@pytest.mark.parametrize("accelerated", [False, True], ids=["linear", "accelerated"])
@pytest.mark.parametrize("kind", KINDS)
def test_agrees_with_brute_force(kind: str, accelerated: bool) -> None:
    rng = np.random.default_rng(1000 + 2 * KINDS.index(kind) + int(accelerated))
    max_time = 1.0
    times = np.linspace(0.0, max_time, SUBSTEPS + 1)
    step = max_time / SUBSTEPS
    hits = 0
    for _ in range(25):
        a, b, v, g = _random_case(kind, rng, accelerated)
        offsets = np.outer(times, v.as_tuple()) + np.outer(0.5 * times**2, g.as_tuple())
        sampled = _brute_distance(a, b, offsets)
        # The vectorised distance is narrowphase's, at a few samples.
        for k in (0, SUBSTEPS // 3, SUBSTEPS):
            off = offset_at(v, g, float(times[k]))
            assert sampled[k] == pytest.approx(distance(a, moved(b, off)), rel=1e-9, abs=1e-9)
        contact = np.flatnonzero(sampled <= 0.0)
        impact = time_of_impact(a, b, Vector3D(0, 0, 0), v, max_time, Vector3D(0, 0, 0), g)
        mirrored = time_of_impact(b, a, v, Vector3D(0, 0, 0), max_time, g, Vector3D(0, 0, 0))
        if impact is None:
            assert mirrored is None
            assert contact.size == 0, f"brute force touches at t = {times[contact[0]]}"
            continue
        hits += 1
        assert mirrored is not None and mirrored.time == impact.time and mirrored.normal == -impact.normal
        assert not impact.initially_overlapping
        # No sample before the impact is in contact; the first sampled contact is within one sub-step.
        first = contact[0] if contact.size else None
        if first is not None:
            assert times[first] - step <= impact.time <= times[first] + 1e-12
        else:  # a contact shorter than a sub-step (a near graze): the samples straddle it
            assert np.all(sampled > 0.0)
        # Moved to the impact the shapes touch, and the normal is narrowphase's there.
        at = moved(b, offset_at(v, g, impact.time))
        sep = separation(a, at)
        assert abs(sep.distance) <= 1e-9
        if isinstance(a, AABB):  # two boxes: narrowphase's normal just after the touch (least overlap)
            sep = separation(a, moved(b, offset_at(v, g, impact.time + 1e-9)))
        assert close(impact.normal, sep.normal, 1e-6), (impact.normal, sep.normal)
    assert hits >= 5  # the cases are aimed: most of them hit


@pytest.mark.parametrize("accelerated", [False, True], ids=["linear", "accelerated"])
@pytest.mark.parametrize("kind", KINDS)
def test_agrees_with_the_reference_interval_solver(kind: str, accelerated: bool) -> None:
    # tests/toi_reference.py: every touch a root of a polynomial, solved in closed form or by
    # bisection to adjacent doubles (the solver this module used before it called the kernel).
    rng = np.random.default_rng(2000 + 2 * KINDS.index(kind) + int(accelerated))
    hits = 0
    for _ in range(150):
        a, b, v, g = _random_case(kind, rng, accelerated)
        ours = time_of_impact(a, b, ZERO, v, 1.0, ZERO, g)
        theirs = toi_reference.time_of_impact(a, b, ZERO, v, 1.0, ZERO, g)
        assert (ours is None) == (theirs is None), (a, b, v, g, ours, theirs)
        if ours is None or theirs is None:
            continue
        hits += 1
        assert ours.time == pytest.approx(theirs.time, rel=1e-9, abs=1e-12)
        if not isinstance(a, AABB) or not isinstance(b, AABB):  # two boxes meeting edge-on: either axis
            assert close(ours.normal, theirs.normal, 1e-6), (ours.normal, theirs.normal)
    assert hits >= 30


# --- issue 11: numbers too large to solve end in the library's error, never a raw one -------------
HUGE_MOTIONS = [
    # (a, b, velocity_a, velocity_b, max_time, acceleration_a, acceleration_b)
    (Sphere((0, 5, 0), 1), Sphere((0, 0, 0), 1), (0, -1e300, 0), (0, 1e300, 0), 1, (0, 0, 0), (0, 0, 0)),
    (Sphere((0, 5, 0), 1), AABB((0, 0, 0), (1, 1, 1)), (0, 0, 0), (0, 0, 0), 1e300, (0, -1e300, 0), (0, 0, 0)),
    (Circle((0, 5), 1), Circle((0, 0), 1), (1e300, -1e300), (-1e300, 1e300), 1e300, (0, 0), (0, 0)),
    (Sphere((1e300, 5, 0), 1), Sphere((-1e300, 0, 0), 1), (-1e300, 0, 0), (1e300, 0, 0), 1, (0, 0, 0), (0, 0, 0)),
]


@pytest.mark.parametrize("motion", HUGE_MOTIONS, ids=range(len(HUGE_MOTIONS)))
def test_numbers_too_large_to_solve_raise_out_of_range_not_a_raw_error_or_a_silent_miss(motion: tuple) -> None:
    # Each motion covers more than 2^500 times the pair's size within max_time, or (the last) the
    # radii are below 2^-250 of the distance: the answer is the library's OutOfRangeError (never a
    # raw ValueError/OverflowError, never a silent None).
    with pytest.raises(OutOfRangeError, match="too large"):
        time_of_impact(*motion)


def test_a_huge_acceleration_still_gives_the_exact_time() -> None:
    # A plane: the gap 5 - 1 = 4 closes as 1e300 t^2 / 2, t = sqrt(8e-300).
    impact = time_of_impact(Sphere((0, 5, 0), 1), Plane((0, 0, 0), (0, 1, 0)), (0, 0, 0), (0, 0, 0), 1, (0, -1e300, 0))
    assert impact is not None and impact.time == pytest.approx(math.sqrt(8e-300), rel=1e-12)
    # Two balls: the gap 5 - 2 = 3 closes as 1e300 t^2 / 2, t = sqrt(6e-300).
    impact = time_of_impact(Sphere((0, 5, 0), 1), Sphere((0, 0, 0), 1), ZERO, ZERO, 1, (0, -1e300, 0))
    assert impact is not None and impact.time == pytest.approx(math.sqrt(6e-300), rel=1e-12)
    assert impact.normal == Vector3D(0, -1, 0)
