"""What an impact touches, settled at its time (phase 4 of :mod:`.exact_kernels`, after each kick
of :func:`.exact_impacts._impacts`). The contacts of the kicked bodies that now approach fast
enough to close their gap (to ``TOI_GAP``) before the step ends, their gap along the normal
``d + v_n t + a_n t^2 / 2`` reaching it within the ``T`` left, take sequential impulses, breadth
first: a row of touching balls passes the impact along. A slower approach cannot touch within the
step and is left to the predictions and to the next step's rests. Then the kicked bodies' rests
are looked at again: a kicked body that rested may lift off, and what rested on it with it (their
resting pairs are dropped, then found again on what holds, with their expiries).

Owns ``RELAX_IMPULSES``, the settling (:func:`_settle`), the look again at rests
(:func:`_rest_again`) and the separations measured at the time of the event being resolved
(:func:`_remember`, :func:`_recalled`: the positions stay while it is resolved, an impulse
changes velocities only). It imports the flight, the rounding speed of
:mod:`.pair_time_of_impact`, the impulses, the rests, the event heap and the kernels they call;
it must not import :mod:`.exact_impacts` or the loop, which call it.
"""

from __future__ import annotations

import math
from typing import Any

if "_GEOMETRY" in globals():  # the compiled copy: the kernels it calls are compiled too
    cl: Any = globals()["_CONTACT_LAW"]
    gk: Any = globals()["_GEOMETRY"]
    evr: Any = globals()["_EVENT_ROWS"]
    ps: Any = globals()["_PAIR_SEPARATION"]
    eh: Any = globals()["_HEAP"]
    ef: Any = globals()["_EXACT_FLIGHT"]
    et: Any = globals()["_PAIR_TIME_OF_IMPACT"]
    ej: Any = globals()["_EXACT_IMPULSES"]
    er: Any = globals()["_EXACT_REST"]
else:
    from . import contact_law as cl
    from . import event_heap as eh
    from . import event_rows as evr
    from . import exact_flight as ef
    from . import exact_impulses as ej
    from . import exact_rest as er
    from . import geometry_kernels as gk
    from . import pair_separation as ps
    from . import pair_time_of_impact as et

#: The most impulses that settle the contacts one impact touches (a row of k balls needs k).
RELAX_IMPULSES = 4096

#: Helpers the compiled form inlines into their callers (:mod:`.compiled`): small, called for
#: every pair looked at.
INLINE = ("_remember", "_recalled")

#: The impacts' phases here, which allocate nothing, compiled without numba's reference counts
#: (:mod:`.compiled`), as the impacts are: so a call from there takes none either. Not inlined:
#: a call of more than 30 arguments passes them as a tuple (CPython's ``CALL_FUNCTION_EX``),
#: which numba cannot inline.
NO_REFCOUNT = ("_settle", "_rest_again")


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


def _settle(
    a: int,
    b: int,
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
    adj_start: Any,
    adj: Any,
    touching: Any,
    sup: Any,
    nsup: Any,
    sep_ev: Any,
    sep_val: Any,
    kicked: Any,
    is_kicked: Any,
    queue: Any,
    queued: Any,
    before: Any,
    events: Any,
    event_count: Any,
    ledger: Any,
    status: Any,
    record: bool,
    step: int,
    start: float,
    when: float,
    dt: float,
    gap: float,
    e_default: float,
    contact_margin: float,
    rest_speed: float,
    reach_body: float,
    reach_static: float,
    ev: int,
) -> int:
    """Settle the contacts the impact of pair ``(a, b)`` at ``when`` touches (sequential impulses,
    breadth first, at most ``RELAX_IMPULSES``; pairs listed farther apart than ``reach_body`` or
    ``reach_static`` cannot be in contact yet). Every body kicked goes to ``kicked`` (marked in
    ``is_kicked``), ``a`` and ``b`` first; returns how many."""
    n = pos.shape[0]
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
                    ef._advance(other, when, pos, vel, acc, tau, ima, gravity, ledger)
                sep2 = ps._contact_separation(kind, pos, ext, s_kind, s_a, s_b, a2, b2)
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
            still = et._rounding_speed(before[0], before[1], before[2], before[3], before[4], before[5])
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
            e2_pair = ps._pair_e(eb[a2] if a2 >= 0 else s_e[-1 - a2], eb[b2], e_default)
            e_2 = cl.applied_restitution(vn2, e2_pair, rest_speed)
            j2 = ej._kick(a2, b2, sep2[1], sep2[2], sep2[3], vn2, e_2, vel, ima, sup, nsup, ledger, True)
            if j2 == 0.0:
                continue
            settled += 1
            status[1] += 1
            if record and touching[c2] == 0:
                evr._put_event(
                    events,
                    event_count[0],
                    evr.EVENT_IMPACT if cl.is_impact(vn2, rest_speed) else evr.EVENT_BELOW_REST,
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
    return n_kicked


def _rest_again(
    n_kicked: int,
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
    gravity: Any,
    ca: Any,
    cb: Any,
    cd: Any,
    count: int,
    adj_start: Any,
    adj: Any,
    rest: Any,
    touching: Any,
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
    ledger: Any,
    when: float,
    dt: float,
    contact_margin: float,
    rest_speed: float,
    resting_on: bool,
    reach_body: float,
    reach_static: float,
    ev: int,
) -> Any:
    """Look again at the rests of the ``n_kicked`` bodies in ``kicked`` at ``when``: their resting
    pairs are dropped (a kicked body may lift off), the bodies that rested on them join them in
    ``kicked``, every one is brought to ``when`` with its acceleration before rests, and, under
    gravity, their pairs in contact rest again on what holds (a static, a kinematic body, a
    supported body) and the new rests' expiries go onto the heap. Returns
    ``(n_look, look_clock, size)``: how many bodies ``kicked`` now holds, the clock of
    :func:`~.exact_rest._unchanged_since`, the heap's size."""
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
                ef._advance(other, when, pos, vel, acc, tau, ima, gravity, ledger)
                is_kicked[other] = 1
                kicked[n_look] = other
                n_look += 1
    for q in range(n_look):
        i = kicked[q]
        ef._advance(i, when, pos, vel, acc, tau, ima, gravity, ledger)
        er._base_acceleration(i, acc, ima, gravity, nsup)
    if resting_on:  # on what holds: a static, a kinematic body, a supported body
        look_start = look_clock + 1
        for _pass in range(er.MAX_SUPPORTS):
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
                    if er._unchanged_since(look_seen, look_changed, c2, a2, b2, look_start):
                        continue  # looked at in this look already, its bodies unchanged: 0 again
                    look_clock += 1
                    look_seen[c2] = look_clock
                    if sep_ev[c2] == ev:
                        sep2 = _recalled(sep_val, c2)
                    else:
                        if other >= 0:
                            ef._advance(other, when, pos, vel, acc, tau, ima, gravity, ledger)
                        sep2 = ps._contact_separation(kind, pos, ext, s_kind, s_a, s_b, a2, b2)
                        _remember(sep_ev, sep_val, c2, ev, sep2)
                    if sep2[0] > contact_margin:
                        continue
                    done = er._rest(
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
                later = when + er._support_expiry(
                    ca[c2], cb[c2], kind, vel, acc, ext, s_kind, normals, c2, contact_margin
                )
                if later < dt:
                    size = eh.heap_compact(ht, hk, hv, size, ver)
                    size = eh.heap_push(ht, hk, hv, size, later, count + c2, ver[count + c2])
    return n_look, look_clock, size
