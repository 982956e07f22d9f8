"""The exact stepper's impacts, earliest first (phases 3 and 4 of :mod:`.exact_kernels`): every
candidate pair's time of impact (:mod:`.pair_time_of_impact`) and every rest's expiry
(:mod:`.exact_rest`) pushed onto a binary heap (:mod:`.event_heap`, lazy invalidation: each
pair's prediction carries a version, a kicked body's pairs get new ones), then popped in time
order. At each impact the two bodies are brought to its time (:mod:`.exact_flight`), the impulse
is applied (:mod:`.exact_impulses`; ``e = 0`` below ``rest_speed``), what it touches is settled
(:mod:`.exact_settle`: the contacts it drives together, the rests of the bodies it kicked) and
the kicked bodies' pairs are predicted again. A kick past the bounds the candidates were listed
for (:mod:`.exact_sweeps`) cuts the step there (``RESTART``).

Owns ``MAX_IMPACTS_PER_STEP``, ``HEAP_ROOM``, what the phase returns with (``DONE``,
``RESTART``, ``ROOM``), the predictions (:func:`_predict_all`) and the impacts (:func:`_impacts`).
It imports the other exact files and the kernels they call; it must not import the loop
(:mod:`.exact_kernels`), which calls it.
"""

from __future__ import annotations

import math
from typing import Any

from ..tolerances import MAX_RUN_SPEED

if "_EVENT_ROWS" in globals():  # the compiled copy: the kernels it calls are compiled too
    cl: Any = globals()["_CONTACT_LAW"]
    evr: Any = globals()["_EVENT_ROWS"]
    ps: Any = globals()["_PAIR_SEPARATION"]
    eh: Any = globals()["_HEAP"]
    ef: Any = globals()["_EXACT_FLIGHT"]
    et: Any = globals()["_PAIR_TIME_OF_IMPACT"]
    ej: Any = globals()["_EXACT_IMPULSES"]
    er: Any = globals()["_EXACT_REST"]
    es: Any = globals()["_EXACT_SWEEPS"]
    st: Any = globals()["_EXACT_SETTLE"]
else:
    from . import contact_law as cl
    from . import event_heap as eh
    from . import event_rows as evr
    from . import exact_flight as ef
    from . import exact_impulses as ej
    from . import exact_rest as er
    from . import exact_settle as st
    from . import exact_sweeps as es
    from . import pair_separation as ps
    from . import pair_time_of_impact as et

#: The most impacts resolved within one step; past it the step ends without the rest (a guard
#: against an endless run of impacts; the world warns, ``status[0]`` counts such steps).
MAX_IMPACTS_PER_STEP = 100_000
#: The heap has room for this many entries per candidate pair (and 2 more): twice the most that
#: can be current (a pair's prediction and its rest's expiry), so a full heap compacts to at most
#: half (:func:`~collisionlab.engine.event_heap.heap_compact`) and no push inside phase 4 allocates.
HEAP_ROOM = 4
#: What :func:`_impacts` returns with: no impact left before the step's end; a kick outran the
#: candidates' bounds (list them again); the events buffer needs room before the next impact.
DONE = 0
RESTART = 1
ROOM = 2

#: The loop's phases here that allocate nothing, compiled without numba's reference counts
#: (:mod:`.compiled`).
NO_REFCOUNT = (
    "_predict_all",
    "_impacts",
)


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
        when = et._time_of_impact(kind, pos, vel, acc, tau, ext, s_kind, s_a, s_b, a, b, t, dt, gap, -cd[c], -math.inf)
        if when < dt:
            size = eh.heap_push(ht, hk, hv, size, when, c, 0)
    for c in range(count):
        if rest[c] == 1:
            when = t + er._support_expiry(ca[c], cb[c], kind, vel, acc, ext, s_kind, normals, c, contact_margin)
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
        reach_body = contact_margin + gap + es._closing(0, when - t, u_bound, v_bound, a_bound)
        reach_static = contact_margin + gap + es._closing(-1, when - t, u_bound, v_bound, a_bound)
        if expiry:
            c -= count
        a = ca[c]
        b = cb[c]
        if a >= 0:
            ef._advance(a, when, pos, vel, acc, tau, ima, gravity, ledger)
        ef._advance(b, when, pos, vel, acc, tau, ima, gravity, ledger)
        sep = ps._contact_separation(kind, pos, ext, s_kind, s_a, s_b, a, b)
        if expiry:
            # A sliding rest's support has turned (er._support_expiry): no impulse; the gap
            # its straight flight opened is closed (the held body moved onto its holder,
            # as push-apart moves bodies: momentum kept, the energy in ledger[2]) and its
            # bodies are looked at again below, as kicked bodies are.
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
            st._remember(sep_ev, sep_val, c, ev, sep)
            ver[c] += 1
            if sep[0] > contact_margin:  # the iteration's cap stopped short: look again from here
                again = et._time_of_impact(
                    kind, pos, vel, acc, tau, ext, s_kind, s_a, s_b, a, b, when, dt, gap, sep[0], -math.inf
                )
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
            if vn >= -et._rounding_speed(before[0], before[1], before[2], before[3], before[4], before[5]):
                # it grazes away (or its approach is only rounding): nothing to resolve
                if record and touching[c] == 0:
                    evr._put_event(
                        events,
                        event_count[0],
                        evr.EVENT_SKIPPED,
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
            e_pair = ps._pair_e(eb[a] if a >= 0 else s_e[-1 - a], eb[b], e_default)
            # An approach no faster than falling twice the contact margin gives (a rest
            # within the margin whose flight left a curved support by up to half of it
            # more, er._support_expiry) lands resting: e = 0 and no new event if in contact,
            # as Forward Euler's |g.n| dt rule. Physics unchanged: such a hop would rise
            # less than the margin.
            pressing = 0.0
            for k in range(3):
                pressing += (acc[b, k] - (acc[a, k] if a >= 0 else 0.0)) * sep[1 + k]
            threshold = rest_speed + math.sqrt(4.0 * max(0.0, -pressing) * contact_margin)
            below = not cl.is_impact(vn, threshold)
            e = cl.applied_restitution(vn, e_pair, threshold)
            j = ej._kick(a, b, nx, ny, nz, vn, e, vel, ima, sup, nsup, ledger, True)
            status[1] += 1
            for k in range(3):  # (not <=: NaN too)
                if not abs(vel[b, k]) <= MAX_RUN_SPEED or (a >= 0 and not abs(vel[a, k]) <= MAX_RUN_SPEED):
                    runaway = True
            if record and (touching[c] == 0 or not below):
                evr._put_event(
                    events,
                    event_count[0],
                    evr.EVENT_BELOW_REST if below else evr.EVENT_IMPACT,
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
            if not cl.is_impact(vn, rest_speed):
                ignored[c] = 1  # a touch too slow to bounce: in contact until the step ends
            # Settle the contacts this impact touches (sequential impulses, breadth first).
            n_kicked = st._settle(
                a, b, kind, pos, vel, acc, tau, ext, ima, eb, ids, s_kind, s_a, s_b, s_e, gravity, ca, cb, cd,
                adj_start, adj, touching, sup, nsup, sep_ev, sep_val, kicked, is_kicked, queue, queued, before,
                events, event_count, ledger, status, record, step, start, when, dt, gap, e_default, contact_margin,
                rest_speed, reach_body, reach_static, ev,
            )  # fmt: skip
        # A kicked body that rested may lift off, and what rested on it with it: look at
        # them again (their resting pairs are dropped, then found again on what holds).
        n_look, look_clock, size = st._rest_again(
            n_kicked, kind, pos, vel, acc, tau, ext, ima, s_kind, s_a, s_b, gravity, ca, cb, cd, count, adj_start,
            adj, rest, touching, normals, sup, nsup, ver, ht, hk, hv, size, sep_ev, sep_val, look_seen,
            look_changed, look_clock, kicked, is_kicked, ledger, when, dt, contact_margin, rest_speed, resting_on,
            reach_body, reach_static, ev,
        )  # fmt: skip
        for q in range(n_look):
            grown_by = a_bound * (when - t)
            if es._speed_beyond(vel, kicked[q], v_ref, v_bound + grown_by, bound[kicked[q]] + grown_by):
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
                floor = -cd[c2] - es._closing(a2, when - t, u_bound, v_bound, a_bound)
                if sep_ev[c2] == ev:
                    floor = max(floor, sep_val[c2, 0])
                again = et._time_of_impact(
                    kind, pos, vel, acc, tau, ext, s_kind, s_a, s_b, a2, b2, when, dt, gap, floor, -math.inf
                )
                if again < dt:
                    size = eh.heap_compact(ht, hk, hv, size, ver)
                    size = eh.heap_push(ht, hk, hv, size, again, c2, ver[c2])
        for q in range(n_look):
            is_kicked[kicked[q]] = 0
    return DONE, size, ev, impacts, look_clock, runaway, dt
