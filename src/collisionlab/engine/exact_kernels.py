"""The exact stepper over arrays, written once: Python for small worlds, compiled by numba
(:mod:`collisionlab.engine.compiled`) for large ones, the same source both ways.

Between impacts every body flies exactly, ``x(t) = x + v t + a t^2 / 2`` (a parabola under
gravity, a line without), so an impact is found at its time, never after it, and nothing tunnels.
One step of ``dt``, in this fixed order:

1. **Candidates.** The state is sorted by cell (the Forward Euler stepper's grid) and every pair
   that can meet before the step ends is listed: bodies ``a``, ``b`` closer than
   ``contact_margin + s_a + s_b``, where ``s_i = u_i T + a_max T^2 / 2`` bounds how far body
   ``i`` can move in the ``T`` left relative to a frame moving at a constant velocity (the
   middle of the bodies' velocities, so speeds are small for a heap sliding as one), ``u_i``
   being the bound it is listed for (``SWEEP_GROWTH`` times its speed in that frame, at least
   ``SWEEP_FLOOR`` of the fastest's, at most that), and a body and a static closer than
   ``contact_margin + v_max T + a_max T^2 / 2`` (``a_max`` is taken as
   ``ACCELERATION_HEADROOM |g|``; if phase 2 leaves a body faster than its bound or more
   accelerated than ``a_max``, the candidates are listed again with the larger ones).
2. **Resting contacts** (with gravity): a pair in contact (within ``contact_margin``) whose
   normal speed is below ``rest_speed`` and whose accelerations press it together rests: a slow
   approach or lift-off is stopped (no event), and the support cancels the pressing part of the
   acceleration, shared as an impulse would be: a body already on a support passes the part
   along that support's normal on to it, so stacks settle from the bottom up (Gauss-Seidel on
   accelerations). A body on a curved support (two balls; a ball on a box's edge or corner, radius
   ``R``) stays only while ``v_t^2 / R`` is below the pressing acceleration. Resting pairs are left
   out of the search for impacts.
3. **Times of impact** of every other candidate pair, by conservative advancement along the
   separating axis (Mirtich 1996; as Box2D's ``b2TimeOfImpact``): the gap along the current
   normal ``n`` is ``d + (w.n) t + (alpha.n) t^2 / 2`` (``w``, ``alpha``: relative velocity and
   acceleration) and the true distance is never below it, so its first root is never after the
   impact; advance to it and repeat until the gap is below ``TOI_GAP``. A gap that never closes
   along ``n`` proves there is no impact. One kernel for every pair of shapes: the separations of
   :mod:`collisionlab.engine.geometry_kernels`.
4. **Impacts, earliest first**, from a binary heap with lazy invalidation (each pair's prediction
   carries a version; a kicked body's pairs get new ones): the two bodies are brought to the
   impact's time, the impulse is applied (``j = -(1 + e) v_n / (1/m_a + 1/m_b)``, lab eqs. 12,
   15, 24; ``e = 0`` below ``rest_speed``), then the contacts it touches are settled (sequential
   impulses through every pair in contact that now approaches fast enough to close its gap to
   ``TOI_GAP`` before the step ends, its gap along the normal ``d + v_n t + a_n t^2 / 2``
   reaching it within the ``T`` left: a row of touching balls passes the impact along; a slower
   approach cannot touch within the step and is left to the predictions and to phase 2 of the
   next step), and the kicked bodies' pairs are predicted again. A kicked body that rested is
   looked at again (it may lift off); if a kick makes a body faster than its bound (or ``v_max``),
   the step is cut there and the candidates are listed again.
5. **End of the step**: every body is brought to its end, overlaps left by rounding are pushed
   apart to ``slop`` (as in Forward Euler: a pass after the first looks only at the pairs one of
   whose bodies moved) and the pairs in contact are remembered, so a pair is reported once per
   impact.

An impact of a pair already in contact is not a new event unless it arrives faster than
``rest_speed``. Lab eq. numbers refer to the lab's text; Ericson is *Real-Time Collision
Detection*; B. Mirtich, "Impulse-based dynamic simulation of rigid body systems" (1996).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..tolerances import APPROACH_ROUNDING, MAX_RUN_SPEED

if "_GEOMETRY" in globals():  # the compiled copy: the kernels it calls are compiled too
    gk: Any = globals()["_GEOMETRY"]
    sk: Any = globals()["_STEP"]
    eh: Any = globals()["_HEAP"]
else:
    from . import event_heap as eh
    from . import geometry_kernels as gk
    from . import step_kernels as sk

__all__ = ["MAX_IMPACTS_PER_STEP", "RELAX_IMPULSES", "STATUS_SIZE", "run_exact_steps"]

#: The most impacts resolved within one step; past it the step ends without the rest (a guard
#: against an endless run of impacts; the world warns, ``status[0]`` counts such steps).
MAX_IMPACTS_PER_STEP = 100_000
#: The most iterations of conservative advancement for one prediction; the time reached is then
#: used (it is never after the impact, so nothing is missed: the pair is looked at again there).
TOI_ITERATIONS = 64
#: The most impulses that settle the contacts one impact touches (a row of k balls needs k).
RELAX_IMPULSES = 4096
#: At most this many support normals are kept per body (a floor and two walls).
MAX_SUPPORTS = 3
#: The candidates are listed for accelerations up to this many times ``|g|``: a support passes
#: the pressing of what rests on it along (a body low in a heap is pushed down the slope by those
#: above it), so a body's acceleration may exceed ``|g|``; listing for more makes a second listing
#: (when phase 2 finds a larger one) rare, at the cost of a sweep wider by ``|g| T^2 / 2``.
ACCELERATION_HEADROOM = 2.0
#: Each body's candidates are listed for a speed (relative to the heap's frame) up to this many
#: times its own, and at least ``SWEEP_FLOOR`` of the fastest body's (never more than that):
#: a body kicked past its bound has the candidates listed again (phase 4's restart), so the
#: bounds trade the sweep's width (candidates to predict and look at again) against restarts.
SWEEP_GROWTH = 2.0
SWEEP_FLOOR = 0.5
#: After a step cut by a kick past a body's own bound, this many steps list every body for the
#: fastest's speed (as if ``SWEEP_FLOOR`` were 1): while bodies land on others, a restart (a
#: listing more) would follow in most steps, costing more than the narrower sweeps save.
SWEEP_PAUSE = 50
#: The heap has room for this many entries per candidate pair (and 2 more): twice the most that
#: can be current (a pair's prediction and its rest's expiry), so a full heap compacts to at most
#: half (:func:`~collisionlab.engine.event_heap.heap_compact`) and no push inside phase 4 allocates.
HEAP_ROOM = 4
#: What :func:`_impacts` returns with: no impact left before the step's end; a kick outran the
#: candidates' bounds (list them again); the events buffer needs room before the next impact.
DONE = 0
RESTART = 1
ROOM = 2
#: Counters returned to the world: steps that hit MAX_IMPACTS_PER_STEP, impacts resolved, times
#: the candidates had to be listed again within a step; then the step from which each body is
#: listed for its own bound again (``SWEEP_PAUSE``; kept here so that a run does not depend on
#: how its steps are split into calls).
STATUS_SIZE = 4

#: Helpers the compiled form inlines into their callers: the small ones, and those the loop calls
#: for every pair it looks at, which take arrays (a call costs a reference count taken and given
#: back for each array it passes, more than the work inside; inlined into a ``NO_REFCOUNT``
#: phase, none at all).
INLINE = (
    "_response",
    "_rounding_speed",
    "_ball_ball_root",
    "_advance",
    "_flown",
    "_flight_work",
    "_time_of_impact",
    "_kick",
    "_curvature",
    "_support_expiry",
    "_rest",
    "_closing",
    "_speed_beyond",
    "_remember",
    "_recalled",
    "_base_acceleration",
    "_unchanged_since",
)

#: The loop's phases that allocate nothing, compiled without numba's reference counts: an
#: inlined helper's array arguments each cost a count taken and given back per call, which
#: numba's pruning leaves in loops (measured: a fifth of the kernel's time; bench/README).
NO_REFCOUNT = (
    "_base_accelerations",
    "_rest_passes",
    "_outrun",
    "_sweeps",
    "_predict_all",
    "_impacts",
    "_end_separations",
)


# --- motion and time of impact ------------------------------------------------------------------
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


def _flown(x: float, v: float, a: float, d: float) -> Any:
    """One coordinate's position and velocity after a flight of ``d`` at acceleration ``a``:
    ``(x + v d + a d^2 / 2, v + a d)``.

    >>> _flown(1.0, 2.0, -10.0, 0.5)
    (0.75, -3.0)
    """
    return x + v * d + 0.5 * a * d * d, v + a * d


def _flight_work(
    vx: float, vy: float, vz: float, ax: float, ay: float, az: float, gravity: Any, d: float, ima_i: float
) -> float:
    """The energy a flight of ``d`` at acceleration ``a`` changes (kinetic plus ``-m g.x``: zero in
    free flight, the work of a support otherwise): ``m [v.(a - g) d + (a.a - g.a) d^2 / 2]``."""
    va = vx * (ax - gravity[0]) + vy * (ay - gravity[1]) + vz * (az - gravity[2])
    aa = ax * (ax - gravity[0]) + ay * (ay - gravity[1]) + az * (az - gravity[2])
    return float((va * d + 0.5 * aa * d * d) / ima_i)


def _advance(i: int, t: float, pos: Any, vel: Any, acc: Any, tau: Any, ima: Any, gravity: Any, ledger: Any) -> None:
    """Bring body ``i`` from its own time ``tau[i]`` to ``t`` exactly:
    ``x += v d + a d^2 / 2``, ``v += a d``; the energy the flight changes goes to ``ledger[0]``
    (:func:`_flight_work`)."""
    d = t - tau[i]
    if d <= 0.0:
        return
    if ima[i] > 0.0:
        ledger[0] += _flight_work(vel[i, 0], vel[i, 1], vel[i, 2], acc[i, 0], acc[i, 1], acc[i, 2], gravity, d, ima[i])
    for k in range(3):
        pos[i, k], vel[i, k] = _flown(pos[i, k], vel[i, k], acc[i, k], d)
    tau[i] = t


def _advance_all(t: float, pos: Any, vel: Any, acc: Any, tau: Any, ima: Any, gravity: Any, ledger: Any) -> None:
    """:func:`_advance` for every body, in order. Its own function, not inlined: an inlined helper
    that takes arrays costs reference counts taken and given back at every call (numba does not
    prune them in a loop), several times the flight itself, so the loop reads the arrays here."""
    energy = ledger[0]  # summed in the same order as body after body would
    for i in range(pos.shape[0]):
        d = t - tau[i]
        if d <= 0.0:
            continue
        if ima[i] > 0.0:
            energy += _flight_work(
                vel[i, 0], vel[i, 1], vel[i, 2], acc[i, 0], acc[i, 1], acc[i, 2], gravity, d, ima[i]
            )  # fmt: skip
        for k in range(3):
            pos[i, k], vel[i, k] = _flown(pos[i, k], vel[i, k], acc[i, k], d)
        tau[i] = t
    ledger[0] = energy


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
            p2[r, k], v2[r, k] = _flown(pos[i, k], vel[i, k], acc[i, k], d)
            e2[r, k] = ext[i, k]
    if a >= 0:
        return sk._body_separation(k2, p2, e2, 0, 1)
    return sk._static_separation(s_kind, s_a, s_b, -1 - a, k2, p2, e2, 1)


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
) -> float:
    """The time in ``[t0, t_end)`` when pair ``(a, b)`` first comes within ``gap`` while
    approaching, or ``inf`` (conservative advancement, the module docstring's phase 3). A pair in
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
    straight = ax == 0.0 and ay == 0.0 and az == 0.0 and a >= 0 and ka <= sk.BALL_3D and kb <= sk.BALL_3D
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
            sep = sk._pair_sep(ka, px, py, pz, ea0, ea1, ea2, kb, bx, by, bz, eb0, eb1, eb2)
        else:
            sep = sk._static_sep(
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
            if s1 < -still or (s1 <= still and s2 < 0.0):
                return t
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


# --- impulses -----------------------------------------------------------------------------------
def _response(i: int, dx: float, dy: float, dz: float, ima: Any, sup: Any, nsup: Any, free: bool) -> Any:
    """How body ``i`` answers a unit impulse along ``d``: a body resting on supports cannot be
    pushed into them, so the part along a support's normal goes to the support (unless ``free``).
    Returns the direction ``m`` its velocity changes in (per unit impulse, times its mass), its
    inverse mass along ``d``, ``(m.d) / m`` (``(1 - (s.d)^2) / m`` on one support ``s``, ``1/m``
    free), and ``|m|^2 / m``."""
    mx = dx
    my = dy
    mz = dz
    if not free:
        for s in range(nsup[i]):
            into = mx * sup[i, s, 0] + my * sup[i, s, 1] + mz * sup[i, s, 2]
            if into < 0.0:
                mx -= sup[i, s, 0] * into
                my -= sup[i, s, 1] * into
                mz -= sup[i, s, 2] * into
    return mx, my, mz, (mx * dx + my * dy + mz * dz) * ima[i], (mx * mx + my * my + mz * mz) * ima[i]


def _kick(
    a: int,
    b: int,
    nx: float,
    ny: float,
    nz: float,
    vn: float,
    e: float,
    vel: Any,
    ima: Any,
    sup: Any,
    nsup: Any,
    ledger: Any,
    impact: bool,
) -> float:
    """Apply ``j = -(1 + e) v_n / (1/m_a + 1/m_b)`` along ``n`` (A gets minus it; lab eqs. 12,
    15, 24), each body answering through its supports (:func:`_response`; its inverse mass along
    ``n`` is then smaller). The supports' normals are those of the moment they were found, so if
    that answer would add kinetic energy (beyond what ``e > 1`` adds free) the kick is applied
    free: a free impulse changes it by ``-(1 - e^2) mu v_n^2 / 2``. The kinetic energy it changes
    goes to ``ledger[1]``; an impact (not a resting contact's stop) also adds its predicted loss
    to ``ledger[3]`` and counts in ``ledger[5]`` or ``ledger[6]``. Returns ``j`` (0 when neither
    body can move)."""
    ax = ay = az = bx = by = bz = 0.0
    inv_sum = 0.0
    j = 0.0
    for attempt in range(2):
        free = attempt == 1
        ax = ay = az = 0.0
        inv_a = energy_a = 0.0
        if a >= 0 and ima[a] > 0.0:
            ax, ay, az, inv_a, energy_a = _response(a, -nx, -ny, -nz, ima, sup, nsup, free)
        bx = by = bz = 0.0
        inv_b = energy_b = 0.0
        if ima[b] > 0.0:
            bx, by, bz, inv_b, energy_b = _response(b, nx, ny, nz, ima, sup, nsup, free)
        inv_sum = inv_a + inv_b
        if inv_sum <= 0.0:
            if free:
                return 0.0
            continue
        j = gk.impulse_magnitude(vn, inv_sum, e)
        if free:
            break
        u = vel[b, 0] * bx + vel[b, 1] * by + vel[b, 2] * bz
        if a >= 0:
            u += vel[a, 0] * ax + vel[a, 1] * ay + vel[a, 2] * az
        gained = j * u + 0.5 * j * j * (energy_a + energy_b)
        if gained <= max(0.0, 0.5 * (e * e - 1.0) * vn * vn / inv_sum):
            break
    kinetic = 0.0
    if a >= 0 and ima[a] > 0.0:
        before = vel[a, 0] ** 2 + vel[a, 1] ** 2 + vel[a, 2] ** 2
        vel[a, 0] += ax * j * ima[a]
        vel[a, 1] += ay * j * ima[a]
        vel[a, 2] += az * j * ima[a]
        kinetic += 0.5 * (vel[a, 0] ** 2 + vel[a, 1] ** 2 + vel[a, 2] ** 2 - before) / ima[a]
    if ima[b] > 0.0:
        before = vel[b, 0] ** 2 + vel[b, 1] ** 2 + vel[b, 2] ** 2
        vel[b, 0] += bx * j * ima[b]
        vel[b, 1] += by * j * ima[b]
        vel[b, 2] += bz * j * ima[b]
        kinetic += 0.5 * (vel[b, 0] ** 2 + vel[b, 1] ** 2 + vel[b, 2] ** 2 - before) / ima[b]
    ledger[1] += kinetic
    if impact:
        ledger[3] -= 0.5 * (1.0 - e * e) * vn * vn / inv_sum
        if a >= 0:
            ledger[5] += 1.0
        else:
            ledger[6] += 1.0
    return float(j)


def _curvature(kind: Any, ext: Any, s_kind: Any, a: int, b: int, nx: float, ny: float, nz: float) -> float:
    """Radius of curvature of the surface pair ``(a, b)`` slides on (the Minkowski sum of the two
    shapes): ``r_a + r_b`` for two balls, the ball's radius on a box's edge or corner (a normal off
    the axes), ``inf`` when flat (a line, a plane, a wall, a box face, two boxes)."""
    if a < 0 and s_kind[-1 - a] != sk.STATIC_BOX:
        return math.inf  # a line, plane or wall: the commonest support, decided first
    ball_a = a >= 0 and kind[a] <= sk.BALL_3D
    ball_b = kind[b] <= sk.BALL_3D
    if ball_a and ball_b:
        return float(ext[a, 0] + ext[b, 0])
    if not ball_a and not ball_b:
        return math.inf
    box_a = (a >= 0 and not ball_a) or (a < 0 and s_kind[-1 - a] == sk.STATIC_BOX)
    if not (box_a or not ball_b):
        return math.inf  # a ball on a line, plane or wall
    off_axes = (1 if nx != 0.0 else 0) + (1 if ny != 0.0 else 0) + (1 if nz != 0.0 else 0)
    if off_axes < 2:
        return math.inf
    return float(ext[a, 0] if ball_a else ext[b, 0])


def _support_expiry(
    a: int, b: int, kind: Any, vel: Any, acc: Any, ext: Any, s_kind: Any, normals: Any, c: int, margin: float
) -> float:
    """How long resting pair ``c`` (normal ``normals[c]``) may be held by its accelerations of
    the moment: a ball on a box (its face ends at an edge, its edge is curved) or on a ball meets a
    support whose normal turns as the two slide past each other, and the flight the rest set
    then leaves the surface by ``s^2 / (2 R)`` after a tangential travel ``s`` (``R``: the ball's
    radius, or the two radii's sum). It is looked at again once ``s`` could reach
    ``sqrt(R margin)`` (a gap of ``margin / 2``): ``s = |v_t| t + |a_t| t^2 / 2``. ``inf`` for a
    flat support (a line, a plane, a wall) or two boxes, and when nothing slides.

    >>> kind = np.array([1, 3]); ext = np.array([[0.5, 0, 0], [1.0, 1, 1]]); n = np.array([[0.0, 1, 0]])
    >>> vel = np.array([[0.0, 0, 0], [0.1, 0, 0]]); acc = np.zeros((2, 3))
    >>> round(float(_support_expiry(1, 0, kind, vel, acc, ext, np.zeros(0, np.int64), n, 0, 2e-7)), 12)
    0.00316227766

    (a ball of radius 0.5 on a box sliding past it at 0.1 m/s: ``sqrt(0.5 * 2e-7) / 0.1`` s.)
    """
    if a < 0 and s_kind[-1 - a] != sk.STATIC_BOX:
        return math.inf  # a line, plane or wall: the commonest support, decided first
    ball_a = a >= 0 and kind[a] <= sk.BALL_3D
    ball_b = kind[b] <= sk.BALL_3D
    box_a = (a >= 0 and not ball_a) or (a < 0 and s_kind[-1 - a] == sk.STATIC_BOX)
    if ball_a and ball_b:
        radius = ext[a, 0] + ext[b, 0]
    elif ball_b and box_a:
        radius = ext[b, 0]
    elif ball_a and not ball_b:
        radius = ext[a, 0]
    else:
        return math.inf
    nx = normals[c, 0]
    ny = normals[c, 1]
    nz = normals[c, 2]
    rx = vel[b, 0] - (vel[a, 0] if a >= 0 else 0.0)
    ry = vel[b, 1] - (vel[a, 1] if a >= 0 else 0.0)
    rz = vel[b, 2] - (vel[a, 2] if a >= 0 else 0.0)
    qx = acc[b, 0] - (acc[a, 0] if a >= 0 else 0.0)
    qy = acc[b, 1] - (acc[a, 1] if a >= 0 else 0.0)
    qz = acc[b, 2] - (acc[a, 2] if a >= 0 else 0.0)
    vn = rx * nx + ry * ny + rz * nz
    qn = qx * nx + qy * ny + qz * nz
    vt = math.sqrt((rx - vn * nx) ** 2 + (ry - vn * ny) ** 2 + (rz - vn * nz) ** 2)
    at = math.sqrt((qx - qn * nx) ** 2 + (qy - qn * ny) ** 2 + (qz - qn * nz) ** 2)
    if vt == 0.0 and at == 0.0:
        return math.inf
    return float(gk.first_root(math.sqrt(radius * margin), -vt, -0.5 * at, math.inf))


def _rest(
    c: int,
    a: int,
    b: int,
    nx: float,
    ny: float,
    nz: float,
    kind: Any,
    vel: Any,
    ext: Any,
    ima: Any,
    acc: Any,
    sup: Any,
    nsup: Any,
    s_kind: Any,
    rest: Any,
    touching: Any,
    rest_speed: float,
    ledger: Any,
) -> int:
    """Make pair ``c`` a resting contact if it is one (phase 2 of the module docstring): returns
    1 if it did, 2 if it did not but stopped a slow approach or lift-off (the bodies' velocities
    changed), 0 if it changed nothing (then it returns 0 again while neither body's velocity,
    acceleration or supports change)."""
    ima_a = ima[a] if a >= 0 else 0.0
    rx = vel[b, 0] - (vel[a, 0] if a >= 0 else 0.0)
    ry = vel[b, 1] - (vel[a, 1] if a >= 0 else 0.0)
    rz = vel[b, 2] - (vel[a, 2] if a >= 0 else 0.0)
    vn = rx * nx + ry * ny + rz * nz
    pressing = 0.0
    for k in range(3):
        pressing += (acc[b, k] - (acc[a, k] if a >= 0 else 0.0)) * (nx if k == 0 else ny if k == 1 else nz)
    if abs(vn) > rest_speed or pressing >= 0.0:
        return 0
    radius = _curvature(kind, ext, s_kind, a, b, nx, ny, nz)
    if radius < math.inf:
        tx = rx - nx * vn
        ty = ry - ny * vn
        tz = rz - nz * vn
        if (tx * tx + ty * ty + tz * tz) / radius > -pressing:
            return 0  # too fast to follow the curve: it leaves the surface
    kicked = 0
    if vn != 0.0:  # a slow approach or lift-off is stopped (e = 0): resting, not an impact
        _kick(a, b, nx, ny, nz, vn, 0.0, vel, ima, sup, nsup, ledger, False)
        kicked = 2
    ax = ay = az = 0.0
    inv_a = 0.0
    if a >= 0 and ima_a > 0.0:
        ax, ay, az, inv_a, _ = _response(a, -nx, -ny, -nz, ima, sup, nsup, False)
    bx = by = bz = 0.0
    inv_b = 0.0
    if ima[b] > 0.0:
        bx, by, bz, inv_b, _ = _response(b, nx, ny, nz, ima, sup, nsup, False)
    if inv_a + inv_b <= 0.0:
        return kicked
    force = -pressing / (inv_a + inv_b)
    if inv_a > 0.0:
        acc[a, 0] += ax * force * ima_a
        acc[a, 1] += ay * force * ima_a
        acc[a, 2] += az * force * ima_a
    if inv_b > 0.0:
        acc[b, 0] += bx * force * ima[b]
        acc[b, 1] += by * force * ima[b]
        acc[b, 2] += bz * force * ima[b]
    # What rests on a support that holds (a static, a kinematic body, a supported body) is
    # supported too, along this contact's normal.
    if a < 0 or ima_a == 0.0 or nsup[a] > 0:
        if nsup[b] < MAX_SUPPORTS and ima[b] > 0.0:
            sup[b, nsup[b], 0] = nx
            sup[b, nsup[b], 1] = ny
            sup[b, nsup[b], 2] = nz
            nsup[b] += 1
    elif (ima[b] == 0.0 or nsup[b] > 0) and nsup[a] < MAX_SUPPORTS:
        sup[a, nsup[a], 0] = -nx
        sup[a, nsup[a], 1] = -ny
        sup[a, nsup[a], 2] = -nz
        nsup[a] += 1
    rest[c] = 1
    touching[c] = 1
    return 1


def _velocity_bounds(vel: Any, v_ref: Any) -> Any:
    """``(v_bound, u_bound)``: the largest speed of a body, and the largest relative to
    ``v_ref``, which is set to the middle of the velocities' bounding box (a heap sliding down a
    slope moves fast, but hardly relative to itself).

    >>> v_ref = np.zeros(3)
    >>> _velocity_bounds(np.array([[3.0, 0, 0], [5.0, 0, 0]]), v_ref), v_ref.tolist()
    ((5.0, 1.0), [4.0, 0.0, 0.0])
    """
    n = vel.shape[0]
    for k in range(3):
        low = math.inf
        high = -math.inf
        for i in range(n):
            low = min(low, vel[i, k])
            high = max(high, vel[i, k])
        v_ref[k] = 0.5 * (low + high) if n > 0 else 0.0
    v_bound = 0.0
    u_bound = 0.0
    for i in range(n):
        v_bound = max(v_bound, math.sqrt(vel[i, 0] ** 2 + vel[i, 1] ** 2 + vel[i, 2] ** 2))
        ux = vel[i, 0] - v_ref[0]
        uy = vel[i, 1] - v_ref[1]
        uz = vel[i, 2] - v_ref[2]
        u_bound = max(u_bound, math.sqrt(ux * ux + uy * uy + uz * uz))
    return v_bound, u_bound


def _speed_beyond(vel: Any, i: int, v_ref: Any, v_bound: float, u_bound: float) -> bool:
    """Whether body ``i`` is faster than ``v_bound``, or than ``u_bound`` relative to ``v_ref``."""
    ux = vel[i, 0] - v_ref[0]
    uy = vel[i, 1] - v_ref[1]
    uz = vel[i, 2] - v_ref[2]
    return bool(
        math.sqrt(vel[i, 0] ** 2 + vel[i, 1] ** 2 + vel[i, 2] ** 2) > v_bound
        or math.sqrt(ux * ux + uy * uy + uz * uz) > u_bound
    )


def _closing(a: int, elapsed: float, u_bound: float, v_bound: float, a_bound: float) -> float:
    """How much nearer than when listed a candidate pair (``a < 0``: a static's) can be
    ``elapsed`` later, its bodies within the bounds the candidates were listed for (phase 1)."""
    drift = 0.5 * a_bound * elapsed * elapsed
    if a >= 0:
        return 2.0 * (u_bound * elapsed + drift)
    return v_bound * elapsed + drift


def _remember(sep_ev: Any, sep_val: Any, c: int, ev: int, sep: Any) -> None:
    """Keep pair ``c``'s separation ``sep``, measured while event ``ev`` is resolved."""
    sep_ev[c] = ev
    for k in range(7):
        sep_val[c, k] = sep[k]


def _recalled(sep_val: Any, c: int) -> Any:
    """Pair ``c``'s separation kept by :func:`_remember`."""
    return (
        sep_val[c, 0], sep_val[c, 1], sep_val[c, 2], sep_val[c, 3], sep_val[c, 4], sep_val[c, 5], sep_val[c, 6]
    )  # fmt: skip


def _unchanged_since(seen: Any, changed: Any, c: int, a: int, b: int, start: int) -> bool:
    """Whether pair ``c`` (bodies ``a``, ``b``) was looked at since tick ``start`` and neither
    body changed since: :func:`_rest` would then return 0 again (it did, or the pair would
    rest or a body would have changed)."""
    if seen[c] < start or changed[b] >= seen[c]:
        return False
    return bool(a < 0 or changed[a] < seen[c])


def _base_acceleration(i: int, acc: Any, ima: Any, gravity: Any, nsup: Any) -> None:
    """Gravity for a body of finite mass, nothing for a kinematic one; no supports."""
    for k in range(3):
        acc[i, k] = gravity[k] if ima[i] > 0.0 else 0.0
    nsup[i] = 0


# --- the pairs in contact, remembered ------------------------------------------------------------
def _save_touching(
    ca: Any, cb: Any, ids: Any, n: int, count: int, touching: Any, near: Any, touch_keys: Any, touch_count: Any
) -> Any:
    """Remember the pairs in contact (touching and within the contact margin) across re-sorts, in
    no order (as :func:`~collisionlab.engine.step_kernels.run_steps`; looked up through a hash
    table, :func:`~collisionlab.engine.step_kernels._mark_touching`)."""
    if count > touch_keys.shape[0]:
        touch_keys = np.zeros(2 * count, np.int64)
    kept = 0
    for c in range(count):
        if touching[c] == 1 and near[c] == 1:
            touch_keys[kept] = sk._pair_key(ca, cb, ids, n, c)
            kept += 1
    touch_count[0] = kept
    return touch_keys


# --- the loop's phases, compiled without reference counts (NO_REFCOUNT) -----------------------
def _base_accelerations(acc: Any, ima: Any, gravity: Any, nsup: Any) -> None:
    """:func:`_base_acceleration` for every body."""
    for i in range(acc.shape[0]):
        _base_acceleration(i, acc, ima, gravity, nsup)


def _rest_passes(
    order: Any,
    n_near: int,
    seen: Any,
    changed_at: Any,
    ca: Any,
    cb: Any,
    normals: Any,
    kind: Any,
    vel: Any,
    ext: Any,
    ima: Any,
    acc: Any,
    sup: Any,
    nsup: Any,
    s_kind: Any,
    rest: Any,
    touching: Any,
    rest_speed: float,
    ledger: Any,
) -> None:
    """Phase 2's passes over the pairs in contact, in ``order`` (the first ``n_near``), until one
    changes nothing (a stack of k bodies settles in k passes). A pair is looked at again only once
    one of its bodies changed since (:func:`_rest` returns 0 again otherwise)."""
    n = vel.shape[0]
    for i in range(n):
        changed_at[i] = 0
    stamp = 0
    for _pass in range(n + 1):
        changed = False
        for u in range(n_near):
            c = order[u]
            if rest[c] == 1:
                continue
            a = ca[c]
            b = cb[c]
            if seen[c] > 0 and changed_at[b] < seen[c] and (a < 0 or changed_at[a] < seen[c]):
                continue
            stamp += 1
            seen[c] = stamp
            done = _rest(
                c, a, b, normals[c, 0], normals[c, 1], normals[c, 2], kind, vel, ext, ima, acc, sup, nsup, s_kind,
                rest, touching, rest_speed, ledger,
            )  # fmt: skip
            if done != 0:
                changed_at[b] = stamp
                if a >= 0:
                    changed_at[a] = stamp
                changed = changed or done == 1
        if not changed:
            break


def _outrun(acc: Any, vel: Any, v_ref: Any, v_bound: float, bound: Any, a_bound: float) -> Any:
    """Whether phase 2 left a body faster or more accelerated than the candidates were listed
    for (``bound[i]``: body ``i``'s speed relative to ``v_ref``), and the largest acceleration
    (at least ``a_bound``)."""
    grown = False
    for i in range(acc.shape[0]):
        size = math.sqrt(acc[i, 0] ** 2 + acc[i, 1] ** 2 + acc[i, 2] ** 2)
        if size > a_bound:
            a_bound = size
            grown = True
        if _speed_beyond(vel, i, v_ref, v_bound, bound[i]):
            grown = True
    return grown, a_bound


def _sweeps(
    vel: Any, v_ref: Any, u_bound: float, floor: float, remaining: float, drift: float, bound: Any, reach: Any
) -> None:
    """Each body's speed bound relative to ``v_ref`` for the listing (``SWEEP_GROWTH`` times its
    own, at least ``floor`` times ``u_bound``, the fastest's, at most that) in ``bound``, and how
    far it can move in that frame in the ``remaining`` time, ``bound T + drift``, in ``reach``:
    a pair of bodies is listed within the contact margin and both reaches.

    >>> bound, reach = np.zeros(2), np.zeros(2)
    >>> _sweeps(np.array([[0.5, 0, 0], [4.0, 0, 0]]), np.zeros(3), 4.0, 0.5, 0.5, 0.25, bound, reach)
    >>> bound.tolist(), reach.tolist()  # max(2 x 0.5, 2) = 2, min(8, 4) = 4; 2 x 0.5 + 0.25, 4 x 0.5 + 0.25
    ([2.0, 4.0], [1.25, 2.25])
    >>> _sweeps(np.array([[0.5, 0, 0], [4.0, 0, 0]]), np.zeros(3), 4.0, 1.0, 0.5, 0.25, bound, reach)
    >>> bound.tolist()  # floor 1: every body listed for the fastest's speed
    [4.0, 4.0]
    """
    for i in range(vel.shape[0]):
        ux = vel[i, 0] - v_ref[0]
        uy = vel[i, 1] - v_ref[1]
        uz = vel[i, 2] - v_ref[2]
        own = SWEEP_GROWTH * math.sqrt(ux * ux + uy * uy + uz * uz)
        bound[i] = min(u_bound, max(own, floor * u_bound))
        reach[i] = bound[i] * remaining + drift


def _predict_all(
    kind: Any,
    pos: Any,
    vel: Any,
    acc: Any,
    tau: Any,
    ext: Any,
    ima: Any,
    s_kind: Any,
    s_a: Any,
    s_b: Any,
    ca: Any,
    cb: Any,
    cd: Any,
    rest: Any,
    normals: Any,
    count: int,
    ht: Any,
    hk: Any,
    hv: Any,
    t: float,
    dt: float,
    gap: float,
    contact_margin: float,
) -> int:
    """Phase 3: push every moving candidate's first impact before ``dt`` (key ``c``) and every
    resting pair's expiry (key ``count + c``), version 0, onto the empty heap (it has room for
    both); returns its size."""
    size = 0
    for c in range(count):
        a = ca[c]
        b = cb[c]
        if rest[c] == 1 or (ima[b] == 0.0 and (a < 0 or ima[a] == 0.0)):
            continue
        when = _time_of_impact(kind, pos, vel, acc, tau, ext, s_kind, s_a, s_b, a, b, t, dt, gap, -cd[c])
        if when < dt:
            size = eh.heap_push(ht, hk, hv, size, when, c, 0)
    for c in range(count):
        if rest[c] == 1:
            when = t + _support_expiry(ca[c], cb[c], kind, vel, acc, ext, s_kind, normals, c, contact_margin)
            if when < dt:
                size = eh.heap_push(ht, hk, hv, size, when, count + c, 0)
    return size


def _impacts(
    kind: Any,
    pos: Any,
    vel: Any,
    acc: Any,
    tau: Any,
    ext: Any,
    ima: Any,
    eb: Any,
    ids: Any,
    s_kind: Any,
    s_a: Any,
    s_b: Any,
    s_e: Any,
    gravity: Any,
    ca: Any,
    cb: Any,
    cd: Any,
    count: int,
    adj_start: Any,
    adj: Any,
    rest: Any,
    touching: Any,
    ignored: Any,
    normals: Any,
    sup: Any,
    nsup: Any,
    ver: Any,
    ht: Any,
    hk: Any,
    hv: Any,
    size: int,
    sep_ev: Any,
    sep_val: Any,
    look_seen: Any,
    look_changed: Any,
    look_clock: int,
    kicked: Any,
    is_kicked: Any,
    queue: Any,
    queued: Any,
    before: Any,
    v_ref: Any,
    events: Any,
    event_count: Any,
    event_room: int,
    ledger: Any,
    status: Any,
    record: bool,
    step: int,
    start: float,
    t: float,
    dt: float,
    gap: float,
    e_default: float,
    contact_margin: float,
    rest_speed: float,
    resting_on: bool,
    u_bound: float,
    v_bound: float,
    a_bound: float,
    bound: Any,
    ev: int,
    impacts: int,
    runaway: bool,
) -> Any:
    """Phase 4 (the module docstring): pop the heap's impacts in time order and resolve them, until
    none is left before the step's end (``DONE``), a kick outran the candidates' bounds (``RESTART``:
    the bodies it looked at are at ``when``, the rest list again from there) or, before popping one,
    the events buffer has fewer than ``event_room`` rows free (``ROOM``: grow it and call again).
    Returns ``(code, size, ev, impacts, look_clock, runaway, when)``.

    Compiled without reference counts (``NO_REFCOUNT``): it allocates nothing, the heap has room
    for every push (``event_heap.heap_compact``) and the driver gives the events buffer room first."""
    n = pos.shape[0]
    restart = False
    while size > 0:
        if record and events.shape[0] - event_count[0] < event_room:
            return ROOM, size, ev, impacts, look_clock, runaway, 0.0
        when = ht[0]
        c = hk[0]
        version = hv[0]
        size = eh.heap_pop(ht, hk, hv, size)
        if version != ver[c]:
            continue
        ev += 1
        if when >= dt:
            break
        if impacts >= MAX_IMPACTS_PER_STEP:
            status[0] += 1
            break
        if runaway:
            # A kick left a body faster than the range simulated (e > 1 adds energy at
            # every impact): the step ends here and the world's range guard stops the
            # run, instead of thousands of impacts at speeds bound for inf.
            break
        impacts += 1
        expiry = c >= count
        # A pair listed farther apart than this cannot be in contact yet: the bounds the
        # candidates were listed for (kept, or the step is cut) limit how much nearer
        # it can be since (a separation changes no faster than the shapes move).
        reach_body = contact_margin + gap + _closing(0, when - t, u_bound, v_bound, a_bound)
        reach_static = contact_margin + gap + _closing(-1, when - t, u_bound, v_bound, a_bound)
        if expiry:
            c -= count
        a = ca[c]
        b = cb[c]
        if a >= 0:
            _advance(a, when, pos, vel, acc, tau, ima, gravity, ledger)
        _advance(b, when, pos, vel, acc, tau, ima, gravity, ledger)
        if expiry:
            # A sliding rest's support has turned (_support_expiry): no impulse; the gap
            # its straight flight opened is closed (the held body moved onto its holder,
            # as push-apart moves bodies: momentum kept, the energy in ledger[2]) and its
            # bodies are looked at again below, as kicked bodies are.
            sep = sk._contact_separation(kind, pos, ext, s_kind, s_a, s_b, a, b)
            if 0.0 < sep[0] <= contact_margin:
                held = b if a < 0 or ima[a] == 0.0 or nsup[a] > 0 else a
                sign = -1.0 if held == b else 1.0
                if ima[held] > 0.0:
                    for k in range(3):
                        pos[held, k] += sign * sep[1 + k] * sep[0]
                        ledger[2] -= sign * gravity[k] * sep[1 + k] * sep[0] / ima[held]  # -m g.dx
            below = True
            n_kicked = 0
            for r in range(2):
                i = a if r == 0 else b
                if i >= 0 and ima[i] > 0.0:
                    kicked[n_kicked] = i
                    n_kicked += 1
                    is_kicked[i] = 1
        else:
            sep = sk._contact_separation(kind, pos, ext, s_kind, s_a, s_b, a, b)
            _remember(sep_ev, sep_val, c, ev, sep)
            ver[c] += 1
            if sep[0] > contact_margin:  # the iteration's cap stopped short: look again from here
                again = _time_of_impact(kind, pos, vel, acc, tau, ext, s_kind, s_a, s_b, a, b, when, dt, gap, sep[0])
                if again < dt:
                    size = eh.heap_compact(ht, hk, hv, size, ver)
                    size = eh.heap_push(ht, hk, hv, size, again, c, ver[c])
                continue
            nx = sep[1]
            ny = sep[2]
            nz = sep[3]
            for k in range(3):
                before[k] = vel[a, k] if a >= 0 else 0.0
                before[3 + k] = vel[b, k]
            vn = (before[3] - before[0]) * nx + (before[4] - before[1]) * ny + (before[5] - before[2]) * nz
            id_a = ids[a] if a >= 0 else a
            if vn >= -_rounding_speed(before[0], before[1], before[2], before[3], before[4], before[5]):
                # it grazes away (or its approach is only rounding): nothing to resolve
                if record and touching[c] == 0:
                    sk._put_event(
                        events,
                        event_count[0],
                        sk.EVENT_SKIPPED,
                        step + 1,
                        start + when,
                        id_a,
                        ids[b],
                        sep,
                        vn,
                        0.0,
                        0.0,
                        before,
                        vel,
                        a,
                        b,
                    )
                    event_count[0] += 1
                ignored[c] = 1
                continue
            e_pair = sk._pair_e(eb[a] if a >= 0 else s_e[-1 - a], eb[b], e_default)
            # An approach no faster than falling twice the contact margin gives (a rest
            # within the margin whose flight left a curved support by up to half of it
            # more, _support_expiry) lands resting: e = 0 and no new event if in contact,
            # as Forward Euler's |g.n| dt rule. Physics unchanged: such a hop would rise
            # less than the margin.
            pressing = 0.0
            for k in range(3):
                pressing += (acc[b, k] - (acc[a, k] if a >= 0 else 0.0)) * sep[1 + k]
            below = -vn < rest_speed + math.sqrt(4.0 * max(0.0, -pressing) * contact_margin)
            e = 0.0 if below else e_pair
            j = _kick(a, b, nx, ny, nz, vn, e, vel, ima, sup, nsup, ledger, True)
            status[1] += 1
            for k in range(3):  # (not <=: NaN too)
                if not abs(vel[b, k]) <= MAX_RUN_SPEED or (a >= 0 and not abs(vel[a, k]) <= MAX_RUN_SPEED):
                    runaway = True
            if record and (touching[c] == 0 or not below):
                sk._put_event(
                    events,
                    event_count[0],
                    sk.EVENT_BELOW_REST if below else sk.EVENT_IMPACT,
                    step + 1,
                    start + when,
                    id_a,
                    ids[b],
                    sep,
                    vn,
                    j,
                    e,
                    before,
                    vel,
                    a,
                    b,
                )
                event_count[0] += 1
            touching[c] = 1
            if -vn < rest_speed:
                ignored[c] = 1  # a touch too slow to bounce: in contact until the step ends
            # Settle the contacts this impact touches (sequential impulses, breadth first).
            n_kicked = 0
            head = 0
            tail = 0
            for r in range(2):
                i = a if r == 0 else b
                if i >= 0 and ima[i] > 0.0:
                    queue[tail % n] = i
                    tail += 1
                    queued[i] = 1
                    kicked[n_kicked] = i
                    n_kicked += 1
                    is_kicked[i] = 1
            settled = 0
            while head < tail and settled < RELAX_IMPULSES:
                i = queue[head % n]
                head += 1
                queued[i] = 0
                for u in range(adj_start[i], adj_start[i + 1]):
                    c2 = adj[u]
                    a2 = ca[c2]
                    b2 = cb[c2]
                    if -cd[c2] > (reach_body if a2 >= 0 else reach_static):
                        continue  # too far apart when listed to be in contact yet
                    other = b2 if a2 == i else a2
                    if sep_ev[c2] == ev:
                        sep2 = _recalled(sep_val, c2)
                    else:
                        if other >= 0:
                            _advance(other, when, pos, vel, acc, tau, ima, gravity, ledger)
                        sep2 = sk._contact_separation(kind, pos, ext, s_kind, s_a, s_b, a2, b2)
                        _remember(sep_ev, sep_val, c2, ev, sep2)
                    if sep2[0] > contact_margin:
                        continue
                    for k in range(3):
                        before[k] = vel[a2, k] if a2 >= 0 else 0.0
                        before[3 + k] = vel[b2, k]
                    vn2 = (
                        (before[3] - before[0]) * sep2[1]
                        + (before[4] - before[1]) * sep2[2]
                        + (before[5] - before[2]) * sep2[3]
                    )
                    still = _rounding_speed(before[0], before[1], before[2], before[3], before[4], before[5])
                    if vn2 >= -still:
                        continue
                    if sep2[0] > gap:
                        # An approach too slow to close the gap (to TOI_GAP) before the step
                        # ends is left alone: it cannot touch in this step (the gap along n
                        # bounds the distance, as in phase 3), and its pair is predicted
                        # again with the kicked bodies' pairs.
                        an = 0.0
                        for k in range(3):
                            an += (acc[b2, k] - (acc[a2, k] if a2 >= 0 else 0.0)) * sep2[1 + k]
                        if gk.first_root(sep2[0] - gap, vn2, 0.5 * an, dt - when) == math.inf:
                            continue
                    e2_pair = sk._pair_e(eb[a2] if a2 >= 0 else s_e[-1 - a2], eb[b2], e_default)
                    e_2 = 0.0 if -vn2 < rest_speed else e2_pair
                    j2 = _kick(a2, b2, sep2[1], sep2[2], sep2[3], vn2, e_2, vel, ima, sup, nsup, ledger, True)
                    if j2 == 0.0:
                        continue
                    settled += 1
                    status[1] += 1
                    if record and touching[c2] == 0:
                        sk._put_event(
                            events,
                            event_count[0],
                            sk.EVENT_BELOW_REST if -vn2 < rest_speed else sk.EVENT_IMPACT,
                            step + 1,
                            start + when,
                            ids[a2] if a2 >= 0 else a2,
                            ids[b2],
                            sep2,
                            vn2,
                            j2,
                            e_2,
                            before,
                            vel,
                            a2,
                            b2,
                        )
                        event_count[0] += 1
                    touching[c2] = 1
                    for r in range(2):
                        i2 = a2 if r == 0 else b2
                        if i2 < 0 or ima[i2] == 0.0:
                            continue
                        if is_kicked[i2] == 0:
                            is_kicked[i2] = 1
                            kicked[n_kicked] = i2
                            n_kicked += 1
                        if queued[i2] == 0 and tail - head < n:
                            queue[tail % n] = i2
                            tail += 1
                            queued[i2] = 1
            for q in range(head, tail):
                queued[queue[q % n]] = 0
        # A kicked body that rested may lift off, and what rested on it with it: look at
        # them again (their resting pairs are dropped, then found again on what holds).
        n_look = n_kicked
        for q in range(n_kicked):
            i = kicked[q]
            for u in range(adj_start[i], adj_start[i + 1]):
                c2 = adj[u]
                if rest[c2] == 0:
                    continue
                rest[c2] = 0
                ver[count + c2] += 1  # its expiry, if any, with it
                other = cb[c2] if ca[c2] == i else ca[c2]
                if other >= 0 and ima[other] > 0.0 and is_kicked[other] == 0:
                    _advance(other, when, pos, vel, acc, tau, ima, gravity, ledger)
                    is_kicked[other] = 1
                    kicked[n_look] = other
                    n_look += 1
        for q in range(n_look):
            i = kicked[q]
            _advance(i, when, pos, vel, acc, tau, ima, gravity, ledger)
            _base_acceleration(i, acc, ima, gravity, nsup)
        if resting_on:  # on what holds: a static, a kinematic body, a supported body
            look_start = look_clock + 1
            for _pass in range(MAX_SUPPORTS):
                changed = False
                for q in range(n_look):
                    i = kicked[q]
                    for u in range(adj_start[i], adj_start[i + 1]):
                        c2 = adj[u]
                        a2 = ca[c2]
                        b2 = cb[c2]
                        other = b2 if a2 == i else a2
                        if rest[c2] == 1 or (other >= 0 and ima[other] > 0.0 and nsup[other] == 0):
                            continue
                        if -cd[c2] > (reach_body if a2 >= 0 else reach_static):
                            continue
                        if _unchanged_since(look_seen, look_changed, c2, a2, b2, look_start):
                            continue  # looked at in this look already, its bodies unchanged: 0 again
                        look_clock += 1
                        look_seen[c2] = look_clock
                        if sep_ev[c2] == ev:
                            sep2 = _recalled(sep_val, c2)
                        else:
                            if other >= 0:
                                _advance(other, when, pos, vel, acc, tau, ima, gravity, ledger)
                            sep2 = sk._contact_separation(kind, pos, ext, s_kind, s_a, s_b, a2, b2)
                            _remember(sep_ev, sep_val, c2, ev, sep2)
                        if sep2[0] > contact_margin:
                            continue
                        done = _rest(
                            c2,
                            a2,
                            b2,
                            sep2[1],
                            sep2[2],
                            sep2[3],
                            kind,
                            vel,
                            ext,
                            ima,
                            acc,
                            sup,
                            nsup,
                            s_kind,
                            rest,
                            touching,
                            rest_speed,
                            ledger,
                        )
                        if done != 0:
                            look_changed[b2] = look_clock
                            if a2 >= 0:
                                look_changed[a2] = look_clock
                        if done == 1:
                            changed = True
                            for k in range(3):
                                normals[c2, k] = sep2[1 + k]
                if not changed:
                    break
            for q in range(n_look):  # the new rests' expiries
                i = kicked[q]
                for u in range(adj_start[i], adj_start[i + 1]):
                    c2 = adj[u]
                    if rest[c2] == 0:
                        continue
                    ver[count + c2] += 1
                    later = when + _support_expiry(
                        ca[c2], cb[c2], kind, vel, acc, ext, s_kind, normals, c2, contact_margin
                    )
                    if later < dt:
                        size = eh.heap_compact(ht, hk, hv, size, ver)
                        size = eh.heap_push(ht, hk, hv, size, later, count + c2, ver[count + c2])
        for q in range(n_look):
            grown_by = a_bound * (when - t)
            if _speed_beyond(vel, kicked[q], v_ref, v_bound + grown_by, bound[kicked[q]] + grown_by):
                restart = True
        if restart:
            for q in range(n_look):
                is_kicked[kicked[q]] = 0
            return RESTART, size, ev, impacts, look_clock, runaway, when
        # Predict the looked-at bodies' pairs again.
        for q in range(n_look):
            i = kicked[q]
            for u in range(adj_start[i], adj_start[i + 1]):
                c2 = adj[u]
                if c2 != c and not below:
                    ignored[c2] = 0
                a2 = ca[c2]
                b2 = cb[c2]
                ver[c2] += 1
                if rest[c2] == 1 or ignored[c2] == 1:
                    continue
                if ima[b2] == 0.0 and (a2 < 0 or ima[a2] == 0.0):
                    continue
                floor = -cd[c2] - _closing(a2, when - t, u_bound, v_bound, a_bound)
                if sep_ev[c2] == ev:
                    floor = max(floor, sep_val[c2, 0])
                again = _time_of_impact(kind, pos, vel, acc, tau, ext, s_kind, s_a, s_b, a2, b2, when, dt, gap, floor)
                if again < dt:
                    size = eh.heap_compact(ht, hk, hv, size, ver)
                    size = eh.heap_push(ht, hk, hv, size, again, c2, ver[c2])
        for q in range(n_look):
            is_kicked[kicked[q]] = 0
    return DONE, size, ev, impacts, look_clock, runaway, dt


def _end_separations(
    kind: Any,
    pos: Any,
    ext: Any,
    s_kind: Any,
    s_a: Any,
    s_b: Any,
    ca: Any,
    cb: Any,
    cd: Any,
    cn: Any,
    count: int,
    near_idx: Any,
    elapsed: float,
    u_bound: float,
    v_bound: float,
    a_bound: float,
    contact_margin: float,
    gap: float,
    solver_margin: float,
) -> Any:
    """Phase 5's look at every candidate, its bodies at the step's end (``elapsed`` after the
    listing): ``cd`` gets its depth (or a bound on it, enough for a pair neither pushed apart nor
    in contact) and ``cn`` its normal; ``near_idx`` gets the pairs push-apart looks at, in their
    order. Returns how many, and whether any overlaps."""
    n_push = 0
    overlap = False
    for c in range(count):
        closing = _closing(ca[c], elapsed, u_bound, v_bound, a_bound)
        if -cd[c] - closing > contact_margin + gap:
            cd[c] -= closing  # a bound is enough: neither pushed apart nor in contact
            continue
        sep = sk._contact_separation(kind, pos, ext, s_kind, s_a, s_b, ca[c], cb[c])
        cd[c] = -sep[0]
        for k in range(3):  # push-apart's first look at the pair, until a body moves
            cn[c, k] = sep[1 + k]
        if cd[c] >= -solver_margin:  # the pairs push-apart looks at, in its order
            near_idx[n_push] = c
            n_push += 1
            overlap = overlap or cd[c] > 0.0
    return n_push, overlap


# --- the loop -----------------------------------------------------------------------------------
def run_exact_steps(
    kind: Any,
    pos: Any,
    vel: Any,
    ext: Any,
    ima: Any,
    eb: Any,
    ids: Any,
    scratch_f: Any,
    scratch_i: Any,
    cell_start: Any,
    dest: Any,
    stencil: Any,
    s_kind: Any,
    s_a: Any,
    s_b: Any,
    s_e: Any,
    gravity: Any,
    dims: int,
    dt: float,
    e_default: float,
    slop: float,
    solver_margin: float,
    contact_margin: float,
    rest_speed: float,
    passes: int,
    min_cell: float,
    gap: float,
    first_step: int,
    steps: int,
    record: bool,
    touch_keys: Any,
    touch_count: Any,
    ca: Any,
    cb: Any,
    cd: Any,
    events: Any,
    event_count: Any,
    ledger: Any,
    status: Any,
) -> Any:
    """Advance ``steps`` exact steps in place (the module docstring's order); arguments as
    :func:`~collisionlab.engine.step_kernels.run_steps`, plus ``gap`` (``TOI_GAP``) and
    ``status`` (``STATUS_SIZE`` counters). Returns ``(touch_keys, ca, cb, cd, events)``."""
    n = pos.shape[0]
    max_cells = cell_start.shape[0] - 2
    lo = np.zeros(3)
    shape = np.zeros(3, np.int64)
    acc = np.zeros((n, 3))
    tau = np.zeros(n)
    sup = np.zeros((n, MAX_SUPPORTS, 3))
    nsup = np.zeros(n, np.int64)
    before = np.zeros(6)
    queue = np.zeros(n, np.int64)
    queued = np.zeros(n, np.int8)
    kicked = np.zeros(n, np.int64)
    is_kicked = np.zeros(n, np.int8)
    changed_at = np.zeros(n, np.int64)
    degree = np.zeros(n, np.int64)  # _order_coupled's count of contacts per body
    # Separations measured at the time of the event being resolved (number sep_ev[c], below
    # every later event's number, so the rows are kept from listing to listing): the positions
    # stay while it is (an impulse changes velocities only).
    sep_ev = np.zeros(0, np.int64)
    sep_val = np.zeros((0, 7))
    # When the look again at kicked bodies' rests last looked at a pair (look_seen) and last
    # changed a body (look_changed), on one clock (look_clock): _unchanged_since.
    look_seen = np.zeros(0, np.int64)
    look_changed = np.zeros(n, np.int64)
    look_clock = sk._int(0)
    near_idx = np.zeros(0, np.int64)
    seen = np.zeros(0, np.int64)
    g_size = math.sqrt(gravity[0] ** 2 + gravity[1] ** 2 + gravity[2] ** 2)
    resting_on = g_size > 0.0
    ht = np.zeros(64)
    hk = np.zeros(64, np.int64)
    hv = np.zeros(64, np.int64)
    width = sk._grid_width(ext, dims)  # the widest body in the grid; wider ones are met apart
    key_of = np.zeros(n, np.int64)
    cell_key = np.zeros(n, np.int64)
    hashed = np.zeros(0, np.int64)  # a hashed grid's buckets, held while this call runs
    ev = sk._int(0)  # the events resolved so far (the separations' memory)
    v_ref = np.zeros(3)  # the frame the candidates' sweep is measured in (_velocity_bounds)
    table = np.zeros(16, np.int64)  # a hash table of the pairs in contact (_mark_touching)
    # Each candidate's unit normal where it was listed (phase 2 reads it), then where the step
    # ended (push-apart's first look); rows as ca.
    cn = np.zeros((ca.shape[0], 3))
    looked = np.zeros(0, np.int64)  # when push-apart last looked at a pair (_push_sweep)
    moved = np.zeros(n, np.int64)  # when push-apart last moved a body
    push_clock = sk._int(0)
    bound = np.zeros(n)  # each body's speed bound for the listing, relative to v_ref (_sweeps)
    reach = np.zeros(n)  # how far that lets it move in the rest of the step
    for step in range(first_step, first_step + steps):
        start = step * dt
        t = 0.0
        impacts = sk._int(0)
        runaway = sk._bool(False)
        for i in range(n):
            tau[i] = 0.0
        count = 0
        touching = np.zeros(0, np.int8)
        floor = SWEEP_FLOOR if step >= status[3] else 1.0  # each body its own sweep, or the fastest's
        while True:  # one pass per listing of the candidates (more than one if a kick outran them)
            remaining = dt - t
            a_bound = ACCELERATION_HEADROOM * g_size
            v_bound = 0.0
            u_bound = 0.0
            rest = np.zeros(0, np.int8)
            ignored = np.zeros(0, np.int8)
            normals = np.zeros((0, 3))
            for _attempt in range(8):
                v_bound, u_bound = _velocity_bounds(vel, v_ref)
                drift = 0.5 * a_bound * remaining * remaining
                # Two bodies close by at most twice (u_bound T + a_bound T^2 / 2): each moves
                # that far relative to v_ref (a frame that does not accelerate); a body moves at
                # most v_bound T + a_bound T^2 / 2 towards a static.
                margin = contact_margin + 2.0 * (u_bound * remaining + drift)
                static_margin = contact_margin + v_bound * remaining + drift
                # The grid of the Forward Euler stepper: cells as wide as the bodies the grid
                # holds (all but the widest few, which meet it apart) plus the margin, hashed
                # into buckets when there would be too many.
                cell = width + margin if width + margin > 0.0 else min_cell
                h, buckets = sk._grid_plan(pos, ext, dims, width, cell, max_cells, lo, shape)
                if buckets > 0 and hashed.shape[0] < buckets + 3:
                    hashed = np.zeros(buckets + 3, np.int64)
                starts = hashed if buckets > 0 else cell_start
                n_small = sk._bucket_sort(pos, ext, dims, lo, h, shape, width, buckets, starts, dest, key_of, cell_key)
                sk._store_in_cell_order(kind, pos, vel, ext, ima, eb, ids, scratch_f, scratch_i, dest)
                _sweeps(vel, v_ref, u_bound, floor, remaining, drift, bound, reach)  # in the bodies' new order
                while True:  # listed again, into arrays twice as large, when they were too small
                    count = sk._find_pairs(
                        kind, pos, ext, ids, s_kind, s_a, s_b, dims, lo, h, shape, buckets, n_small, starts,
                        stencil, cell_key, ca, cb, cd, cn, margin, static_margin, reach, contact_margin,
                    )  # fmt: skip
                    if count <= ca.shape[0]:
                        break
                    ca = np.zeros(2 * count, np.int64)
                    cb = np.zeros(2 * count, np.int64)
                    cd = np.zeros(2 * count)
                    cn = np.zeros((2 * count, 3))
                # Phase 2: resting contacts and the accelerations they leave.
                _base_accelerations(acc, ima, gravity, nsup)
                touching = np.zeros(count, np.int8)
                rest = np.zeros(count, np.int8)
                ignored = np.zeros(count, np.int8)
                normals = cn  # as listed: the positions have not changed since
                while table.shape[0] < 2 * touch_count[0]:
                    table = np.zeros(2 * table.shape[0], np.int64)
                sk._mark_touching(touch_keys, touch_count[0], table, ca, cb, ids, n, count, touching)
                if resting_on:
                    # Only pairs in contact can rest: order those alone. A pair is looked at again
                    # only once one of its bodies changed since (_rest returns 0 again otherwise).
                    if near_idx.shape[0] < count:
                        near_idx = np.zeros(2 * count, np.int64)
                        seen = np.zeros(2 * count, np.int64)
                    n_near = sk._int(0)
                    for c in range(count):
                        if -cd[c] <= contact_margin:
                            near_idx[n_near] = c
                            n_near += 1
                            seen[c] = 0
                    order = sk._order_coupled(pos, ca, cb, cd, near_idx, n_near, degree)
                    _rest_passes(
                        order, n_near, seen, changed_at, ca, cb, normals, kind, vel, ext, ima, acc, sup, nsup, s_kind,
                        rest, touching, rest_speed, ledger,
                    )  # fmt: skip
                grown, a_bound = _outrun(acc, vel, v_ref, v_bound, bound, a_bound)
                if not grown:
                    break
            # Each body's candidate pairs (CSR).
            adj_start = np.zeros(n + 1, np.int64)
            for c in range(count):
                if ca[c] >= 0:
                    adj_start[ca[c] + 1] += 1
                adj_start[cb[c] + 1] += 1
            max_degree = 0
            for i in range(n):
                max_degree = max(max_degree, adj_start[i + 1])
                adj_start[i + 1] += adj_start[i]
            fill = adj_start[:n].copy()
            adj = np.zeros(max(1, adj_start[n]), np.int64)
            for c in range(count):
                if ca[c] >= 0:
                    adj[fill[ca[c]]] = c
                    fill[ca[c]] += 1
                adj[fill[cb[c]]] = c
                fill[cb[c]] += 1
            # Phase 3: every candidate's first impact.
            ver = np.zeros(2 * count, np.int64)  # a pair's prediction, then (count + c) its rest's expiry
            if sep_ev.shape[0] < count:
                sep_ev = np.full(2 * count, -1, np.int64)
                sep_val = np.empty((2 * count, 7))
                look_seen = np.zeros(2 * count, np.int64)
            if ht.shape[0] < HEAP_ROOM * count + 2:  # (event_heap.heap_compact); empty here: nothing to copy
                room = max(2 * ht.shape[0], HEAP_ROOM * count + 2)
                ht = np.zeros(room)
                hk = np.zeros(room, np.int64)
                hv = np.zeros(room, np.int64)
            size = _predict_all(
                kind, pos, vel, acc, tau, ext, ima, s_kind, s_a, s_b, ca, cb, cd, rest, normals, count, ht, hk, hv,
                t, dt, gap, contact_margin,
            )  # fmt: skip
            # Phase 4: impacts in time order.
            event_room = 1 + min(count, RELAX_IMPULSES + max_degree)  # the most rows one impact writes
            while True:
                if record:
                    events = sk._events_with_room(events, event_count[0], event_room)
                code, size, ev, impacts, look_clock, runaway, when = _impacts(
                    kind, pos, vel, acc, tau, ext, ima, eb, ids, s_kind, s_a, s_b, s_e, gravity, ca, cb, cd, count,
                    adj_start, adj, rest, touching, ignored, normals, sup, nsup, ver, ht, hk, hv, size, sep_ev,
                    sep_val, look_seen, look_changed, look_clock, kicked, is_kicked, queue, queued, before, v_ref,
                    events, event_count, event_room, ledger, status, record, step, start, t, dt, gap, e_default,
                    contact_margin, rest_speed, resting_on, u_bound, v_bound, a_bound, bound, ev, impacts, runaway,
                )  # fmt: skip
                if code != ROOM:
                    break
            restart = code == RESTART
            if restart:  # list the candidates again from the time the bounds were outrun
                _advance_all(when, pos, vel, acc, tau, ima, gravity, ledger)
                near = np.zeros(count, np.int8)
                for c2 in range(count):
                    sep2 = sk._contact_separation(kind, pos, ext, s_kind, s_a, s_b, ca[c2], cb[c2])
                    near[c2] = 1 if sep2[0] <= contact_margin else 0
                touch_keys = _save_touching(ca, cb, ids, n, count, touching, near, touch_keys, touch_count)
                t = when
                status[2] += 1
                if floor < 1.0:  # the fastest's sweep for the rest of this step and SWEEP_PAUSE more
                    floor = 1.0
                    status[3] = step + 1 + SWEEP_PAUSE
            if not restart:
                break
        # Phase 5: the end of the step.
        _advance_all(dt, pos, vel, acc, tau, ima, gravity, ledger)
        if near_idx.shape[0] < count:
            near_idx = np.zeros(2 * count, np.int64)
            seen = np.zeros(2 * count, np.int64)
        if looked.shape[0] < count:
            looked = np.zeros(2 * count, np.int64)
        n_push, overlap = _end_separations(
            kind, pos, ext, s_kind, s_a, s_b, ca, cb, cd, cn, count, near_idx, dt - t, u_bound, v_bound, a_bound,
            contact_margin, gap, solver_margin,
        )  # fmt: skip
        # Push-apart moves only overlapping pairs (the others only once a push makes them
        # overlap): with none, its first pass would move nothing, so neither it nor its order
        # is needed.
        if overlap:
            order = sk._order_coupled(pos, ca, cb, cd, near_idx, n_push, degree)
            found = push_clock  # every earlier tick is below it
            for p in range(passes):
                moves = sk._push_sweep(
                    kind, pos, ext, ima, s_kind, s_a, s_b, ca, cb, cd, cn, order, looked, moved, found,
                    found + 1 + p * n_push, p == 0, gravity, slop, solver_margin, ledger,
                )  # fmt: skip
                if moves == 0:
                    break
            push_clock = found + 1 + passes * n_push
        sk._clamp_to_walls(kind, pos, ext, ima, s_kind, s_a, s_b, ca, cb, count, gravity, slop, ledger)
        near = np.zeros(count, np.int8)
        for c in range(count):
            # a resting pair is in contact even where its flight past a curved support opened
            # its gap a little beyond the margin (_support_expiry)
            near[c] = 1 if -cd[c] <= contact_margin or (c < rest.shape[0] and rest[c] == 1) else 0
        touch_keys = _save_touching(ca, cb, ids, n, count, touching, near, touch_keys, touch_count)
    return touch_keys, ca, cb, cd, events
