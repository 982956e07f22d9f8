"""Shapes: construction from vectors or sequences, derived properties, golden values.

Refused input (zero directions, collinear points, bad radii, ...) is tabled in test_validate.py.
"""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np
import pytest
from hypothesis import given

from collisionlab import (
    AABB,
    Circle,
    InvalidInputError,
    Line,
    Plane,
    Sphere,
    UnsupportedPairError,
    Vector3D,
    contact,
    distance,
    intersects,
)
from tests.strategies import aabbs, directions, lines, planes, vectors


@pytest.mark.parametrize(
    "center", [(1, 2), [1, 2, 0], Vector3D(1, 2), np.array([1.0, 2.0])], ids=["tuple2", "list3", "vector", "ndarray"]
)
def test_circle_accepts_any_vector_like(center: object) -> None:
    c = Circle(center, 0.5)  # type: ignore[arg-type]
    assert c.center == Vector3D(1, 2, 0)
    assert c.radius == 0.5


def test_shapes_are_frozen_and_compare_by_value() -> None:
    c = Circle((0, 0), 1)
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.radius = 2.0  # type: ignore[misc]
    assert Circle((0, 0), 1) == Circle(Vector3D(0, 0), 1.0)
    assert Sphere((1, 2, 3), 2) == Sphere([1.0, 2.0, 3.0], 2)
    assert Circle((0, 0), 1).moved_to(Vector3D(3, 4)) == Circle((3, 4), 1)
    assert Sphere((0, 0, 0), 1).moved_to(Vector3D(3, 4, 5)) == Sphere((3, 4, 5), 1)


def test_sphere_radius_int_becomes_float() -> None:
    s = Sphere((0, 0, 1), 2)
    assert s.radius == 2.0 and type(s.radius) is float


def test_aabb_2d_and_3d() -> None:
    box2 = AABB((0, 0), (2, 4))
    assert box2.dim == 2
    assert box2.center == Vector3D(1, 2)  # ((0+2)/2, (0+4)/2)
    assert box2.half_size == Vector3D(1, 2)  # ((2-0)/2, (4-0)/2)
    box3 = AABB((-1, -2, -3), (1, 2, 3))
    assert box3.dim == 3
    assert box3.center == Vector3D(0, 0, 0)
    assert box3.half_size == Vector3D(1, 2, 3)


def test_aabb_flat_box_is_allowed() -> None:
    box = AABB((0, 0, 1), (2, 0, 1))  # no extent in y
    assert box.half_size == Vector3D(1, 0, 0)
    assert box.dim == 3


def test_aabb_from_center_size_golden() -> None:
    # centre (1, 1), size (2, 2): corners (1 -+ 1, 1 -+ 1)
    assert AABB.from_center_size((1, 1), (2, 2)) == AABB((0, 0), (2, 2))
    box = AABB.from_center_size((0, 0, 0), (2, 4, 6))  # half size (1, 2, 3)
    assert (box.min_corner, box.max_corner, box.dim) == (Vector3D(-1, -2, -3), Vector3D(1, 2, 3), 3)
    # a 2D size with a 2D centre gives a 2D box
    assert AABB.from_center_size([5, 5], [1, 3]).dim == 2


def test_aabb_moved_to_keeps_size() -> None:
    box = AABB((0, 0, 0), (2, 4, 6)).moved_to(Vector3D(10, 10, 10))
    assert box == AABB((9, 8, 7), (11, 12, 13))  # 10 -+ (1, 2, 3)


def test_line_golden() -> None:
    line = Line((1, 1), (3, 4))
    assert line.direction == Vector3D(3, 4)  # kept as given
    assert line.unit_direction == Vector3D(0.6, 0.8)  # (3, 4) / 5
    assert line.unit_normal == Vector3D(-0.8, 0.6)  # turned +90 degrees: (-dy, dx)


def test_plane_golden() -> None:
    plane = Plane((0, 0, 5), (0, 0, 2))
    assert plane.normal == Vector3D(0, 0, 2)
    assert plane.unit_normal == Vector3D(0, 0, 1)


def test_plane_from_points_right_hand_rule() -> None:
    # (b - a) x (c - a) = (1, 0, 0) x (0, 1, 0) = (0, 0, 1)
    assert Plane.from_points((0, 0, 0), (1, 0, 0), (0, 1, 0)).unit_normal == Vector3D(0, 0, 1)
    # swapping b and c reverses it
    assert Plane.from_points((0, 0, 0), (0, 1, 0), (1, 0, 0)).unit_normal == Vector3D(0, 0, -1)
    # the lab's plane through (1,0,0), (0,1,0), (0,0,1): (-1,1,0) x (-1,0,1) = (1, 1, 1), /sqrt(3)
    plane = Plane.from_points((1, 0, 0), (0, 1, 0), (0, 0, 1))
    k = 1 / math.sqrt(3)
    assert all(math.isclose(got, k, rel_tol=1e-15) for got in plane.unit_normal)
    assert plane.point == Vector3D(1, 0, 0)


@pytest.mark.parametrize("scale", [1e-6, 1e-3, 1.0, 1e3, 1e6])
def test_plane_from_points_works_at_every_scale_and_ordering(scale: float) -> None:
    points = [(0.0, 0.0, 5.0 * scale), (scale, 0.0, 5.0 * scale), (0.0, scale, 5.0 * scale)]
    for order in itertools.permutations(points):
        normal = Plane.from_points(*order).unit_normal
        assert math.isclose(abs(normal.z), 1.0, rel_tol=1e-15)
        assert normal.x == 0.0 and normal.y == 0.0


@given(vectors(), vectors(), vectors())
def test_plane_from_points_contains_its_points(a: Vector3D, b: Vector3D, c: Vector3D) -> None:
    try:
        plane = Plane.from_points(a, b, c)
    except ValueError:
        return  # collinear: tabled in test_validate.py
    n = plane.unit_normal
    assert math.isclose(n.length(), 1.0, abs_tol=1e-15)
    scale = a.length() + b.length() + c.length()
    for p in (a, b, c):
        # a point's height above the plane, relative to the sine test's bound
        assert abs(n.dot(p - plane.point)) <= 1e-6 * scale


@given(lines())
def test_line_unit_vectors(line: Line) -> None:
    assert math.isclose(line.unit_direction.length(), 1.0, abs_tol=1e-15)
    assert math.isclose(line.unit_normal.length(), 1.0, abs_tol=1e-15)
    assert abs(line.unit_direction.dot(line.unit_normal)) <= 1e-15
    assert line.unit_direction.cross(line.unit_normal).z > 0  # normal is +90 degrees


@given(planes())
def test_plane_unit_normal_is_unit_and_parallel(plane: Plane) -> None:
    n = plane.unit_normal
    assert math.isclose(n.length(), 1.0, abs_tol=1e-15)
    assert n.cross(plane.normal).length() <= 1e-12 * plane.normal.length()
    assert n.dot(plane.normal) > 0


@given(aabbs(2), aabbs(3))
def test_aabb_strategy_dims_and_center_round_trip(box2: AABB, box3: AABB) -> None:
    assert box2.dim == 2 and box3.dim == 3
    for box in (box2, box3):
        rebuilt = AABB.from_center_size(box.center, box.half_size * 2)
        assert (rebuilt.min_corner - box.min_corner).length() <= 1e-12 * (1 + box.min_corner.length())
        assert (rebuilt.max_corner - box.max_corner).length() <= 1e-12 * (1 + box.max_corner.length())


@given(directions(2))
def test_line_direction_is_kept(d: Vector3D) -> None:
    assert Line((0, 0), d).direction == d


# --- query methods and numpy inputs (issue 13) -----------------------------------------------------
_SAMPLES = {
    "circle": Circle((0, 0), 1),
    "sphere": Sphere((0, 0.5, 0), 1),
    "box2": AABB((0.5, -1), (2, 1)),
    "box3": AABB((0.5, -1, -1), (2, 1, 1)),
    "line": Line((0, -0.5), (1, 0)),
    "plane": Plane((0, 0, 0), (0, 1, 0)),
}


@pytest.mark.parametrize("a", list(_SAMPLES))
@pytest.mark.parametrize("b", list(_SAMPLES))
def test_every_shapes_methods_are_the_free_functions(a: str, b: str) -> None:
    first, second = _SAMPLES[a], _SAMPLES[b]
    try:
        expected = (intersects(first, second), contact(first, second), distance(first, second))
    except UnsupportedPairError as error:
        for method in (first.intersects, first.contact, first.distance):
            with pytest.raises(UnsupportedPairError) as raised:
                method(second)
            assert str(raised.value) == str(error)  # the same clear message, naming both types
        return
    assert (first.intersects(second), first.contact(second), first.distance(second)) == expected


def test_methods_give_the_lab_golden_values() -> None:
    # Sphere centre 0.5 above the floor, radius 1: |Proj_n PQ| - r = 0.5 - 1 = -0.5 (lab eq. 9).
    ball, floor = Sphere((0, 0.5, 0), 1), Plane((0, 0, 0), (0, 1, 0))
    assert ball.intersects(floor) and ball.distance(floor) == -0.5
    found = ball.contact(floor)
    assert found is not None and found.normal == Vector3D(0, -1, 0) and found.depth == 0.5
    assert Circle((0, 0), 1).contact(Circle((3, 0), 1)) is None  # 3 - 2 = 1 apart


def test_shapes_accept_numpy_scalars_and_arrays() -> None:
    assert Sphere(np.array([1, 2, 3]), np.array(1.0)) == Sphere((1, 2, 3), 1)
    assert Circle(np.array([0.5, 0.0]), np.float32(2)) == Circle((0.5, 0), 2)
    assert AABB.from_center_size(np.zeros(2), np.array([2, 2])) == AABB((-1, -1), (1, 1))
    assert Plane(np.zeros(3), np.array([0, 0, 2])).unit_normal == Vector3D(0, 0, 1)
    with pytest.raises(InvalidInputError, match="radius: must be > 0"):
        Sphere((0, 0, 0), np.array(-1.0))
