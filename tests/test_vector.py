"""Vector3D and as_vector: golden values (lab part I), properties, and input checks."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from collisionlab import InvalidInputError, Line, Plane, Vector3D
from collisionlab.errors import OutOfRangeError
from collisionlab.vector import as_vector
from tests.strategies import directions, vectors

TOL = 1e-9


def close(u: Vector3D, v: Vector3D, tol: float = TOL) -> bool:
    return (u - v).length() <= tol * (1.0 + u.length() + v.length())


# --- golden values ---------------------------------------------------------------------------
def test_construction_defaults_z_to_zero_and_converts_to_float() -> None:
    v = Vector3D(1, 2)
    assert (v.x, v.y, v.z) == (1.0, 2.0, 0.0)
    assert all(type(c) is float for c in v)


def test_iterable_and_len() -> None:
    v = Vector3D(1, 2, 3)
    assert list(v) == [1.0, 2.0, 3.0]
    assert tuple(v) == v.as_tuple() == (1.0, 2.0, 3.0)
    assert len(v) == 3
    x, y, z = v
    assert (x, y, z) == (1.0, 2.0, 3.0)


def test_immutable() -> None:
    v = Vector3D(1, 2, 3)
    with pytest.raises(dataclasses.FrozenInstanceError):
        v.x = 5.0  # type: ignore[misc]
    assert v == Vector3D(1, 2, 3)


def test_equality_and_hash() -> None:
    assert Vector3D(1, 2) == Vector3D(1.0, 2.0, 0.0)
    assert Vector3D(1, 2) != Vector3D(1, 2, 1e-300)
    assert hash(Vector3D(1, 2)) == hash(Vector3D(1.0, 2.0, 0.0))
    assert len({Vector3D(1, 2), Vector3D(1, 2, 0)}) == 1


def test_arithmetic_golden() -> None:
    a, b = Vector3D(1, 2, 3), Vector3D(4, 5, 6)
    assert a + b == Vector3D(5, 7, 9)  # 1+4, 2+5, 3+6
    assert b - a == Vector3D(3, 3, 3)  # 4-1, 5-2, 6-3
    assert a * 2 == 2 * a == Vector3D(2, 4, 6)
    assert a / 2 == Vector3D(0.5, 1, 1.5)
    assert -a == Vector3D(-1, -2, -3)
    assert a.dot(b) == 32.0  # 4 + 10 + 18
    # (2*6 - 3*5, 3*4 - 1*6, 1*5 - 2*4) = (-3, 6, -3)
    assert a.cross(b) == Vector3D(-3, 6, -3)
    assert Vector3D(3, 4).length() == 5.0  # 3-4-5 triangle
    assert Vector3D(1, 2, 2).length_squared() == 9.0  # 1 + 4 + 4
    assert Vector3D(0, 3, 4).normalized() == Vector3D(0, 0.6, 0.8)  # (0, 3, 4) / 5


def test_sequences_are_accepted_where_a_vector_is_expected() -> None:
    v = Vector3D(1, 2)
    assert v + (1, 1) == Vector3D(2, 3)  # noqa: RUF005 - vector addition, not concatenation
    assert (1, 1) + v == Vector3D(2, 3)  # noqa: RUF005
    assert v - [1, 1, 1] == Vector3D(0, 1, -1)
    assert (3, 3) - v == Vector3D(2, 1)
    assert v.dot((3, 4)) == 11.0  # 1*3 + 2*4
    assert v.cross((0, 1)) == Vector3D(0, 0, 1)  # (1,2,0) x (0,1,0) = (0, 0, 1*1 - 2*0)
    assert v.parallel_projection((5, 0)) == Vector3D(1, 0)
    assert v.dot(np.array([3.0, 4.0])) == 11.0


def test_operators_refuse_non_vectors_with_type_error() -> None:
    v = Vector3D(1, 2)
    with pytest.raises(TypeError):
        v + 1  # type: ignore[operator]
    with pytest.raises(TypeError):
        "ab" - v  # type: ignore[operator]
    with pytest.raises(InvalidInputError, match="other"):
        v + (1, 2, 3, 4)  # noqa: RUF005


def test_division_by_zero_names_divisor() -> None:
    with pytest.raises(InvalidInputError) as info:
        Vector3D(1, 2) / 0
    assert info.value.field == "divisor"


def test_projections_golden() -> None:
    # Proj_(1,0) (3,4) = ((3*1 + 4*0) / 1) (1, 0) = (3, 0); the rest is (0, 4)
    assert Vector3D(3, 4).parallel_projection((1, 0)) == Vector3D(3, 0)
    assert Vector3D(3, 4).perpendicular_projection((1, 0)) == Vector3D(0, 4)
    # onto (2, 2): ((1*2 + 3*2) / 8) (2, 2) = (2, 2); perpendicular (1, 3) - (2, 2) = (-1, 1)
    assert Vector3D(1, 3).parallel_projection(Vector3D(2, 2)) == Vector3D(2, 2)
    assert Vector3D(1, 3).perpendicular_projection(Vector3D(2, 2)) == Vector3D(-1, 1)


def test_closest_point_on_line_lab_eq_6() -> None:
    # S = P + Proj_d(PQ): P = (1, 0), d = (1, 1), Q = (3, 0): PQ = (2, 0),
    # Proj = ((2*1 + 0*1) / 2) (1, 1) = (1, 1), so S = (2, 1)
    assert Vector3D.closest_point_on_line((1, 0), (1, 1), (3, 0)) == Vector3D(2, 1)
    # horizontal line y = 2: the foot of (5, -7) is (5, 2), whatever the direction's length
    assert Vector3D.closest_point_on_line((0, 2), (-10, 0), (5, -7)) == Vector3D(5, 2)


def test_closest_point_on_plane_lab_eq_8() -> None:
    # S = Q - Proj_n(PQ): P = (0, 0, 1), n = (0, 0, 3), Q = (4, 5, 6): PQ = (4, 5, 5),
    # Proj = ((5*3) / 9) (0, 0, 3) = (0, 0, 5), so S = (4, 5, 1)
    assert Vector3D.closest_point_on_plane((0, 0, 1), (0, 0, 3), (4, 5, 6)) == Vector3D(4, 5, 1)
    # plane x + y = 2 through (1, 1, 0), n = (1, 1, 0); Q = (3, 3, 7): PQ = (2, 2, 7),
    # Proj = ((2 + 2) / 2) (1, 1, 0) = (2, 2, 0), S = (1, 1, 7)
    assert Vector3D.closest_point_on_plane((1, 1, 0), (1, 1, 0), (3, 3, 7)) == Vector3D(1, 1, 7)


def test_as_vector_accepts_2_and_3_sequences_and_arrays() -> None:
    assert as_vector((1, 2), "v") == Vector3D(1, 2, 0)
    assert as_vector([1, 2, 3], "v") == Vector3D(1, 2, 3)
    assert as_vector(np.array([1.5, 2.5]), "v") == Vector3D(1.5, 2.5)
    v = Vector3D(1, 2, 3)
    assert as_vector(v, "v") is v


# --- properties ------------------------------------------------------------------------------
@given(vectors(), vectors())
def test_addition_and_subtraction_invert(a: Vector3D, b: Vector3D) -> None:
    assert close((a + b) - b, a)
    assert a + b == b + a
    assert a - b == -(b - a)


@given(vectors(bound=1e2), vectors(bound=1e2))
def test_cross_is_orthogonal_and_anticommutative(a: Vector3D, b: Vector3D) -> None:
    c = a.cross(b)
    scale = (a.length() * b.length()) ** 1.5 + 1.0
    assert abs(c.dot(a)) <= 1e-12 * scale
    assert abs(c.dot(b)) <= 1e-12 * scale
    assert c == -(b.cross(a))


@given(directions())
def test_normalized_has_unit_length(v: Vector3D) -> None:
    assert math.isclose(v.normalized().length(), 1.0, abs_tol=1e-15)


@given(vectors(), directions())
def test_projections_sum_to_vector_and_are_orthogonal(v: Vector3D, onto: Vector3D) -> None:
    parallel = v.parallel_projection(onto)
    perpendicular = v.perpendicular_projection(onto)
    assert close(parallel + perpendicular, v)
    assert abs(perpendicular.dot(onto.normalized())) <= 1e-9 * (1.0 + v.length())
    assert parallel.cross(onto).length() <= 1e-9 * (1.0 + v.length()) * onto.length()


@given(vectors(2), directions(2), vectors(2))
def test_closest_point_on_line_is_on_line_and_foot_of_perpendicular(p: Vector3D, d: Vector3D, q: Vector3D) -> None:
    s = Vector3D.closest_point_on_line(p, d, q)
    u = d.normalized()
    scale = 1.0 + p.length() + q.length()
    assert abs((q - s).dot(u)) <= 1e-9 * scale  # QS is perpendicular to the line
    assert abs((s - p).cross(u).z) <= 1e-9 * scale  # S lies on the line
    assert s.z == 0.0


@given(vectors(), directions(), vectors())
def test_closest_point_on_plane_is_on_plane_and_foot_of_perpendicular(p: Vector3D, n: Vector3D, q: Vector3D) -> None:
    s = Vector3D.closest_point_on_plane(p, n, q)
    u = n.normalized()
    scale = 1.0 + p.length() + q.length()
    assert abs((s - p).dot(u)) <= 1e-9 * scale  # S lies on the plane
    assert (q - s).cross(u).length() <= 1e-9 * scale  # QS is along the normal
    # |QS| = |Proj_n PQ| (lab eq. 9)
    assert math.isclose((q - s).length(), abs((q - p).dot(u)), rel_tol=1e-9, abs_tol=1e-9 * scale)


@given(st.floats(1e-3, 1e3), st.sampled_from([-1.0, 1.0]), vectors(bound=1e3))
def test_scalar_multiplication_scales_length(size: float, sign: float, v: Vector3D) -> None:
    k = sign * size  # |k| >= 1e-3 keeps k * v out of the subnormal range
    assert math.isclose((k * v).length(), abs(k) * v.length(), rel_tol=1e-12, abs_tol=1e-300)
    assert close((v * k) / k, v)


@pytest.mark.parametrize("scale", [1e-200, 1e-150, 1.0, 1e150, 1e200])
def test_projection_works_for_very_short_and_very_long_axes(scale):
    # Proj_d(v) does not depend on |d|: (3, 4) onto the x axis is (3, 0) at any scale, though
    # |d|^2 underflows (1e-200^2) or overflows (1e200^2) in floating point.
    close = {"rel": 1e-15, "abs": 1e-15}
    assert tuple(Vector3D(3, 4).parallel_projection((scale, 0))) == pytest.approx((3, 0, 0), **close)
    assert tuple(Vector3D.closest_point_on_line((0, 0), (scale, 0), (3, 4))) == pytest.approx((3, 0, 0), **close)
    plane_point = Vector3D.closest_point_on_plane((0, 0, 0), (0, 0, scale), (1, 2, 4))
    assert tuple(plane_point) == pytest.approx((1, 2, 0), **close)


def test_vector_times_vector_is_a_type_error():
    with pytest.raises(TypeError):
        Vector3D(1, 2) * Vector3D(3, 4)  # ambiguous: dot or cross


# --- numpy and Python protocols (issue 13) ------------------------------------------------------
def test_asarray_is_a_float64_array_of_three() -> None:
    array = np.asarray(Vector3D(1, 2))
    assert array.dtype == np.float64 and array.shape == (3,)
    assert array.tolist() == [1.0, 2.0, 0.0]
    assert np.asarray(Vector3D(1, 2, 3), dtype=np.float32).dtype == np.float32
    assert np.array([Vector3D(1, 2), Vector3D(3, 4, 5)]).shape == (2, 3)  # a stack of vectors
    assert np.linalg.norm(Vector3D(3, 4)) == 5.0


def test_asarray_never_claims_to_share_memory() -> None:
    # numpy 2's protocol: copy=False must raise when a copy is unavoidable (it always is here).
    with pytest.raises(ValueError, match="always copies"):
        np.asarray(Vector3D(1, 2, 3), copy=False)
    first = np.asarray(Vector3D(1, 2, 3))
    first[0] = 9.0
    assert np.asarray(Vector3D(1, 2, 3))[0] == 1.0


@pytest.mark.parametrize(
    "source",
    [[1, 2, 3], (1, 2, 3), np.array([1, 2, 3]), np.array([1.0, 2.0, 3.0], dtype=np.float32), Vector3D(1, 2, 3)],
    ids=["list", "tuple", "int-array", "float32-array", "vector"],
)
def test_one_argument_builds_from_any_3_sequence_or_array(source: object) -> None:
    v = Vector3D(source)  # type: ignore[arg-type]
    assert v == Vector3D(1.0, 2.0, 3.0) and all(type(c) is float for c in v)


def test_one_argument_builds_from_a_2_sequence_with_z_zero() -> None:
    assert Vector3D([4, 5]) == Vector3D(np.array([4, 5])) == Vector3D(4.0, 5.0, 0.0)


@pytest.mark.parametrize(
    ("bad", "field"),
    [(5, "y"), (np.array(5.0), "y"), ([1, 2, 3, 4], "vector"), (np.zeros((3, 1)), "vector[0]"), ("xyz", "vector"),
     ([1, float("nan")], "vector[1]")],
    ids=["number", "0-d array", "four", "column", "string", "nan"],
)  # fmt: skip
def test_one_bad_argument_is_refused_naming_the_field(bad: object, field: str) -> None:
    with pytest.raises(InvalidInputError) as error:
        Vector3D(bad)  # type: ignore[arg-type]
    assert error.value.field == field


def test_numpy_scalars_are_components() -> None:
    v = Vector3D(np.float32(0.5), np.int64(2), np.float64(3.25))
    assert v.as_tuple() == (0.5, 2.0, 3.25) and all(type(c) is float for c in v)
    with pytest.raises(InvalidInputError, match="x: must be a number"):
        Vector3D(np.bool_(True), 0)


def test_indexing_unpacking_and_abs() -> None:
    v = Vector3D(3, 4, 12)
    x, y, z = v
    assert (x, y, z) == (3.0, 4.0, 12.0)
    assert (v[0], v[1], v[2], v[-1]) == (3.0, 4.0, 12.0, 12.0)
    assert v[:2] == (3.0, 4.0)
    assert abs(v) == 13.0  # 3-4-5 then 5-12-13
    with pytest.raises(IndexError):
        v[3]


def test_numpy_operands_give_vectors() -> None:
    v = Vector3D(1, 2, 3)
    assert np.float64(2) * v == v * np.float32(2) == Vector3D(2, 4, 6)
    assert np.array([1, 1, 1]) + v == v + np.array([1, 1, 1]) == Vector3D(2, 3, 4)
    assert np.array([1, 1]) - v == Vector3D(0, -1, -3)


@pytest.mark.parametrize(
    ("spec", "expected"),
    [(".2f", "(1.00, -2.50, 0.00)"), (".1e", "(1.0e+00, -2.5e+00, 0.0e+00)"), ("+.0f", "(+1, -2, +0)"),
     ("8.3f", "(   1.000,   -2.500,    0.000)")],
)  # fmt: skip
def test_format_specs_apply_to_each_component(spec: str, expected: str) -> None:
    assert format(Vector3D(1, -2.5, 0), spec) == expected


def test_no_signed_zero_is_ever_printed() -> None:
    v = Vector3D(-0.0, 1, -0.0)
    assert math.copysign(1.0, v.x) == 1.0 and math.copysign(1.0, v.z) == 1.0  # stored as +0.0
    assert "-0" not in repr(v) and "-0" not in str(v)
    assert "-" not in f"{Vector3D(-1e-12, -4e-7, 0):.3f}"  # rounds to zero: no minus sign
    assert repr(-Vector3D(0, 0, 0)) == "Vector3D(x=0.0, y=0.0, z=0.0)"
    assert f"{Vector3D(-1e-12, 0):.1e}" == "(-1.0e-12, 0.0e+00, 0.0e+00)"  # a real negative keeps its sign


def test_isclose_is_relative_to_the_longer_vector() -> None:
    assert Vector3D(0.1 + 0.2, 0) != Vector3D(0.3, 0)  # 0.30000000000000004: one ulp apart
    assert Vector3D(0.1 + 0.2, 0).isclose(Vector3D(0.3, 0)) and Vector3D(0.1 + 0.2, 0).isclose((0.3, 0))
    # |a - b| = 1e-6 against |a| = 1: close at rel_tol 1e-5, not at the default 1e-9.
    a, b = Vector3D(1, 0), Vector3D(1, 1e-6)
    assert not a.isclose(b) and a.isclose(b, rel_tol=1e-5)
    # Near zero only abs_tol can make two vectors close.
    assert not Vector3D(0, 0).isclose((1e-12, 0)) and Vector3D(0, 0).isclose((1e-12, 0), abs_tol=1e-9)
    with pytest.raises(InvalidInputError, match="rel_tol: must be >= 0"):
        a.isclose(b, rel_tol=-1)


@given(vectors(), vectors())
def test_isclose_is_symmetric_and_reflexive(u: Vector3D, v: Vector3D) -> None:
    assert u.isclose(u)
    assert u.isclose(v) == v.isclose(u)


# --- issue 11: unit length over the whole float range -------------------------------------------
def test_a_huge_normal_normalises_to_a_unit_vector() -> None:
    # |(0, 1.7e308, 1.7e308)| overflows to inf; scaled first, the unit normal is (0, 1, 1)/sqrt 2.
    n = Plane((0, 0, 0), (0, 1.7e308, 1.7e308)).unit_normal
    assert (n.x, n.y, n.z) == (0.0, pytest.approx(math.sqrt(0.5)), pytest.approx(math.sqrt(0.5)))


def test_a_subnormal_direction_normalises_to_a_unit_vector() -> None:
    # 5e-324 / hypot(5e-324, 5e-324) is 1, not 1/sqrt 2: the length rounds to 5e-324 too.
    d = Line((0, 0), (5e-324, 5e-324)).unit_direction
    assert d.length() == pytest.approx(1.0)
    assert d.x == pytest.approx(math.sqrt(0.5))


_ANY_FINITE = st.floats(allow_nan=False, allow_infinity=False)


@given(st.builds(Vector3D, _ANY_FINITE, _ANY_FINITE, _ANY_FINITE).filter(lambda v: v != Vector3D(0, 0, 0)))
def test_normalized_has_unit_length_over_the_whole_float_range(v: Vector3D) -> None:
    # Any non-zero finite vector, subnormal to 1.8e308: unit length to a few ulp, same direction.
    u = v.normalized()
    assert abs(u.length() - 1.0) <= 4e-16
    for component, unit in zip(v, u, strict=True):
        assert unit == 0.0 or math.copysign(1.0, unit) == math.copysign(1.0, component)
        assert (component == 0.0) == (unit == 0.0) or abs(unit) < 1e-300


def test_a_dot_product_or_length_that_overflows_is_the_librarys_error_not_inf() -> None:
    # (-1, 1e308) . (0, 3) = 3e308 > 1.8e308: it was returned as inf.
    with pytest.raises(OutOfRangeError):
        Vector3D(-1.0, 1e308).dot((0.01, 3.0, 2.5))
    with pytest.raises(OutOfRangeError):
        Vector3D(1.7e308, 1.7e308).length()
    assert Vector3D(1e308, 0).length() == 1e308
