"""Refused input, one table: every public constructor and function, every kind of bad value.

Each row must raise :class:`InvalidInputError` - a ``ValueError`` subclass - whose ``field``
is the expected name and whose message starts with it. Nothing returns NaN.
(Coincident centres are not refused: they have a fallback normal, tabled in test_narrowphase.py.)
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from fractions import Fraction
from typing import Any

import numpy as np
import pytest

from collisionlab import (
    AABB,
    Circle,
    InvalidInputError,
    Line,
    Plane,
    Sphere,
    Vector3D,
    reflect_velocity,
    resolve_collision,
    separate,
)
from collisionlab.model import Body
from collisionlab.validate import finite_number, non_negative, positive, positive_or_inf, whole_number
from collisionlab.vector import as_vector

NAN = math.nan
INF = math.inf
SCALES = (1e-6, 1e-3, 1.0, 1e3, 1e6)

# Collinear or coincident triples (before scaling); every ordering of each is refused.
_COLLINEAR_SETS: dict[str, tuple[tuple[float, ...], ...]] = {
    "diagonal": ((0, 0, 0), (1, 1, 1), (2, 2, 2)),
    "generic": ((1, 2, 3), (1.5, 1, 5), (2.5, -1, 9)),  # a, a + d, a + 3d with d = (0.5, -1, 2)
    "far-from-origin": ((1e3 + 1, 1e3 + 2, 1e3 + 3), (1e3 + 2, 1e3 + 4, 1e3 + 6), (1e3 + 4, 1e3 + 8, 1e3 + 12)),
    "on-the-x-axis": ((0, 0, 0), (1, 0, 0), (5, 0, 0)),
    "two-coincident": ((1, 2, 3), (1, 2, 3), (4, 5, 6)),
    "all-coincident": ((1, 2, 3), (1, 2, 3), (1, 2, 3)),
}


def _plane_point_rows() -> list[Any]:
    rows = []
    for name, points in _COLLINEAR_SETS.items():
        for scale in SCALES:
            scaled = [tuple(c * scale for c in p) for p in points]
            for k, order in enumerate(itertools.permutations(scaled)):
                rows.append(
                    pytest.param(
                        lambda o=order: Plane.from_points(*o), "points", id=f"from_points-{name}-{scale:g}-{k}"
                    )
                )
    return rows


def _row(id_: str, call: Callable[[], object], field: str) -> Any:
    return pytest.param(call, field, id=id_)


INVALID = [
    # --- NaN or inf anywhere ------------------------------------------------------------------
    _row("vector-x-nan", lambda: Vector3D(NAN, 0), "x"),
    _row("vector-y-inf", lambda: Vector3D(0, INF), "y"),
    _row("vector-z-neginf", lambda: Vector3D(0, 0, -INF), "z"),
    _row("vector-overflow", lambda: Vector3D(1e308, 0) * 10, "x"),
    _row("as_vector-nan", lambda: as_vector((0, NAN), "velocity"), "velocity[1]"),
    _row("as_vector-numpy-nan", lambda: as_vector(np.array([np.nan, 0.0]), "velocity"), "velocity[0]"),
    _row("circle-center-nan", lambda: Circle((NAN, 0), 1), "center[0]"),
    _row("circle-center-inf", lambda: Circle((0, INF), 1), "center[1]"),
    _row("circle-radius-nan", lambda: Circle((0, 0), NAN), "radius"),
    _row("circle-radius-inf", lambda: Circle((0, 0), INF), "radius"),
    _row("sphere-center-nan", lambda: Sphere((0, 0, NAN), 1), "center[2]"),
    _row("sphere-radius-inf", lambda: Sphere((0, 0, 0), INF), "radius"),
    _row("sphere-radius-400-digits", lambda: Sphere((1, 2, 3), 10**400), "radius"),  # was OverflowError
    _row("vector-400-digits", lambda: Vector3D(10**400, 0), "x"),
    _row("aabb-min-nan", lambda: AABB((0, NAN), (1, 1)), "min_corner[1]"),
    _row("aabb-max-inf", lambda: AABB((0, 0, 0), (INF, 1, 1)), "max_corner[0]"),
    _row("aabb-min-neginf", lambda: AABB((-INF, 0, 0), (1, 1, 1)), "min_corner[0]"),
    _row("from_center_size-center-nan", lambda: AABB.from_center_size((NAN, 0), (1, 1)), "center[0]"),
    _row("from_center_size-size-inf", lambda: AABB.from_center_size((0, 0), (1, INF)), "size[1]"),
    _row("line-point-nan", lambda: Line((NAN, 0), (1, 0)), "point[0]"),
    _row("line-direction-inf", lambda: Line((0, 0), (1, INF)), "direction[1]"),
    _row("plane-point-inf", lambda: Plane((INF, 0, 0), (0, 0, 1)), "point[0]"),
    _row("plane-normal-nan", lambda: Plane((0, 0, 0), (0, 0, NAN)), "normal[2]"),
    _row("from_points-a-nan", lambda: Plane.from_points((NAN, 0, 0), (1, 0, 0), (0, 1, 0)), "points[0][0]"),
    _row("from_points-b-inf", lambda: Plane.from_points((0, 0, 0), (1, INF, 0), (0, 1, 0)), "points[1][1]"),
    _row("from_points-c-nan", lambda: Plane.from_points((0, 0, 0), (1, 0, 0), (0, 1, NAN)), "points[2][2]"),
    _row("closest_line-point-nan", lambda: Vector3D.closest_point_on_line((0, 0), (1, 0), (NAN, 0)), "point[0]"),
    _row("closest_line-p-inf", lambda: Vector3D.closest_point_on_line((0, INF), (1, 0), (0, 0)), "point_on_line[1]"),
    _row(
        "closest_plane-normal-nan",
        lambda: Vector3D.closest_point_on_plane((0, 0, 0), (0, NAN, 1), (1, 1, 1)),
        "normal[1]",
    ),
    _row("projection-onto-nan", lambda: Vector3D(1, 2).parallel_projection((NAN, 1)), "onto[0]"),
    _row("reflect-velocity-nan", lambda: reflect_velocity((NAN, 0), (0, 1), 1.0), "velocity[0]"),
    _row("reflect-normal-inf", lambda: reflect_velocity((1, 0), (0, INF), 1.0), "normal[1]"),
    _row("reflect-restitution-nan", lambda: reflect_velocity((1, 0), (0, 1), NAN), "restitution"),
    _row("reflect-restitution-inf", lambda: reflect_velocity((1, 0), (0, 1), INF), "restitution"),
    _row("resolve-v_a-nan", lambda: resolve_collision((NAN, 0), (0, 0), 1, 1, (1, 0), 1), "v_a[0]"),
    _row("resolve-v_b-inf", lambda: resolve_collision((0, 0), (0, INF), 1, 1, (1, 0), 1), "v_b[1]"),
    _row("resolve-m_a-nan", lambda: resolve_collision((1, 0), (0, 0), NAN, 1, (1, 0), 1), "m_a"),
    _row("resolve-m_b-neginf", lambda: resolve_collision((1, 0), (0, 0), 1, -INF, (1, 0), 1), "m_b"),
    _row("resolve-normal-nan", lambda: resolve_collision((1, 0), (0, 0), 1, 1, (NAN, 0), 1), "normal[0]"),
    _row("resolve-restitution-nan", lambda: resolve_collision((1, 0), (0, 0), 1, 1, (1, 0), NAN), "restitution"),
    _row("separate-p_a-nan", lambda: separate((NAN, 0), (1, 0), 1, 1, (1, 0), 0.1), "p_a[0]"),
    _row("separate-p_b-inf", lambda: separate((0, 0), (INF, 0), 1, 1, (1, 0), 0.1), "p_b[0]"),
    _row("separate-depth-nan", lambda: separate((0, 0), (1, 0), 1, 1, (1, 0), NAN), "depth"),
    _row("separate-depth-inf", lambda: separate((0, 0), (1, 0), 1, 1, (1, 0), INF), "depth"),
    _row("separate-m_a-nan", lambda: separate((0, 0), (1, 0), NAN, 1, (1, 0), 0.1), "m_a"),
    # --- zero-length direction or normal --------------------------------------------------------
    _row("line-direction-zero-2", lambda: Line((0, 0), (0, 0)), "direction"),
    _row("line-direction-zero-3", lambda: Line((0, 0), [0.0, 0.0, 0.0]), "direction"),
    _row("line-direction-zero-vector", lambda: Line((0, 0), Vector3D(-0.0, 0)), "direction"),
    _row("plane-normal-zero", lambda: Plane((0, 0, 0), (0, 0, 0)), "normal"),
    _row("plane-normal-zero-2", lambda: Plane((1, 2, 3), (0, 0)), "normal"),
    _row("closest_line-direction-zero", lambda: Vector3D.closest_point_on_line((0, 0), (0, 0), (1, 1)), "direction"),
    _row(
        "closest_plane-normal-zero", lambda: Vector3D.closest_point_on_plane((0, 0, 0), (0, 0, 0), (1, 1, 1)), "normal"
    ),
    _row("projection-onto-zero", lambda: Vector3D(1, 2).parallel_projection((0, 0)), "onto"),
    _row("perpendicular-onto-zero", lambda: Vector3D(1, 2).perpendicular_projection(Vector3D(0, 0)), "onto"),
    _row("normalized-zero", lambda: Vector3D(0, 0, 0).normalized(), "vector"),
    _row("reflect-normal-zero", lambda: reflect_velocity((1, -1), (0, 0), 1.0), "normal"),
    _row("resolve-normal-zero", lambda: resolve_collision((1, 0), (0, 0), 1, 1, (0, 0, 0), 1), "normal"),
    _row("separate-normal-zero", lambda: separate((0, 0), (1, 0), 1, 1, (0, 0), 0.1), "normal"),
    # --- negative or zero radius, size, mass; negative restitution and depth --------------------
    _row("circle-radius-zero", lambda: Circle((0, 0), 0), "radius"),
    _row("circle-radius-negzero", lambda: Circle((0, 0), -0.0), "radius"),
    _row("circle-radius-negative", lambda: Circle((0, 0), -1), "radius"),
    _row("sphere-radius-zero", lambda: Sphere((0, 0, 0), 0.0), "radius"),
    _row("sphere-radius-negative", lambda: Sphere((0, 0, 0), -1e-300), "radius"),
    _row("from_center_size-size-zero", lambda: AABB.from_center_size((0, 0), (0, 1)), "size.x"),
    _row("from_center_size-size-negative", lambda: AABB.from_center_size((0, 0, 0), (1, -1, 1)), "size.y"),
    _row("from_center_size-size-z-zero-3d", lambda: AABB.from_center_size((0, 0, 5), (1, 1, 0)), "size.z"),
    _row("resolve-m_a-zero", lambda: resolve_collision((1, 0), (0, 0), 0, 1, (1, 0), 1), "m_a"),
    _row("resolve-m_b-negative", lambda: resolve_collision((1, 0), (0, 0), 1, -2, (1, 0), 1), "m_b"),
    _row("resolve-both-static", lambda: resolve_collision((1, 0), (0, 0), INF, INF, (1, 0), 1), "m_a, m_b"),
    _row("resolve-restitution-negative", lambda: resolve_collision((1, 0), (0, 0), 1, 1, (1, 0), -0.5), "restitution"),
    _row("reflect-restitution-negative", lambda: reflect_velocity((1, -1), (0, 1), -1e-9), "restitution"),
    _row("separate-depth-negative", lambda: separate((0, 0), (1, 0), 1, 1, (1, 0), -0.1), "depth"),
    _row("separate-both-static", lambda: separate((0, 0), (1, 0), INF, INF, (1, 0), 0.1), "m_a, m_b"),
    _row("separate-m_b-zero", lambda: separate((0, 0), (1, 0), 1, 0, (1, 0), 0.1), "m_b"),
    # --- min > max corners ------------------------------------------------------------------------
    _row("aabb-2d-x-reversed", lambda: AABB((1, 0), (0, 1)), "max_corner"),
    _row("aabb-2d-y-reversed", lambda: AABB((0, 2), (1, 1)), "max_corner"),
    _row("aabb-3d-z-reversed", lambda: AABB((0, 0, 1), (1, 1, 0)), "max_corner"),
    _row("aabb-3d-ulp-reversed", lambda: AABB((0, 0, 0), (1, 1, math.nextafter(0.0, -1.0))), "max_corner"),
    # --- wrong shape or type of input ---------------------------------------------------------------
    _row("vector-string", lambda: Vector3D("1", 0), "x"),  # type: ignore[arg-type]
    _row("vector-bool", lambda: Vector3D(True, 0), "x"),
    _row("as_vector-4", lambda: as_vector((1, 2, 3, 4), "velocity"), "velocity"),
    _row("as_vector-1", lambda: as_vector((1,), "velocity"), "velocity"),
    _row("as_vector-scalar", lambda: as_vector(3.0, "velocity"), "velocity"),
    _row("as_vector-string", lambda: as_vector("12", "velocity"), "velocity"),
    _row("circle-center-3d", lambda: Circle((0, 0, 1), 1), "center"),
    _row("line-point-3d", lambda: Line((0, 0, 1), (1, 0)), "point"),
    _row("line-direction-3d", lambda: Line((0, 0), (1, 0, 1)), "direction"),
    _row("from_center_size-2d-size-3d-center", lambda: AABB.from_center_size((0, 0, 1), (1, 1)), "center"),
    _row("dot-bad-sequence", lambda: Vector3D(1, 2).dot((1, 2, 3, 4)), "other"),
    # --- collinear or coincident plane points: every ordering, scales 1e-6 to 1e6 ----------------
    *_plane_point_rows(),
]


@pytest.mark.parametrize(("call", "field"), INVALID)
def test_invalid_input_is_refused_naming_the_field(call: Callable[[], object], field: str) -> None:
    with pytest.raises(InvalidInputError) as info:
        call()
    error = info.value
    assert isinstance(error, ValueError)
    assert error.field == field
    assert str(error).startswith(f"{field}: ")


def test_invalid_input_table_covers_every_scale_and_ordering() -> None:
    plane_rows = [row for row in INVALID if row.id.startswith("from_points-") and row.values[1] == "points"]
    # 6 point sets x 5 scales x 6 orderings (the 6 orderings of three equal points included)
    assert len(plane_rows) == len(_COLLINEAR_SETS) * len(SCALES) * 6


# --- the checks themselves ---------------------------------------------------------------------
@pytest.mark.parametrize(
    ("value", "expected"),
    [(2, 2.0), (-0.5, -0.5), (Fraction(1, 4), 0.25), (np.float64(1.5), 1.5), (np.int64(3), 3.0)],
)
def test_finite_number_accepts_reals(value: object, expected: float) -> None:
    got = finite_number(value, "f")
    assert got == expected and type(got) is float


@pytest.mark.parametrize("value", [NAN, INF, -INF, "1", None, True, 1j, [1.0]])
def test_finite_number_refuses(value: object) -> None:
    with pytest.raises(InvalidInputError, match=r"^dt: ") as info:
        finite_number(value, "dt")
    assert info.value.field == "dt"


def test_positive_non_negative_and_positive_or_inf() -> None:
    assert positive(1e-300, "r") == 1e-300
    assert non_negative(0, "e") == 0.0
    assert positive_or_inf(INF, "m") == INF
    assert positive_or_inf(2, "m") == 2.0
    for check, bad in ((positive, 0.0), (non_negative, -1e-300), (positive_or_inf, -INF), (positive_or_inf, 0)):
        with pytest.raises(InvalidInputError):
            check(bad, "field")


@pytest.mark.parametrize(("value", "expected"), [(1, 1), (3.0, 3), (np.int64(7), 7)])
def test_whole_number_accepts(value: object, expected: int) -> None:
    assert whole_number(value, "steps") == expected


@pytest.mark.parametrize("value", [0, -1, 2.5, NAN, INF, True, "3"])
def test_whole_number_refuses(value: object) -> None:
    with pytest.raises(InvalidInputError, match=r"^steps: "):
        whole_number(value, "steps")


def test_error_renamed_keeps_problem() -> None:
    error = InvalidInputError("radius", "must be > 0", got=-1.0)
    renamed = error.renamed("bodies[0].radius")
    assert renamed.field == "bodies[0].radius"
    assert str(renamed) == "bodies[0].radius: must be > 0 (got -1.0)"


# --- component counts: a 3D shape needs (x, y, z); a 2D shape takes (x, y) or (x, y, 0) -------------
@pytest.mark.parametrize(
    ("call", "field", "words"),
    [
        (lambda: Sphere((1, 2), 1), "center", "a sphere needs three numbers (x, y, z), not 2"),
        (lambda: Sphere(np.array([1.0, 2.0]), 1), "center", "a sphere needs three numbers"),
        (lambda: Sphere((1, 2, 3, 4), 1), "center", "a sphere needs three numbers (x, y, z), not 4"),
        (lambda: Plane((0, 0), (0, 1)), "point", "a plane needs three numbers"),
        (lambda: Plane((0, 0, 0), (0, 1)), "normal", "a plane needs three numbers"),
        (lambda: Plane.from_points((0, 0, 0), (1, 0), (0, 1, 0)), "points[1]", "a plane needs three numbers"),
        (lambda: AABB((0, 0), (1, 1, 1)), "min_corner", "a 3D box needs three numbers"),
        (lambda: AABB((0, 0, -1), (1, 1)), "max_corner", "a 3D box needs three numbers"),
        (lambda: AABB.from_center_size((0, 0), (1, 1, 1)), "center", "a 3D box needs three numbers"),
        (lambda: Body("b", Sphere((0, 0, 0), 1), velocity=(0, -1)), "velocity", "a sphere needs three numbers"),
        (lambda: Body("b", AABB((0, 0, 0), (1, 1, 1)), velocity=[1, 0]), "velocity", "a 3D box needs three"),
        (lambda: Circle((1, 2, 3), 1), "center", "x-y plane"),  # a 2D shape's third number must be 0
    ],
)
def test_a_raw_vector_with_the_wrong_count_is_refused_naming_the_field(
    call: Callable[[], object], field: str, words: str
) -> None:
    with pytest.raises(InvalidInputError) as info:
        call()
    assert info.value.field == field and words in str(info.value)
    assert str(info.value).startswith(f"{field}: ") and "\n" not in str(info.value)


def test_a_vector3d_is_taken_as_it_is_and_2d_shapes_take_a_zero_z() -> None:
    assert Sphere(Vector3D(1, 2), 1).center == Vector3D(1, 2, 0)
    assert Body("b", Sphere((0, 0, 0), 1), velocity=Vector3D(0, -1)).velocity == Vector3D(0, -1, 0)
    assert Plane(Vector3D(0, 0), Vector3D(0, 1)).unit_normal == Vector3D(0, 1, 0)
    assert Circle((1, 2, 0), 1).center == Circle((1, 2), 1).center == Vector3D(1, 2, 0)
    assert Line((0, 0, 0), (1, 0, 0)) == Line((0, 0), (1, 0))
    assert AABB((0, 0), (1, 1, 0)).dim == 2 and AABB.from_center_size((0, 0, 0), (2, 2)).dim == 2
    assert Body("c", Circle((0, 0), 1), velocity=(1, 0, 0)).velocity == Body("c", Circle((0, 0), 1), (1, 0)).velocity
    assert Body("d", AABB((0, 0), (1, 1)), velocity=(1, 0)).velocity == Vector3D(1, 0, 0)
