"""Collision resolution: reflect_velocity (lab eq. 24), resolve_collision (lab eqs. 12 and 15
along the normal) and separate - golden values and hypothesis properties."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from collisionlab import Vector3D, reflect_velocity, resolve_collision, separate
from collisionlab.resolution import impulse_magnitude
from tests.strategies import directions, masses, restitutions, vectors

INF = math.inf
R2 = math.sqrt(2.0)


def vec_close(got: Vector3D, expected: tuple[float, ...] | Vector3D, tol: float = 1e-15) -> bool:
    e = Vector3D(*expected)
    return (got - e).length() <= tol * (1.0 + e.length())


def kinetic_energy(m: float, v: Vector3D) -> float:
    return 0.5 * m * v.length_squared()


# --- reflect_velocity --------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("restitution", "expected"),
    [
        (1.0, (3, 4)),  # elastic: v_perp -4 -> +4, v_par 3 kept
        (0.5, (3, 2)),  # lab eq. 16: v_perp -4 -> -0.5 * -4 = 2
        (0.0, (3, 0)),  # perfectly inelastic: the normal part is removed
    ],
)
def test_billiard_rail_lab_figure_1(restitution: float, expected: tuple[float, float]) -> None:
    # a ball moving (3, -4) onto a rail along x: eq. 24 with n = (0, 1): v - (1 + e)(-4)(0, 1)
    assert reflect_velocity((3, -4), (0, 1), restitution) == Vector3D(*expected)


def test_reflect_velocity_golden() -> None:
    # n = (1,1)/sqrt2, v = (1,0): v.n = 1/sqrt2; v - 2 (1/sqrt2) (1,1)/sqrt2 = (1,0) - (1,1) = (0,-1)
    assert vec_close(reflect_velocity((1, 0), (1, 1), 1.0), (0, -1))
    # plane normal (0,0,5) -> (0,0,1); v_n = -3; e = 0.8: z = -3 - 1.8 (-3) = 2.4
    assert vec_close(reflect_velocity((1, 2, -3), (0, 0, 5), 0.8), (1, 2, 2.4))
    # the sign of the normal does not matter (eq. 24 is even in n)
    assert reflect_velocity((3, -4), (0, -1), 1.0) == Vector3D(3, 4)


# --- resolve_collision ---------------------------------------------------------------------------------
def test_resolve_collision_golden_1d() -> None:
    # equal masses, elastic: velocities swap
    assert resolve_collision((1, 0), (-1, 0), 1, 1, (1, 0), 1.0) == (Vector3D(-1, 0), Vector3D(1, 0))
    # m_a = 2, m_b = 1, v_a = 3, v_b = 0, e = 1: v_a' = (2 - 1)/3 * 3 = 1, v_b' = 2*2/3 * 3 = 4;
    # momentum 2*3 = 2*1 + 1*4 = 6, relative velocity 3 -> -3
    va, vb = resolve_collision((3, 0), (0, 0), 2, 1, (1, 0), 1.0)
    assert vec_close(va, (1, 0)) and vec_close(vb, (4, 0))
    # m_a = 1, m_b = 3, e = 0 (lab eq. 13): both (2*1 + 0*3) / 4 = 0.5
    assert resolve_collision((2, 0), (0, 0), 1, 3, (1, 0), 0.0) == (Vector3D(0.5, 0), Vector3D(0.5, 0))
    # equal masses, e = 0.5: v_n = -2, j = -(1.5)(-2) / 2 = 1.5: v_a' = 2 - 1.5, v_b' = 0 + 1.5;
    # relative velocity 1.5 - 0.5 = 1 = 0.5 * 2 (lab eq. 15)
    assert resolve_collision((2, 0), (0, 0), 1, 1, (1, 0), 0.5) == (Vector3D(0.5, 0), Vector3D(1.5, 0))


def test_resolve_collision_golden_oblique() -> None:
    # line of action x, A moves (1, 1) onto B at rest, equal masses, elastic:
    # the x parts swap, A keeps its perpendicular y = 1
    assert resolve_collision((1, 1), (0, 0), 1, 1, (2, 0), 1.0) == (Vector3D(0, 1), Vector3D(1, 0))
    # 3D, normal (0,0,1): z parts of (0,5,2) and (7,0,-2) with m 1, 1, e = 1 swap; x, y kept
    assert resolve_collision((0, 5, 2), (7, 0, -2), 1, 1, (0, 0, 1), 1.0) == (Vector3D(0, 5, -2), Vector3D(7, 0, 2))


def test_resolve_collision_static_bodies() -> None:
    # B static: A reflects as off a wall (lab eq. 24); normal from A to B is -y here
    assert resolve_collision((3, -4), (0, 0), 1, INF, (0, -1), 1.0) == (Vector3D(3, 4), Vector3D(0, 0))
    # A static, B moving (-2, 1) into it along -x: B bounces to (2, 1); A untouched
    assert resolve_collision((0, 0), (-2, 1), INF, 1, (1, 0), 1.0) == (Vector3D(0, 0), Vector3D(2, 1))
    # e = 0.5 against a static body: v_perp -4 -> 2
    assert resolve_collision((3, -4), (0, 0), 5, INF, (0, -1), 0.5)[0] == Vector3D(3, 2)


@pytest.mark.parametrize(
    ("v_a", "v_b"),
    [((-1, 0), (1, 0)), ((0, 3), (0, 3)), ((0, 0), (0, 0)), ((5, 1), (5, -1))],
    ids=["separating", "parallel", "at-rest", "sliding"],
)
def test_resolve_collision_leaves_non_approaching_pairs_unchanged(
    v_a: tuple[float, float], v_b: tuple[float, float]
) -> None:
    # v_n = (v_b - v_a).x >= 0 in every row
    assert resolve_collision(v_a, v_b, 1, 7, (1, 0), 0.5) == (Vector3D(*v_a), Vector3D(*v_b))


def test_impulse_magnitude_golden() -> None:
    # j = -(1 + 0.5)(-2) / 2 = 1.5
    assert impulse_magnitude(-2.0, 2.0, 0.5) == 1.5


# --- resolve_collision properties ------------------------------------------------------------------------
_MASSES = st.one_of(st.sampled_from([1.0, 1000.0]), masses())
_VELOCITIES = vectors(3, bound=1e2)


def _check_resolution(va: Vector3D, vb: Vector3D, ma: float, mb: float, normal: Vector3D, e: float) -> None:
    va2, vb2 = resolve_collision(va, vb, ma, mb, normal, e)
    n = normal.normalized()
    vn, vn2 = (vb - va).dot(n), (vb2 - va2).dot(n)
    speed = 1.0 + va.length() + vb.length()
    # velocity perpendicular to the normal is untouched, for both bodies
    for before, after in ((va, va2), (vb, vb2)):
        assert vec_close(after.perpendicular_projection(n), before.perpendicular_projection(n), tol=1e-12 * speed)
    if vn >= 0.0:  # separating or resting: unchanged
        assert (va2, vb2) == (va, vb)
        return
    # relative normal velocity after = -e times before (lab eq. 15)
    assert vn2 == pytest.approx(-e * vn, abs=1e-9 * speed)
    if math.isinf(ma) or math.isinf(mb):
        static, after = (va, va2) if math.isinf(ma) else (vb, vb2)
        assert after == static  # a static body never moves
        return
    # momentum conserved (lab eq. 12), relative to the momenta involved
    p, p2 = va * ma + vb * mb, va2 * ma + vb2 * mb
    assert (p2 - p).length() <= 1e-12 * (ma * va.length() + mb * vb.length()) + 1e-300
    # kinetic energy lost: (1 - e^2)/2 mu v_n^2, mu the reduced mass; 0 at e = 1
    mu = ma * mb / (ma + mb)
    ke, ke2 = kinetic_energy(ma, va) + kinetic_energy(mb, vb), kinetic_energy(ma, va2) + kinetic_energy(mb, vb2)
    expected_loss = 0.5 * (1.0 - e * e) * mu * vn * vn
    assert ke - ke2 == pytest.approx(expected_loss, abs=1e-12 * (ke + 1.0))
    assert ke2 <= ke * (1 + 1e-12)


@given(_VELOCITIES, _VELOCITIES, _MASSES, _MASSES, directions(), restitutions())
def test_resolve_collision_physics(
    va: Vector3D, vb: Vector3D, ma: float, mb: float, normal: Vector3D, e: float
) -> None:
    _check_resolution(va, vb, ma, mb, normal, e)


@given(_VELOCITIES, _MASSES, _MASSES, directions(), restitutions())
def test_resolve_collision_physics_head_on(va: Vector3D, ma: float, mb: float, normal: Vector3D, e: float) -> None:
    # B at rest in A's path: always approaching, so the impulse branch is exercised
    n = normal.normalized()
    _check_resolution(n * (1.0 + abs(va.dot(n))) + va.perpendicular_projection(n), Vector3D(0, 0), ma, mb, n, e)


@given(_VELOCITIES, _VELOCITIES, _MASSES, _MASSES, directions())
def test_resolve_collision_elastic_conserves_energy(
    va: Vector3D, vb: Vector3D, ma: float, mb: float, normal: Vector3D
) -> None:
    va2, vb2 = resolve_collision(va, vb, ma, mb, normal, 1.0)
    ke = kinetic_energy(ma, va) + kinetic_energy(mb, vb)
    ke2 = kinetic_energy(ma, va2) + kinetic_energy(mb, vb2)
    assert ke2 == pytest.approx(ke, rel=1e-12, abs=1e-12)


@given(_VELOCITIES, _VELOCITIES, _MASSES, st.booleans(), directions(), restitutions())
def test_resolve_collision_static(
    va: Vector3D, vb: Vector3D, m: float, a_static: bool, normal: Vector3D, e: float
) -> None:
    ma, mb = (INF, m) if a_static else (m, INF)
    _check_resolution(va, vb, ma, mb, normal, e)


@given(_VELOCITIES, _MASSES, directions(), restitutions())
def test_resolve_collision_against_static_at_rest_is_reflection(
    v: Vector3D, m: float, normal: Vector3D, e: float
) -> None:
    n = normal.normalized()
    moving = v if v.dot(n) > 0.0 else -v  # A moves towards B along n
    va2, vb2 = resolve_collision(moving, (0, 0, 0), m, INF, n, e)
    assert vb2 == Vector3D(0, 0, 0)
    if moving.dot(n) > 0.0:
        assert vec_close(va2, reflect_velocity(moving, n, e), tol=1e-12)


@given(_VELOCITIES, _VELOCITIES, _MASSES, _MASSES, directions(), restitutions())
def test_resolve_collision_is_symmetric_in_a_and_b(
    va: Vector3D, vb: Vector3D, ma: float, mb: float, normal: Vector3D, e: float
) -> None:
    va2, vb2 = resolve_collision(va, vb, ma, mb, normal, e)
    vb3, va3 = resolve_collision(vb, va, mb, ma, -normal, e)
    scale = 1e-12 * (1.0 + va.length() + vb.length())
    assert vec_close(va3, va2, tol=scale) and vec_close(vb3, vb2, tol=scale)


@given(_VELOCITIES, directions(), restitutions())
def test_reflect_velocity_properties(v: Vector3D, normal: Vector3D, e: float) -> None:
    n = normal.normalized()
    out = reflect_velocity(v, normal, e)
    tol = 1e-12 * (1.0 + v.length())
    assert vec_close(out.perpendicular_projection(n), v.perpendicular_projection(n), tol=tol)  # tangential kept
    assert out.dot(n) == pytest.approx(-e * v.dot(n), abs=tol)  # normal part reversed, times e
    assert vec_close(reflect_velocity(v, -3.0 * normal, e), out, tol=tol)  # sign and length of n irrelevant
    if e == 1.0:
        assert out.length() == pytest.approx(v.length(), rel=1e-12, abs=1e-12)


# --- separate -----------------------------------------------------------------------------------------
def test_separate_golden() -> None:
    # w_a = (1/1) / (1/1 + 1/3) = 0.75, w_b = 0.25: A moves -0.3, B +0.1
    pa, pb = separate((0, 0), (1, 0), 1, 3, (1, 0), 0.4)
    assert vec_close(pa, (-0.3, 0)) and vec_close(pb, (1.1, 0))
    # equal masses: half each, along the unit normal (0, 2) -> (0, 1)
    assert separate((0, 0, 0), (0, 1, 0), 2, 2, (0, 2, 0), 0.5) == (Vector3D(0, -0.25, 0), Vector3D(0, 1.25, 0))
    # B static: A takes the whole depth
    assert separate((0, 0), (1, 0), 1, INF, (1, 0), 0.5) == (Vector3D(-0.5, 0), Vector3D(1, 0))
    # depth 0: nothing moves
    assert separate((1, 2), (3, 4), 1, 1, (1, 1), 0.0) == (Vector3D(1, 2), Vector3D(3, 4))


@given(vectors(), vectors(), _MASSES, _MASSES, directions(), st.floats(0, 1e2))
def test_separate_properties(pa: Vector3D, pb: Vector3D, ma: float, mb: float, normal: Vector3D, depth: float) -> None:
    pa2, pb2 = separate(pa, pb, ma, mb, normal, depth)
    n = normal.normalized()
    tol = 1e-12 * (1.0 + pa.length() + pb.length())
    da, db = pa2 - pa, pb2 - pb
    assert ((pb2 - pa2) - (pb - pa)).dot(n) == pytest.approx(depth, abs=tol)  # the overlap is removed
    assert vec_close(da * ma + db * mb, Vector3D(0, 0), tol=tol * (ma + mb))  # centre of mass stays
    assert da.cross(n).length() <= tol and db.cross(n).length() <= tol  # moved along the normal only
    assert da.dot(n) <= 0.0 <= db.dot(n)  # A backwards, B forwards


@given(vectors(), vectors(), _MASSES, st.booleans(), directions(), st.floats(0, 1e2))
def test_separate_static_body_does_not_move(
    pa: Vector3D, pb: Vector3D, m: float, a_static: bool, normal: Vector3D, depth: float
) -> None:
    pa2, pb2 = separate(pa, pb, INF if a_static else m, m if a_static else INF, normal, depth)
    assert (pa2 == pa) if a_static else (pb2 == pb)


def test_the_velocity_update_every_stepper_makes_is_lab_eq_24_worked_by_hand() -> None:
    # contact_law.pushed_velocity is the one velocity update (Euler, exact and contact
    # steppers, the event loop's wall bounce, this module). A 2 kg ball at (3, -4) m/s onto a
    # floor (n = (0, 1)), e = 0.5: j = -(1 + 0.5)(-4) / (1/2) = 12 N s, v_y' = -4 + 12 * 0.5 * 1
    # = 2 m/s (eq. 24: -e v_y); v_x' = 3 + 12 * 0.5 * 0 = 3 m/s.
    from collisionlab.engine.contact_law import pushed_velocity

    assert pushed_velocity(-4.0, 12.0, 0.5, 1.0) == 2.0
    assert pushed_velocity(3.0, 12.0, 0.5, 0.0) == 3.0
    # The other body of a pair gets -j: A (1 kg) at 1 m/s, j = 1.5 N s along n = (1, 0, 0) from A
    # to B: 1 - 1.5 * 1 = -0.5 m/s (momentum: B's +1.5 / m_b balances it).
    assert pushed_velocity(1.0, -1.5, 1.0, 1.0) == -0.5
    assert pushed_velocity(7.0, 5.0, 0.0, 1.0) == 7.0  # an infinite mass does not move
