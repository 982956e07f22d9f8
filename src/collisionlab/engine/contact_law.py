"""The contact law, each rule written once as a scalar kernel: the restitution a contact gets
(:func:`applied_restitution`), the impulse along its normal (:func:`impulse_magnitude`), the
velocity it leaves (:func:`pushed_velocity`) and the kinetic energy theory says it takes (the
ledger's term, :func:`collision_loss`). Lab eqs. 12, 15 and 24.

Like :mod:`.geometry_kernels`, every function takes and returns plain floats, so the same source
runs as Python (the scalar API, :mod:`collisionlab.resolution`; small worlds) and compiled by
numba inside every stepper (Forward Euler, exact, contact, and the event loop,
:mod:`collisionlab.edmd.predict`). Nothing here allocates or raises; it imports nothing.

>>> impulse_magnitude(-2.0, 2.0, 1.0)    # j = -(1 + 1)(-2) / (1/1 + 1/1)
2.0
"""

from __future__ import annotations

__all__ = ["applied_restitution", "collision_loss", "impulse_magnitude", "pushed_velocity"]


def applied_restitution(normal_speed: float, restitution: float, rest_speed: float) -> float:
    """The e a contact gets: ``restitution``, or 0 when the approach ``-v_n`` is slower than
    ``rest_speed`` (so a ball under gravity comes to rest instead of bouncing forever).

    >>> applied_restitution(-2.0, 0.5, 1e-3), applied_restitution(-1e-4, 0.5, 1e-3)
    (0.5, 0.0)
    """
    return 0.0 if -normal_speed < rest_speed else restitution


def collision_loss(normal_speed: float, inverse_mass_sum: float, restitution: float) -> float:
    """The kinetic energy a collision takes, as theory has it: ``(1 - e^2) mu v_n^2 / 2`` with
    ``mu = 1 / (1/m_a + 1/m_b)`` the reduced mass (the ledger's theory column: every stepper's
    impacts book it). An infinite mass (a wall) makes ``mu`` the other body's.

    >>> collision_loss(-2.0, 2.0, 0.5)   # two balls of 1 kg (mu 0.5) closing at 2 m/s: 0.75 * 0.5 * 4 / 2
    0.75
    >>> collision_loss(-2.0, 1.0, 1.0), collision_loss(-3.0, 0.5, 0.0)   # elastic; a 2 kg body stopped by a wall
    (0.0, 9.0)
    """
    return 0.5 * (1.0 - restitution * restitution) * normal_speed * normal_speed / inverse_mass_sum


def pushed_velocity(velocity: float, impulse: float, inverse_mass: float, direction: float) -> float:
    """One component of a body's velocity after an impulse: ``v' = v + (j / m) n``, ``n`` the unit
    direction it is pushed in (lab eqs. 12 and 15 along the line of action: B gets ``+j`` along the
    normal from A to B, A gets ``-j``; eq. 24 off a static surface). Every stepper's impulse and
    the scalar API's (:mod:`collisionlab.resolution`) move a velocity through here, one component
    at a time. An infinite mass (``inverse_mass`` 0) is not moved by it.

    >>> pushed_velocity(-2.0, 3.0, 1.0, 1.0)     # 1 kg off a wall at 2 m/s, e = 0.5: j = 3 N s
    1.0
    >>> pushed_velocity(1.0, -2.0, 0.5, 1.0)     # A (2 kg) gets -j: 1 - 2 / 2
    0.0
    >>> pushed_velocity(4.0, 3.0, 0.0, 1.0)      # a kinematic body
    4.0
    """
    return velocity + impulse * inverse_mass * direction


def impulse_magnitude(normal_speed: float, inverse_mass_sum: float, restitution: float) -> float:
    """``j = -(1 + e) v_n / (1/m_a + 1/m_b)``: the impulse that turns the relative normal
    velocity ``v_n`` into ``-e v_n`` (lab eq. 15 along the normal; eq. 24 when one mass is
    infinite).

    >>> impulse_magnitude(-2.0, 1.0, 0.5)    # a body of mass 1 off a wall at 2 m/s, e = 0.5
    3.0
    """
    return -(1.0 + restitution) * normal_speed / inverse_mass_sum
