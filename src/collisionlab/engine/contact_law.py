"""The contact law, each rule written once as a scalar kernel: the restitution a contact gets
(:func:`applied_restitution`), the impulse along its normal (:func:`impulse_magnitude`), the
velocity it leaves (:func:`pushed_velocity`) and the kinetic energy theory says it takes (the
ledger's term, :func:`collision_loss`). Lab eqs. 12, 15 and 24.

Like :mod:`.geometry_kernels`, every function takes and returns plain floats, so the same source
runs as Python (the scalar API, :mod:`collisionlab.resolution`; small worlds) and compiled by
numba inside every stepper (Forward Euler, exact, contact, and the event loop,
:mod:`collisionlab.edmd.predict`). Nothing here allocates or raises; it imports nothing.

The restitution rule: ``e`` applies to an approach at least a threshold speed ``v_rest`` fast
(:func:`is_impact`); a slower one is a resting contact, ``e = 0``. The test is this file's; the
threshold is each stepper's, because each comes to rest its own way:

=====================  ======================================================================
stepper                ``v_rest``
=====================  ======================================================================
Forward Euler          on a support, ``rest_speed + 2 |g.n| dt / e^2`` (a bounce that would not
                       rise above one step's approach is the integrator's, not physics); between
                       two free bodies ``rest_speed``; without gravity 0 (every touch bounces)
exact, every touch an  ``rest_speed + sqrt(4 |a.n| contact_margin)`` (a hop lower than the contact
event                  margin), ``a`` the pair's relative acceleration
exact, contacts        ``max(REST_SPEED, |g| dt)`` (:func:`~collisionlab.engine.contact_stepper.rest_speed`:
solved                 a body resting on a support closes at up to ``|g| dt / 2`` within a step)
event-driven           no threshold: the TC model (``e = 1`` within ``t_c`` of a ball's last
                       collision; Luding and McNamara 1998), the floor's bounce at least ``g t_c / 2``
=====================  ======================================================================

One threshold for every stepper was tried (bench/LOG.md, 2026-12-06): the contact stepper's in the
exact stepper moved the golden outputs, and in Forward Euler a ball dropped on an incline made 322
collision events in 3 s instead of a few bounces.

>>> impulse_magnitude(-2.0, 2.0, 1.0)    # j = -(1 + 1)(-2) / (1/1 + 1/1)
2.0
"""

from __future__ import annotations

__all__ = ["applied_restitution", "collision_loss", "impulse_magnitude", "is_impact", "pushed_velocity"]

#: Helpers the compiled form inlines into their callers (:mod:`.compiled`): the two the steppers'
#: innermost loops call (every prediction asks :func:`is_impact`; every solver iteration moves
#: velocities by :func:`pushed_velocity`).
INLINE = ("is_impact", "pushed_velocity")


def is_impact(normal_speed: float, rest_speed: float) -> bool:
    """The restitution rule's test: whether a contact closing at ``normal_speed`` (``v_n < 0``) is
    an impact, which ``e`` applies to, rather than a resting contact (``e = 0``, no bounce): its
    approach ``-v_n`` is at least ``rest_speed``. The Forward Euler, exact and contact steppers
    decide with this, each with its own threshold (module docstring); the event loop has none.

    >>> is_impact(-2.0, 0.1), is_impact(-0.05, 0.1), is_impact(-0.1, 0.1)
    (True, False, True)
    """
    return -normal_speed >= rest_speed


def applied_restitution(normal_speed: float, restitution: float, rest_speed: float) -> float:
    """The e a contact gets: ``restitution``, or 0 when the approach ``-v_n`` is slower than
    ``rest_speed`` (so a ball under gravity comes to rest instead of bouncing forever).

    >>> applied_restitution(-2.0, 0.5, 1e-3), applied_restitution(-1e-4, 0.5, 1e-3)
    (0.5, 0.0)
    """
    return restitution if is_impact(normal_speed, rest_speed) else 0.0


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
