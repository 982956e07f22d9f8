"""Collision resolution: pure velocity formulas and a separate positional correction.

* :func:`reflect_velocity` - a body off a static line or plane (lab eq. 24).
* :func:`resolve_collision` - two bodies with masses, an impulse along the line of action
  (lab eqs. 12 and 15 applied along the normal; the postlab's question 3).
* :func:`separate` - pushes overlapping bodies apart, in inverse proportion to mass. It is kept
  apart from the two formulas above so that they stay pure velocity laws.
"""

from __future__ import annotations

from .engine.contact_law import impulse_magnitude, pushed_velocity
from .errors import InvalidInputError
from .validate import non_negative, positive_or_inf
from .vector import Vector3D, VectorLike, as_vector

__all__ = ["impulse_magnitude", "reflect_velocity", "resolve_collision", "separate"]


def reflect_velocity(velocity: VectorLike, normal: VectorLike, restitution: float) -> Vector3D:
    """Velocity after hitting a static line or plane: ``v_f = v_i - (1 + e)(v_i . n) n``
    (lab eq. 24, with ``n`` the unit normal; ``normal`` is normalised here, and its sign does not
    matter because the formula is even in ``n``).

    The tangential part is unchanged; the normal part is reversed and scaled by ``e``. The
    formula is applied as written even to a body moving away from the surface; callers that
    step a simulation check ``v . n`` first (the world does).

    >>> reflect_velocity((3, -4), (0, 1), 1.0)        # billiard ball off a rail along x
    Vector3D(x=3.0, y=4.0, z=0.0)
    >>> reflect_velocity((3, -4), (0, 1), 0.5)        # v_perp -4 -> +2 (eq. 16)
    Vector3D(x=3.0, y=2.0, z=0.0)
    >>> reflect_velocity((1, -1, 0), (0, 2, 0), 0.0)  # perfectly inelastic: normal part removed
    Vector3D(x=1.0, y=0.0, z=0.0)
    """
    v = as_vector(velocity, "velocity")
    n = as_vector(normal, "normal").normalized("normal")
    e = non_negative(restitution, "restitution")
    # A static surface has infinite mass: 1/m_a + 1/m_b = 1/m, and v += (j/m) n with j/m as below.
    return _pushed(v, impulse_magnitude(v.dot(n), 1.0, e), 1.0, n)


def resolve_collision(
    v_a: VectorLike,
    v_b: VectorLike,
    m_a: float,
    m_b: float,
    normal: VectorLike,
    restitution: float,
) -> tuple[Vector3D, Vector3D]:
    """Velocities after a collision of bodies A and B, with ``normal`` the line of action from
    A to B (normalised here).

    With ``v_n = (v_b - v_a) . n`` (negative when approaching) and
    ``j = -(1 + e) v_n / (1/m_a + 1/m_b)``: ``v_a' = v_a - (j / m_a) n`` and
    ``v_b' = v_b + (j / m_b) n``. Momentum is conserved (lab eq. 12), the relative normal
    velocity becomes ``-e v_n`` (lab eq. 15), the velocity perpendicular to ``n`` is unchanged.
    ``math.inf`` is the mass of a static body. A pair that is already separating or resting
    (``v_n >= 0``) is returned unchanged.

    >>> resolve_collision((1, 0), (-1, 0), 1.0, 1.0, (1, 0), 1.0)   # equal masses swap velocities
    (Vector3D(x=-1.0, y=0.0, z=0.0), Vector3D(x=1.0, y=0.0, z=0.0))
    >>> # m_a = 1, m_b = 3, e = 0: both end at the centre-of-mass velocity (2*1 + 0*3)/4 = 0.5 (eq. 13)
    >>> resolve_collision((2, 0), (0, 0), 1.0, 3.0, (1, 0), 0.0)
    (Vector3D(x=0.5, y=0.0, z=0.0), Vector3D(x=0.5, y=0.0, z=0.0))
    >>> import math   # against a static body it is eq. 24
    >>> resolve_collision((3, -4), (0, 0), 1.0, math.inf, (0, -1), 1.0)[0]
    Vector3D(x=3.0, y=4.0, z=0.0)
    """
    va = as_vector(v_a, "v_a")
    vb = as_vector(v_b, "v_b")
    inverse_a = 1.0 / positive_or_inf(m_a, "m_a")
    inverse_b = 1.0 / positive_or_inf(m_b, "m_b")
    n = as_vector(normal, "normal").normalized("normal")
    e = non_negative(restitution, "restitution")
    if inverse_a + inverse_b == 0.0:
        raise InvalidInputError("m_a, m_b", "at least one body must have a finite mass")
    vn = (vb - va).dot(n)
    if vn >= 0.0:
        return va, vb
    j = impulse_magnitude(vn, inverse_a + inverse_b, e)
    return _pushed(va, -j, inverse_a, n), _pushed(vb, j, inverse_b, n)


def _pushed(v: Vector3D, impulse: float, inverse_mass: float, n: Vector3D) -> Vector3D:
    """``v + (j / m) n``, each component by the steppers' own kernel."""
    return Vector3D(*(pushed_velocity(c, impulse, inverse_mass, d) for c, d in zip(v, n, strict=True)))


def separate(
    p_a: VectorLike,
    p_b: VectorLike,
    m_a: float,
    m_b: float,
    normal: VectorLike,
    depth: float,
) -> tuple[Vector3D, Vector3D]:
    """Positions that remove an overlap of ``depth`` along ``normal`` (from A to B), each body
    moved in inverse proportion to its mass: A by ``-n d w_a``, B by ``+n d w_b`` with
    ``w_a = (1/m_a) / (1/m_a + 1/m_b)``. A static body (mass ``math.inf``) does not move.

    >>> separate((0, 0), (1, 0), 1.0, 3.0, (1, 0), 0.4)   # w_a = 1/(1 + 1/3) = 0.75, w_b = 0.25
    (Vector3D(x=-0.30000000000000004, y=0.0, z=0.0), Vector3D(x=1.1, y=0.0, z=0.0))
    """
    pa = as_vector(p_a, "p_a")
    pb = as_vector(p_b, "p_b")
    inverse_a = 1.0 / positive_or_inf(m_a, "m_a")
    inverse_b = 1.0 / positive_or_inf(m_b, "m_b")
    n = as_vector(normal, "normal").normalized("normal")
    d = non_negative(depth, "depth")
    total = inverse_a + inverse_b
    if total == 0.0:
        raise InvalidInputError("m_a, m_b", "at least one body must have a finite mass")
    return pa - n * (d * inverse_a / total), pb + n * (d * inverse_b / total)
