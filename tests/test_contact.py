"""Contact and Separation: the flip, and the one touching policy (distance 0 is a contact)."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from collisionlab import Contact, Separation, Vector3D
from tests.strategies import directions, vectors

TINY = math.nextafter(0.0, 1.0)  # 5e-324, one ulp above 0


def test_contact_flipped_golden() -> None:
    c = Contact(Vector3D(0.6, 0.8), 0.25, Vector3D(1, 2))
    assert c.flipped() == Contact(Vector3D(-0.6, -0.8), 0.25, Vector3D(1, 2))


def test_separation_flipped_golden() -> None:
    s = Separation(1.5, Vector3D(0, 0, 1), Vector3D(3, 2, 1))
    assert s.flipped() == Separation(1.5, Vector3D(0, 0, -1), Vector3D(3, 2, 1))


@pytest.mark.parametrize(
    ("distance", "depth"),
    [
        (1.0, None),  # apart
        (TINY, None),  # apart by 1 ulp of 0
        (0.0, 0.0),  # exactly touching: a contact of depth 0
        (-0.0, 0.0),
        (-TINY, TINY),  # overlapping by 1 ulp
        (-0.5, 0.5),  # overlapping: depth = -distance
    ],
)
def test_separation_contact_touching_policy(distance: float, depth: float | None) -> None:
    s = Separation(distance, Vector3D(1, 0), Vector3D(0, 0))
    found = s.contact()
    if depth is None:
        assert found is None
    else:
        assert found == Contact(Vector3D(1, 0), depth, Vector3D(0, 0))
        assert math.copysign(1.0, found.depth) == 1.0  # never -0.0


@given(directions(), st.floats(0, 1e3), vectors())
def test_flipping_twice_is_identity(normal: Vector3D, depth: float, point: Vector3D) -> None:
    c = Contact(normal.normalized(), depth, point)
    assert c.flipped().flipped() == c
    assert c.flipped().normal == -c.normal
    assert (c.flipped().depth, c.flipped().point) == (c.depth, c.point)


@given(st.floats(-1e3, 1e3), directions(), vectors())
def test_contact_of_flipped_separation_is_flipped_contact(distance: float, normal: Vector3D, point: Vector3D) -> None:
    s = Separation(distance, normal.normalized(), point)
    forward, backward = s.contact(), s.flipped().contact()
    assert (forward is None) == (distance > 0.0)
    if forward is None:
        assert backward is None
    else:
        assert backward == forward.flipped()
        assert forward.depth == -distance
