"""A flight with its impacts, earliest first (phases 2 and 4 of :mod:`.contact_kernels`): every
candidate pair's time of impact goes onto a calendar (:mod:`.event_heap`; a pair's older
predictions are dropped by version); an approach faster than the rest speed is an impact
(``j = -(1 + e) v_n / (1/m_a + 1/m_b)``, lab eqs. 12, 15, 24), an event, and its bodies' other
pairs are predicted again. A slower approach is left to the solve. A kick past the speed bound, or
an impact on a sleeping island (which wakes it), ends the flight early: the candidates are listed
again from there.

Owns ``MAX_IMPACTS_PER_STEP``, ``MAX_BODY_IMPACTS``, what a flight returns with (``DONE``,
``RESTART``), a pair's prediction (:func:`_predict`) and the flight (:func:`_flight`). It imports
:mod:`.contact_law`, :mod:`.non_literal`, :mod:`.pair_separation` (the pair's restitution),
:mod:`.event_rows`, :mod:`.event_heap`, :mod:`.contact_flight`, :mod:`.contact_time_of_impact` and
:mod:`.contact_islands` (waking); it must not import the candidates, the solve, push-apart or the
loop.
"""

from __future__ import annotations

from typing import Any

import numpy as np

if "_CONTACT_LAW" in globals():  # the compiled copy: the kernels it calls are compiled too
    cl: Any = globals()["_CONTACT_LAW"]
    evr: Any = globals()["_EVENT_ROWS"]
    nl: Any = globals()["_NON_LITERAL"]
    ps: Any = globals()["_PAIR_SEPARATION"]
    eh: Any = globals()["_HEAP"]
    fl: Any = globals()["_CONTACT_FLIGHT"]
    ct: Any = globals()["_CONTACT_TIME_OF_IMPACT"]
    il: Any = globals()["_CONTACT_ISLANDS"]
else:
    from . import contact_flight as fl
    from . import contact_islands as il
    from . import contact_law as cl
    from . import contact_time_of_impact as ct
    from . import event_heap as eh
    from . import event_rows as evr
    from . import non_literal as nl
    from . import pair_separation as ps

#: The most impacts resolved within one flight; past it the flight ends without the rest (the
#: world warns; ``status[0]`` counts such flights).
MAX_IMPACTS_PER_STEP = 100_000
#: The most impacts with e one body takes in one half step's flight: its later ones in it are
#: perfectly inelastic (e = 0), and past four times as many its approaches are left to the
#: solve, as slow ones are (a cluster of bodies squeezed together would otherwise collide ever
#: faster: inelastic collapse, McNamara and Young 1992). A blow passing along a row of touching
#: balls (Newton's cradle) takes two impacts per ball.
MAX_BODY_IMPACTS = 8
#: What a flight returns with: it reached its end; it must list the candidates again first.
DONE = 0
RESTART = 1


def _predict(
    kind: Any, pos: Any, vel: Any, acc: Any, tau: Any, ext: Any, s_kind: Any, s_a: Any, s_b: Any,
    pairs: Any, ver: Any, p: int, t: float, t_end: float, rest_speed: float, ht: Any, hk: Any, hv: Any, size: int,
) -> int:  # fmt: skip
    """Predict pair ``p`` again from ``t``: a new version, on the calendar if it meets before
    ``t_end``; returns the calendar's size."""
    ver[p] += 1
    when = ct._pair_toi(kind, pos, vel, acc, tau, ext, s_kind, s_a, s_b, pairs[p, 0], pairs[p, 1], t, t_end, rest_speed)
    if when >= t_end:
        return size
    size = eh.heap_compact(ht, hk, hv, size, ver)
    return int(eh.heap_push(ht, hk, hv, size, when, p, ver[p]))


def _flight(
    kind: Any, pos: Any, vel: Any, acc: Any, tau: Any, ext: Any, ima: Any, eb: Any, ids: Any,
    s_kind: Any, s_a: Any, s_b: Any, s_e: Any, gravity: Any, asleep: Any, island: Any,
    pairs: Any, count: int, ver: Any, hits: Any, ht: Any, hk: Any, hv: Any, start: Any, adj: Any,
    t: float, t_end: float, u: float, e_default: float, rest_speed: float,
    step: int, dt: float, record: bool, events: Any, event_count: Any, ledger: Any,
    static_impulse: Any, rows_i: Any, rows_f: Any, row_count: Any, status: Any,
) -> Any:  # fmt: skip
    """Fly from ``t`` to ``t_end`` (times within the step), resolving impacts earliest first (phase
    2 of :mod:`.contact_kernels`) from a calendar of predictions (:mod:`.event_heap`; a pair's older
    predictions are dropped by version). Returns ``(code, t, events)``: ``DONE`` with every body at
    ``t_end``, or ``RESTART`` at ``t`` (every body brought there) when a kick outran ``u`` or woke
    an island. ``hits`` counts each body's impacts in this flight."""
    size = nl._int(0)
    for p in range(count):
        size = _predict(
            kind, pos, vel, acc, tau, ext, s_kind, s_a, s_b, pairs, ver, p, t, t_end, rest_speed, ht, hk, hv, size
        )
    before = np.zeros(6)
    for _ in range(MAX_IMPACTS_PER_STEP):
        best = -1
        while size > 0:
            best = hk[0]
            current = hv[0] == ver[best]
            t_next = ht[0]
            size = eh.heap_pop(ht, hk, hv, size)
            if current:
                break
            best = -1
        if best < 0:
            fl._advance_all(pos, vel, acc, tau, t_end)
            return DONE, t_end, events
        a = pairs[best, 0]
        b = pairs[best, 1]
        t = t_next
        fl._advance(pos, vel, acc, tau, b, t)
        if a >= 0:
            fl._advance(pos, vel, acc, tau, a, t)
        sep = ct._sep_now(kind, pos, ext, s_kind, s_a, s_b, a, b)
        vn = 0.0
        for k in range(3):
            vn += (vel[b, k] - (vel[a, k] if a >= 0 else 0.0)) * sep[1 + k]
        most = max(hits[b], hits[a] if a >= 0 else 0)
        if not cl.is_impact(vn, rest_speed) or most >= 4 * MAX_BODY_IMPACTS:
            continue  # a slow approach, or a body in a cluster that will not stop: the solve's
        sleeper = b if asleep[b] != 0 else (a if a >= 0 and asleep[a] != 0 else -1)
        if sleeper >= 0:
            il._wake(island, asleep, acc, ima, gravity, tau, t, island[sleeper], rows_i, rows_f, row_count,
                     static_impulse, t / dt)  # fmt: skip
            fl._advance_all(pos, vel, acc, tau, t)
            return RESTART, t, events
        ima_a = ima[a] if a >= 0 else 0.0
        inv_sum = ima_a + ima[b]
        if inv_sum == 0.0:
            continue
        e = ps._pair_e(eb[a] if a >= 0 else s_e[-1 - a], eb[b], e_default) if most < MAX_BODY_IMPACTS else 0.0
        j = cl.impulse_magnitude(vn, inv_sum, e)
        kinetic = 0.0
        for k in range(3):
            before[k] = vel[a, k] if a >= 0 else 0.0
            before[3 + k] = vel[b, k]
            vb = cl.pushed_velocity(vel[b, k], j, ima[b], sep[1 + k])
            if ima[b] > 0.0:
                kinetic += (vb * vb - vel[b, k] * vel[b, k]) / ima[b]
            vel[b, k] = vb
            if a >= 0:
                va = cl.pushed_velocity(vel[a, k], -j, ima_a, sep[1 + k])
                if ima_a > 0.0:
                    kinetic += (va * va - vel[a, k] * vel[a, k]) / ima_a
                vel[a, k] = va
            else:
                static_impulse[-1 - a, k] += j * sep[1 + k]
        ledger[1] += 0.5 * kinetic
        ledger[3] -= cl.collision_loss(vn, inv_sum, e)
        ledger[5 if a >= 0 else 6] += 1.0
        status[1] += 1
        if record:
            id_a = ids[a] if a >= 0 else a
            when = (step - 1) * dt + t
            events = evr._write_event(events, event_count[0], evr.EVENT_IMPACT, step, when, id_a, ids[b], sep, vn, j, e,
                                     before, vel, a, b)  # fmt: skip
            event_count[0] += 1
        outran = False
        for end in range(2):
            i = b if end == 0 else a
            if i < 0:
                continue
            hits[i] += 1
            if vel[i, 0] ** 2 + vel[i, 1] ** 2 + vel[i, 2] ** 2 > u * u:
                outran = True
            for q in range(start[i], start[i + 1]):
                size = _predict(kind, pos, vel, acc, tau, ext, s_kind, s_a, s_b, pairs, ver, adj[q], t, t_end,
                                rest_speed, ht, hk, hv, size)  # fmt: skip
        if outran:
            fl._advance_all(pos, vel, acc, tau, t)
            return RESTART, t, events
    status[0] += 1
    fl._advance_all(pos, vel, acc, tau, t_end)
    return DONE, t_end, events
