"""The contact stepper's mid-step solve (phase 3 of :mod:`.contact_kernels`; Moreau's midpoint
scheme): every candidate pair touching, or apart and approaching slower than the rest speed, is a
contact, and their normal impulses are found together (:mod:`.contact_qp`), started from the last
step's (:mod:`.contact_memory`), so that no pair is closing at the step's end; the energy the
impulses take goes to the ledger, measured and theory's.

Owns ``PAIR_COLUMNS`` (a pair's float row), the solve's iteration caps (``COLD_SOLVER_SWEEPS``,
``MPRGP_SWEEPS``, ``APGD_SWEEPS``), the solve (:func:`_solve`) and its helpers on pair rows
(:func:`_apply`, :func:`_normal_velocity`, :func:`_contact_kinetic`). It imports
:mod:`.non_literal`, :mod:`.contact_law` (the velocity update), :mod:`.contact_time_of_impact`
(a pair's separation), :mod:`.contact_memory` and :mod:`.contact_qp`; it must not import the
candidates, impacts, push-apart, islands or the loop.
"""

from __future__ import annotations

from typing import Any

import numpy as np

if "_NON_LITERAL" in globals():  # the compiled copy: the kernels it calls are compiled too
    nl: Any = globals()["_NON_LITERAL"]
    cl: Any = globals()["_CONTACT_LAW"]
    ct: Any = globals()["_CONTACT_TIME_OF_IMPACT"]
    cm: Any = globals()["_CONTACT_MEMORY"]
    qp: Any = globals()["_CONTACT_QP"]
else:
    from . import contact_law as cl
    from . import contact_memory as cm
    from . import contact_qp as qp
    from . import contact_time_of_impact as ct
    from . import non_literal as nl

#: The most iterations of a solve most of whose touching contacts are new (nothing to start from: a
#: stack's first step, where a column of k balls needs of the order of k^2 sweeps).
COLD_SOLVER_SWEEPS = 2000
#: A warm solve's most MPRGP iterations (enough for a stack), then APGD's (a heap); one that
#: stops there is counted in ``status[2]``. Fewer left the 2,000-circle pour jittering
#: (bench/README.md, ``bench_piles.py``).
MPRGP_SWEEPS = 50
APGD_SWEEPS = 300
#: Columns of a pair's float row in the solve: height (times ``|g|``), normal (3), gap at
#: mid-step, impulse, target normal velocity, inverse mass sum, what the relative acceleration
#: adds to the normal velocity by the step's end.
PAIR_COLUMNS = 9


def _solve(
    kind: Any, pos: Any, vel: Any, acc: Any, ext: Any, ima: Any, s_kind: Any, s_a: Any, s_b: Any,
    asleep: Any, pairs: Any, count: int, pf: Any, contacts: Any, memory: Any, memory_lam: Any,
    memory_count: Any, gravity: Any, dt: float, rest_speed: float, contact_margin: float, ledger: Any,
    static_impulse: Any, status: Any,
) -> Any:  # fmt: skip
    """The mid-step solve (phase 3 of :mod:`.contact_kernels`) over the candidates; every body is at
    mid-step. Returns ``(contacts, c, memory, memory_lam, woken)``: the contacts' pair numbers, how
    many, the new memory, and a sleeping body an awake one touches (-1 if none: then nothing is
    solved, the caller wakes its island and lists again)."""
    m = s_kind.shape[0]
    n = pos.shape[0]
    h = 0.5 * dt
    c = nl._int(0)
    cold = nl._int(0)  # contacts touching with nothing remembered
    for p in range(count):
        a = pairs[p, 0]
        b = pairs[p, 1]
        sep = ct._sep_now(kind, pos, ext, s_kind, s_a, s_b, a, b)
        vn = 0.0
        gn = 0.0
        for k in range(3):
            vn += (vel[b, k] - (vel[a, k] if a >= 0 else 0.0)) * sep[1 + k]
            gn += (acc[b, k] - (acc[a, k] if a >= 0 else 0.0)) * sep[1 + k]
        if cl.is_impact(vn, rest_speed) and sep[0] > contact_margin:
            continue  # an impact to come: the flights' (one passed over in a collapsing cluster is solved)
        if sep[0] > contact_margin and asleep[b] + (asleep[a] if a >= 0 else 0) != 0:
            continue  # not touching a sleeper yet: it wakes when it is touched
        if asleep[b] != 0:
            return contacts, 0, memory, memory_lam, b
        if a >= 0 and asleep[a] != 0:
            return contacts, 0, memory, memory_lam, a
        inv_sum = (ima[a] if a >= 0 else 0.0) + ima[b]
        if inv_sum == 0.0:
            continue
        if c == contacts.shape[0]:
            grown = np.zeros(2 * c + 16, np.int64)
            for q in range(c):  # not a slice copy: see _lowest_first
                grown[q] = contacts[q]
            contacts = grown
        contacts[c] = p
        c += 1
        for k in range(3):
            pf[p, 1 + k] = sep[1 + k]
        pf[p, 0] = -(gravity[0] * sep[4] + gravity[1] * sep[5] + gravity[2] * sep[6])  # height x |g|
        pf[p, 4] = sep[0]
        # The gap at the step's end is G + v'_n h, G = gap - (alpha.n) h^2 / 2 (the second half's
        # flight): a pair apart (G >= 0) may close it no sooner than a step later (G + v'_n 1.5 dt
        # >= 0: it is solved again before it could touch); an overlap (G < 0) stops closing, and
        # push-apart undoes it. (A target that pushed overlaps apart would ask a jammed pile to
        # lift itself: impulses growing step after step, then let go as a kick.)
        undipped = sep[0] - 0.5 * gn * h * h
        pf[p, 6] = -undipped / (3.0 * h) if undipped >= 0.0 else 0.0
        pf[p, 7] = inv_sum
        pf[p, 8] = gn * h
        found = cm._find(memory, memory_count[0], cm._key(a, b, m, n))
        pf[p, 5] = memory_lam[found] if found >= 0 else 0.0
        cold += found < 0 and sep[0] <= contact_margin
    heights = np.empty(c)
    for q in range(c):
        heights[q] = pf[contacts[q], 0]
    _lowest_first(contacts, heights, c)  # a weight passes down a heap to its floor in one sweep
    kinetic = _contact_kinetic(pairs, contacts, c, vel, ima, n)
    approach = np.empty(c)  # each contact's normal velocity before the solve
    for q in range(c):
        approach[q] = _normal_velocity(pairs, pf, contacts[q], vel)
    for q in range(c):  # the warm start
        p = contacts[q]
        _apply(pairs, pf, p, vel, ima, pf[p, 5])
    # The contacts as dense rows in sweep order, what every sweep reads in sequence: bodies;
    # normal (3), target, inverse mass sum, the acceleration's share, impulse.
    ca = np.empty(c, np.int64)
    cb = np.empty(c, np.int64)
    cf = np.empty((c, 7))
    for q in range(c):
        p = contacts[q]
        ca[q] = pairs[p, 0]
        cb[q] = pairs[p, 1]
        for k in range(3):
            cf[q, k] = pf[p, 1 + k]
        cf[q, 3] = pf[p, 6]
        cf[q, 4] = pf[p, 7]
        cf[q, 5] = pf[p, 8]
        cf[q, 6] = pf[p, 5]
    if 2 * cold > c:
        if not qp._mprgp(ca, cb, cf, c, vel, ima, n, nl._int(COLD_SOLVER_SWEEPS), status):
            status[2] += 1
    elif not qp._qp(ca, cb, cf, c, vel, ima, n, nl._int(MPRGP_SWEEPS), nl._int(APGD_SWEEPS), status):
        status[2] += 1
    for q in range(c):
        pf[contacts[q], 5] = cf[q, 6]
    ledger[1] += _contact_kinetic(pairs, contacts, c, vel, ima, n) - kinetic
    # Theory's account of the same, contact by contact: an impulse P that takes a normal velocity
    # from v_n to v_n' does work P (v_n + v_n') / 2 (kinetic energy is quadratic: with
    # dv = M^-1 J^T P, dK = P.J v + P.A P / 2 and v_n' = v_n + (A P)_n), summed over the contacts;
    # for one contact stopped (v_n' = 0, P = -mu v_n) the lab's -(1 - e^2) mu v_n^2 / 2 at e = 0.
    work = 0.0
    for q in range(c):
        p = contacts[q]
        work += pf[p, 5] * (approach[q] + _normal_velocity(pairs, pf, p, vel))
    ledger[3] += 0.5 * work
    kept = nl._int(0)
    for q in range(c):
        kept += pf[contacts[q], 5] > 0.0
    memory = np.empty(kept, np.int64)  # the pairs pushing, for the warm start and the islands
    lam = np.empty(kept)
    kept = nl._int(0)
    for q in range(c):
        p = contacts[q]
        a = pairs[p, 0]
        if pf[p, 5] <= 0.0:
            continue
        memory[kept] = cm._key(a, pairs[p, 1], m, n)
        lam[kept] = pf[p, 5]
        kept += 1
        if a < 0:
            for k in range(3):
                static_impulse[-1 - a, k] += pf[p, 5] * pf[p, 1 + k]
    keys = np.empty(kept)  # the keys are distinct (and exact as floats): any sort gives this order
    for q in range(kept):
        keys[q] = memory[q]
    order = np.argsort(keys)
    memory_count[0] = kept
    return contacts, c, memory[order], lam[order], -1


def _lowest_first(contacts: Any, heights: Any, c: int) -> None:
    """Order ``contacts[:c]`` by ``heights``, lowest first, equal heights in their order (a stable
    sort: the same order in both forms). numba's quicksort ``argsort`` of floats with each run of
    equal heights then put back in order: the kernels' one sort (numba compiles each sort, kind
    and dtype apart, seconds each), and elements copied one by one (numba compiles a slice copied
    from an array with its shape error's message and string formatting)."""
    rank = np.argsort(heights)
    v = 0
    while v < c:
        w = v + 1
        while w < c and heights[rank[w]] == heights[rank[v]]:
            w += 1
        if w - v > 1:  # rank[v:w] in ascending order: their positions as the float keys of a sort
            at = np.empty(w - v)
            for u in range(v, w):
                at[u - v] = rank[u]
            back = np.argsort(at)
            for u in range(v, w):
                rank[u] = int(at[back[u - v]])
        v = w
    ordered = np.empty(c, np.int64)
    for q in range(c):
        ordered[q] = contacts[rank[q]]
    for q in range(c):
        contacts[q] = ordered[q]


def _apply(pairs: Any, pf: Any, p: int, vel: Any, ima: Any, impulse: float) -> None:
    """Apply ``impulse`` along pair ``p``'s normal: ``v_b += P n / m_b``, ``v_a -= P n / m_a``."""
    a = pairs[p, 0]
    b = pairs[p, 1]
    for k in range(3):
        vel[b, k] = cl.pushed_velocity(vel[b, k], impulse, ima[b], pf[p, 1 + k])
        if a >= 0:
            vel[a, k] = cl.pushed_velocity(vel[a, k], -impulse, ima[a], pf[p, 1 + k])


def _normal_velocity(pairs: Any, pf: Any, p: int, vel: Any) -> float:
    """Pair ``p``'s relative velocity along its normal (``pf[p, 1:4]``), ``v_b - v_a``."""
    a = pairs[p, 0]
    b = pairs[p, 1]
    vn = 0.0
    for k in range(3):
        vn += (vel[b, k] - (vel[a, k] if a >= 0 else 0.0)) * pf[p, 1 + k]
    return vn


def _contact_kinetic(pairs: Any, contacts: Any, c: int, vel: Any, ima: Any, n: int) -> float:
    """Kinetic energy of the bodies in the contacts, each counted once."""
    seen = np.zeros(n, np.bool_)
    kinetic = 0.0
    for q in range(c):
        p = contacts[q]
        for end in range(2):
            i = pairs[p, end]
            if i >= 0 and not seen[i] and ima[i] > 0.0:
                seen[i] = True
                kinetic += 0.5 * (vel[i, 0] ** 2 + vel[i, 1] ** 2 + vel[i, 2] ** 2) / ima[i]
    return kinetic
