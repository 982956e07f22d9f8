"""When a pair of bodies in flight first touches: the engine's one time of impact, for every
stepper that predicts impacts (phase 3 of :mod:`.exact_kernels`; phase 2 of
:mod:`.contact_kernels`, through :mod:`.contact_time_of_impact`) and for the scalar query
:func:`collisionlab.toi.time_of_impact`. Conservative advancement along the separating axis
(B. Mirtich, "Impulse-based dynamic simulation of rigid body systems", 1996; as Box2D's
``b2TimeOfImpact``), each step the first root of the gap along the current normal
(:func:`~.geometry_kernels.first_root`, exact for a ball against a line, plane or box face), two
balls in straight flight in closed form (Ericson, *Real-Time Collision Detection*, 4.4.3). A touch
slower than the caller's rest speed is no impact (the restitution rule,
:func:`~.contact_law.is_impact`). The state is only read: each body is where its flight
(:mod:`.exact_flight`) puts it at each time tried.

Owns ``TOI_ITERATIONS``, :func:`_time_of_impact`, :func:`_separation_at` (both called as Python by
:func:`collisionlab.toi.time_of_impact` too), two balls' root (:func:`_ball_ball_root`) and the
approach speed that is only rounding (:func:`_rounding_speed`, which the impacts use too). It
imports the contact law's test, the separations of :mod:`.geometry_kernels` and
:mod:`.pair_separation` and the flight; it must not import the impulses, rests, sweeps, impacts
or the loops (a query changes nothing).
"""

from __future__ import annotations

import math
from typing import Any

from ..tolerances import APPROACH_ROUNDING

if "_GEOMETRY" in globals():  # the compiled copy: the kernels it calls are compiled too
    cl: Any = globals()["_CONTACT_LAW"]
    gk: Any = globals()["_GEOMETRY"]
    ps: Any = globals()["_PAIR_SEPARATION"]
    ef: Any = globals()["_EXACT_FLIGHT"]
else:
    from . import contact_law as cl
    from . import exact_flight as ef
    from . import geometry_kernels as gk
    from . import pair_separation as ps

#: The most iterations of conservative advancement for one prediction; the time reached is then
#: used (it is never after the impact, so nothing is missed: the pair is looked at again there).
TOI_ITERATIONS = 64

#: Helpers the compiled form inlines into their callers (:mod:`.compiled`): the small ones.
INLINE = (
    "_rounding_speed",
    "_ball_ball_root",
)
#: Called, not inlined, and compiled without reference counts (it allocates nothing, so a call
#: passes its arrays as they are): inlined at its three places in the exact stepper's impacts it
#: took 29 % of that kind's compile (109.9 s against 77.9 s); called, the exact stepper's
#: landing of a pile runs 5-7 % slower (bench/LOG.md, 2026-12-06, fourth session).
NO_REFCOUNT = ("_time_of_impact",)


def _rounding_speed(ux: float, uy: float, uz: float, wx: float, wy: float, wz: float) -> float:
    """The approach speed that is only rounding for bodies of velocities ``u`` and ``w``
    (``APPROACH_ROUNDING`` in :mod:`collisionlab.tolerances`).

    >>> _rounding_speed(0.5, 0.0, 0.0, -1.0, 0.0, 0.0) < 1e-14
    True
    """
    return APPROACH_ROUNDING * (math.sqrt(ux * ux + uy * uy + uz * uz) + math.sqrt(wx * wx + wy * wy + wz * wz))


def _ball_ball_root(
    px: float, py: float, pz: float, wx: float, wy: float, wz: float, reach: float, limit: float
) -> float:
    """The first ``t`` in ``(0, limit]`` with ``|p + w t| = reach`` for two balls apart (``p``,
    ``w``: the second's position and velocity minus the first's), or ``inf``: the engine's one
    time of impact of two balls (:func:`~collisionlab.engine.geometry_kernels.time_of_impact_ball_ball`).

    >>> float(_ball_ball_root(3.0, 1.0, 0.0, -1.0, 0.0, 0.0, 1.0, 10.0))   # a graze: (3 - t)^2 + 1 = 1 at t = 3 only
    3.0
    """
    t = gk.time_of_impact_ball_ball(px, py, pz, wx, wy, wz, reach * reach)
    return t if 0.0 < t <= limit else math.inf  # 0: touching already, which the caller handles


def _separation_at(
    kind: Any,
    pos: Any,
    vel: Any,
    acc: Any,
    tau: Any,
    ext: Any,
    s_kind: Any,
    s_a: Any,
    s_b: Any,
    a: int,
    b: int,
    t: float,
    k2: Any,
    p2: Any,
    v2: Any,
    e2: Any,
) -> Any:
    """The separation of pair ``(a, b)`` at time ``t`` (each body where its flight puts it then,
    the state untouched); rows 0 and 1 of ``v2`` get their velocities then (0 for a static). As
    :func:`_time_of_impact` finds it, for :func:`collisionlab.toi.time_of_impact`."""
    for r in range(2):
        i = a if r == 0 else b
        if i < 0:
            for k in range(3):
                p2[r, k] = 0.0
                v2[r, k] = 0.0
                e2[r, k] = 0.0
            k2[r] = 0
            continue
        d = t - tau[i]
        k2[r] = kind[i]
        for k in range(3):
            p2[r, k], v2[r, k] = ef._flown(pos[i, k], vel[i, k], acc[i, k], d)
            e2[r, k] = ext[i, k]
    if a >= 0:
        return ps._body_separation(k2, p2, e2, 0, 1)
    return ps._static_separation(s_kind, s_a, s_b, -1 - a, k2, p2, e2, 1)


def _time_of_impact(
    kind: Any,
    pos: Any,
    vel: Any,
    acc: Any,
    tau: Any,
    ext: Any,
    s_kind: Any,
    s_a: Any,
    s_b: Any,
    a: int,
    b: int,
    t0: float,
    t_end: float,
    gap: float,
    floor: float,
    rest_speed: float,
) -> float:
    """The time in ``[t0, t_end)`` when pair ``(a, b)`` first comes within ``gap`` while
    approaching, or ``inf`` (conservative advancement, the module docstring's phase 3): the
    engine's one time of impact of two bodies in flight (the exact stepper's, the contact
    stepper's and :func:`collisionlab.toi.time_of_impact`'s). A pair that comes within ``gap``
    approaching slower than ``rest_speed`` is a resting contact, not an impact (the restitution
    rule, :func:`~.contact_law.is_impact`): ``inf`` (the contact stepper's solve takes it);
    ``-inf`` makes every approach an impact (the exact stepper, the scalar API). A pair in
    contact and separating is followed until its gap along the normal closes again (a slow hop
    under gravity), once; an overlapping one until that gap is back to 0 after it has left.
    Each body is where its flight puts it at each time tried (a static stays, as a body of
    position and velocity 0); the state is not changed. ``floor`` is a bound the caller knows
    the pair's separation at ``t0`` is not below (``-inf`` if none): if the flight cannot close
    it to ``gap`` by ``t_end`` (the shapes do not turn, so a separation changes no faster than
    their relative position), there is no impact and nothing is computed."""
    kb = kind[b]
    eb0 = ext[b, 0]
    eb1 = ext[b, 1]
    eb2 = ext[b, 2]
    ka = kind[a] if a >= 0 else 0
    ea0 = ext[a, 0] if a >= 0 else 0.0
    ea1 = ext[a, 1] if a >= 0 else 0.0
    ea2 = ext[a, 2] if a >= 0 else 0.0
    s = -1 - a
    ax = acc[b, 0] - (acc[a, 0] if a >= 0 else 0.0)
    ay = acc[b, 1] - (acc[a, 1] if a >= 0 else 0.0)
    az = acc[b, 2] - (acc[a, 2] if a >= 0 else 0.0)
    straight = ax == 0.0 and ay == 0.0 and az == 0.0 and a >= 0 and ka <= ps.BALL_3D and kb <= ps.BALL_3D
    if floor > gap:
        span = t_end - t0
        d = t0 - tau[b]
        wx = vel[b, 0] + acc[b, 0] * d
        wy = vel[b, 1] + acc[b, 1] * d
        wz = vel[b, 2] + acc[b, 2] * d
        if a >= 0:
            d = t0 - tau[a]
            wx -= vel[a, 0] + acc[a, 0] * d
            wy -= vel[a, 1] + acc[a, 1] * d
            wz -= vel[a, 2] + acc[a, 2] * d
        travel = math.sqrt(wx * wx + wy * wy + wz * wz) * span
        travel += 0.5 * math.sqrt(ax * ax + ay * ay + az * az) * span * span
        if floor - travel > gap:
            return math.inf
    t = t0
    jumped = False
    for _ in range(TOI_ITERATIONS):
        d = t - tau[b]
        bx = pos[b, 0] + vel[b, 0] * d + 0.5 * acc[b, 0] * d * d
        by = pos[b, 1] + vel[b, 1] * d + 0.5 * acc[b, 1] * d * d
        bz = pos[b, 2] + vel[b, 2] * d + 0.5 * acc[b, 2] * d * d
        wbx = vel[b, 0] + acc[b, 0] * d
        wby = vel[b, 1] + acc[b, 1] * d
        wbz = vel[b, 2] + acc[b, 2] * d
        px = py = pz = wax = way = waz = 0.0
        if a >= 0:
            d = t - tau[a]
            px = pos[a, 0] + vel[a, 0] * d + 0.5 * acc[a, 0] * d * d
            py = pos[a, 1] + vel[a, 1] * d + 0.5 * acc[a, 1] * d * d
            pz = pos[a, 2] + vel[a, 2] * d + 0.5 * acc[a, 2] * d * d
            wax = vel[a, 0] + acc[a, 0] * d
            way = vel[a, 1] + acc[a, 1] * d
            waz = vel[a, 2] + acc[a, 2] * d
            sep = ps._pair_sep(ka, px, py, pz, ea0, ea1, ea2, kb, bx, by, bz, eb0, eb1, eb2)
        else:
            sep = ps._static_sep(
                s_kind[s], s_a[s, 0], s_a[s, 1], s_a[s, 2], s_b[s, 0], s_b[s, 1], s_b[s, 2],
                kb, bx, by, bz, eb0, eb1, eb2,
            )  # fmt: skip
        nx = sep[1]
        ny = sep[2]
        nz = sep[3]
        s1 = (wbx - wax) * nx + (wby - way) * ny + (wbz - waz) * nz
        s2 = 0.5 * (ax * nx + ay * ny + az * nz)
        if sep[0] <= gap:
            still = _rounding_speed(wax, way, waz, wbx, wby, wbz)
            if s1 < -still or (s1 <= still and s2 < 0.0):  # approaching: an impact, or resting
                return t if cl.is_impact(s1, rest_speed) else math.inf
            if jumped or s2 >= 0.0:
                return math.inf
            if sep[0] < -gap and s1 * s1 >= 4.0 * s2 * sep[0]:
                # Overlapping by more than the gap (not by rounding): the later root of
                # sep + s1 t + s2 t^2 = 0, when the gap along n is back to 0 from above
                # (s2 < 0 < s1, so -s1 - sqrt(disc) does not cancel).
                t += (-s1 - math.sqrt(s1 * s1 - 4.0 * s2 * sep[0])) / (2.0 * s2)
            else:
                t += -s1 / s2  # when the gap along n closes again: never after the true return
            jumped = True
            if t >= t_end:
                return math.inf
            continue
        if s2 == 0.0 and straight:
            # Two balls in straight flight: |p + w t| = r_a + r_b in closed form (Ericson 4.4.3),
            # exact also for a graze, which the iteration would only approach.
            step = _ball_ball_root(bx - px, by - py, bz - pz, wbx - wax, wby - way, wbz - waz, ea0 + eb0, t_end - t)
        else:
            step = gk.first_root(sep[0], s1, s2, t_end - t)
        if step == math.inf:
            return math.inf
        t += step
        if t >= t_end:
            return math.inf
    return t
