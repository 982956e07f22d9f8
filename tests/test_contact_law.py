"""engine/contact_law.py, the contact law written once (the impulse, the velocity update, the
restitution rule and the ledger's loss term), against the closed form of a head-on collision of
two masses (momentum kept, the relative velocity reversed and scaled by e), never against the
formulas it is written with."""

from __future__ import annotations

import math

import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from collisionlab.engine.contact_law import (
    applied_restitution,
    collision_loss,
    impulse_magnitude,
    is_impact,
    pushed_velocity,
)


def _head_on(m1: float, v1: float, m2: float, v2: float, e: float) -> tuple[float, float]:
    """The textbook result (e.g. Goldstein; any mechanics text): u1 = (m1 v1 + m2 v2 + m2 e (v2 - v1)) / (m1 + m2),
    u2 = (m1 v1 + m2 v2 + m1 e (v1 - v2)) / (m1 + m2)."""
    p = m1 * v1 + m2 * v2
    return (p + m2 * e * (v2 - v1)) / (m1 + m2), (p + m1 * e * (v1 - v2)) / (m1 + m2)


def _through_the_law(m1: float, v1: float, m2: float, v2: float, e: float) -> tuple[float, float]:
    """Body 1 (A) at the left moving right into body 2 (B): the normal from A to B is +x, so
    v_n = v2 - v1, B gets +j, A gets -j."""
    j = impulse_magnitude(v2 - v1, 1.0 / m1 + 1.0 / m2, e)
    return pushed_velocity(v1, -j, 1.0 / m1, 1.0), pushed_velocity(v2, j, 1.0 / m2, 1.0)


@pytest.mark.parametrize(
    "m1, v1, m2, v2, e, u1, u2",
    [
        # equal masses, elastic: they swap (1, 0) -> (0, 1)
        (1.0, 1.0, 1.0, 0.0, 1.0, 0.0, 1.0),
        # equal masses, e = 0: they move together at the mean, 0.5
        (1.0, 1.0, 1.0, 0.0, 0.0, 0.5, 0.5),
        # 2 kg at 3 m/s into 1 kg at rest, e = 0.5: p = 6; u1 = (6 + 1 * 0.5 * (0 - 3)) / 3 = 1.5,
        # u2 = (6 + 2 * 0.5 * 3) / 3 = 3
        (2.0, 3.0, 1.0, 0.0, 0.5, 1.5, 3.0),
        # closing from both sides: 1 kg at 2, 3 kg at -2, e = 1: p = -4; u1 = (-4 + 3 * (-4)) / 4 = -4,
        # u2 = (-4 + 1 * 4) / 4 = 0
        (1.0, 2.0, 3.0, -2.0, 1.0, -4.0, 0.0),
    ],
)
def test_a_head_on_collision_leaves_the_hand_worked_velocities(
    m1: float, v1: float, m2: float, v2: float, e: float, u1: float, u2: float
) -> None:
    assert _through_the_law(m1, v1, m2, v2, e) == pytest.approx((u1, u2), abs=1e-15)


@given(
    st.floats(0.01, 100.0),
    st.floats(-50.0, 50.0),
    st.floats(0.01, 100.0),
    st.floats(-50.0, 50.0),
    st.floats(0.0, 1.0),
)
def test_the_law_is_the_closed_form_and_books_the_energy_it_takes(
    m1: float, v1: float, m2: float, v2: float, e: float
) -> None:
    assume(v2 - v1 < -1e-6)  # approaching: a collision to check
    u1, u2 = _through_the_law(m1, v1, m2, v2, e)
    w1, w2 = _head_on(m1, v1, m2, v2, e)
    scale = abs(v1) + abs(v2)
    assert u1 == pytest.approx(w1, abs=1e-12 * scale) and u2 == pytest.approx(w2, abs=1e-12 * scale)
    lost = 0.5 * (m1 * v1 * v1 + m2 * v2 * v2) - 0.5 * (m1 * w1 * w1 + m2 * w2 * w2)
    energy = 0.5 * (m1 * v1 * v1 + m2 * v2 * v2)
    assert collision_loss(v2 - v1, 1.0 / m1 + 1.0 / m2, e) == pytest.approx(lost, abs=1e-9 * energy)


def test_a_wall_takes_the_closed_form_energy() -> None:
    # 2 kg at 3 m/s into a wall (infinite mass: inverse mass 0), e = 0.5: it leaves at -1.5 m/s,
    # losing 0.5 * 2 * (9 - 2.25) = 6.75 J; j = 2 * (3 + 1.5) = 9 N s against +x.
    j = impulse_magnitude(-3.0, 0.5, 0.5)  # the wall's normal points at the body: v_n = -3
    assert j == 9.0
    assert pushed_velocity(3.0, j, 0.5, -1.0) == -1.5
    assert collision_loss(-3.0, 0.5, 0.5) == 6.75


@pytest.mark.parametrize(
    "normal_speed, rest_speed, impact",
    [
        (-2.0, 0.1, True),
        (-0.1, 0.1, True),  # exactly the threshold: an impact (the approach is at least v_rest)
        (-0.0999, 0.1, False),
        (0.5, 0.1, False),  # separating
        (-1e-300, 0.0, True),  # no threshold: every approach
        (0.0, -math.inf, True),  # the steppers' "every touch an impact"
    ],
)
def test_the_restitution_rule_s_threshold(normal_speed: float, rest_speed: float, impact: bool) -> None:
    assert is_impact(normal_speed, rest_speed) is impact
    assert applied_restitution(normal_speed, 0.7, rest_speed) == (0.7 if impact else 0.0)
