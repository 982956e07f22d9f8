"""The contact stepper over arrays: impacts at their time of impact, slow and resting contacts
solved together at mid-step, supported bodies at rest asleep. Written once: Python for small
worlds, compiled by numba (:mod:`collisionlab.engine.compiled`) for large ones.

One step of ``dt`` (``h = dt / 2``), in this fixed order:

1. **Candidates.** Every pair that can meet before the step ends is listed (sort and sweep along
   x, the order kept from step to step so the insertion sort is nearly free; Ericson 7.2.1): two
   bodies whose boxes, each widened by ``u dt``, overlap and whose gap is within ``2 u dt``, a
   body and a static within ``u dt + |g| dt^2 / 2``; ``u`` bounds every awake body's speed over
   the step. Two sleeping bodies are never listed. A kick past ``u``, or a body woken, lists
   again from that time.
2. **Flight to mid-step** with impacts: every body flies its parabola ``x + v t + g t^2 / 2``
   (a kinematic body, of infinite mass, its line). Each candidate pair's time of impact is found
   by conservative advancement along the separating normal (Mirtich 1996; two balls in the same
   field of gravity in closed form, Ericson 4.4.3), the earliest first. An approach faster than
   the rest speed ``v_rest`` is an impact: ``j = -(1 + e) v_n / (1/m_a + 1/m_b)`` (lab eqs. 12,
   15, 24), an event, and the pair's bodies have their other pairs predicted again (a row of
   touching balls passes a blow along, one impact after another, as in Newton's cradle). A slower
   approach is no event: it is left to the solve. A body's impacts past ``MAX_BODY_IMPACTS`` in
   one half step are perfectly inelastic (a collapsing cluster).
3. **Solve at mid-step** (Moreau's midpoint scheme; Moreau 1988, Jean 1999): every candidate
   pair touching, or apart and approaching slower than ``v_rest``, is a contact. Their normal
   impulses ``P >= 0`` are found together so that no pair is closing at the step's end: a pair
   in contact stops approaching (an overlap stops growing; push-apart undoes it), and a pair
   still apart may close its gap no sooner than it is solved again (a speculative contact, as in
   Box2D v3). That is a bound-constrained quadratic program in ``P`` (the Signorini condition at
   velocity level), started from the last step's impulses (contact memory, keyed by the pair)
   and iterated until every contact's projected gradient is below ``SOLVER_TOLERANCE``: first by
   MPRGP (modified proportioning with reduced gradient projections, Dostal 2009; conjugate
   gradients on the pushing contacts, which end a stack's in a few iterations), then, for a heap
   whose pushing set keeps changing, by accelerated projected gradient descent (APGD; Mazhar et
   al. 2015), both far fewer iterations than Gauss-Seidel sweeps for the bottom of a deep pile,
   up to ``MPRGP_SWEEPS`` and ``APGD_SWEEPS``. A body at rest on a support
   gets ``-g h`` at mid-step, which its flight turns into 0 by the step's end: an impulse applied
   at mid-step between two exact half flights is Moreau's ``x' = x + (v + v') dt / 2``,
   ``v' = v + g dt + P / m``, so free flight stays exact and a support does no work on a body at
   rest.
4. **Flight to the step's end**, with impacts as in 2.
5. **End of the step**: overlaps deeper than ``slop`` left (the solve's residual) are pushed
   apart, all at once, without touching velocities (the energy in the ledger's
   push-apart column); then **sleep**: bodies joined by contacts form islands (union-find). An island that
   touches a static, holds no kinematic body, and whose bodies all stayed slower than
   ``SLEEP_SPEED`` for ``SLEEP_TIME`` falls asleep: it no longer flies, is solved or listed
   against itself, and its supports go on carrying exactly its weight (``static_impulses``). An
   island is pushed apart once more as it falls asleep, to convergence (``SETTLE_ROUNDS``): a
   pile at rest shows no overlap one step's push-apart left. An impact on a sleeping body, or a
   contact of an awake body with it, wakes its island.

Each static's total impulse on the bodies is summed in ``static_impulse`` (momentum balance:
their sum is ``P_end - P_start - M g T``).

The stepper lives in files of its own, each owning one concept (this file is the loop):

* :mod:`.contact_candidates` - phase 1, the candidate pairs (sort and sweep), each body's pairs,
  the bound ``u`` on the speeds, and the arrays grown when full;
* :mod:`.contact_flight` - a body's exact flight (phases 2 and 4);
* :mod:`.contact_time_of_impact` - a pair's separation and its first time of impact;
* :mod:`.contact_impacts` - phases 2 and 4, a flight with its impacts in time order;
* :mod:`.contact_solver` - phase 3, the mid-step solve of the contacts;
* :mod:`.contact_qp` - the quadratic program the solve and push-apart share (MPRGP, APGD);
* :mod:`.contact_memory` - the contact memory's keys (the warm start, the islands);
* :mod:`.contact_push_apart` - phase 5's push-apart;
* :mod:`.contact_islands` - phase 5's islands and sleep, a sleeping island's supports, waking;
* this file - the loop (:func:`run_contact_steps`), the phases in order.

This file imports those (and :mod:`.non_literal`); none of them imports it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

if "_NON_LITERAL" in globals():  # the compiled copy: the kernels it calls are compiled too
    nl: Any = globals()["_NON_LITERAL"]
    cc: Any = globals()["_CONTACT_CANDIDATES"]
    ci: Any = globals()["_CONTACT_IMPACTS"]
    il: Any = globals()["_CONTACT_ISLANDS"]
    cp: Any = globals()["_CONTACT_PUSH_APART"]
    qp: Any = globals()["_CONTACT_QP"]
    cs: Any = globals()["_CONTACT_SOLVER"]
else:
    from . import contact_candidates as cc
    from . import contact_impacts as ci
    from . import contact_islands as il
    from . import contact_push_apart as cp
    from . import contact_qp as qp
    from . import contact_solver as cs
    from . import non_literal as nl

__all__ = ["MAX_IMPACTS_PER_STEP", "PAIR_COLUMNS", "STATUS_SIZE", "run_contact_steps"]

#: The stepper's sizes and limits, as its stepper and a world read them from its kernels
#: (:mod:`.contact_impacts`, :mod:`.contact_solver` and :mod:`.contact_qp` own them).
MAX_IMPACTS_PER_STEP = ci.MAX_IMPACTS_PER_STEP
PAIR_COLUMNS = cs.PAIR_COLUMNS
STATUS_SIZE = qp.STATUS_SIZE


def run_contact_steps(
    kind: Any, pos: Any, vel: Any, ext: Any, ima: Any, eb: Any, ids: Any,
    s_kind: Any, s_a: Any, s_b: Any, s_e: Any, gravity: Any, dims: int, dt: float, e_default: float,
    rest_speed: float, slop: float, contact_margin: float, first_step: int, steps: int, record: bool,
    tau: Any, acc: Any, asleep: Any, still: Any, island: Any, parent: Any, order: Any, lo: Any, start: Any,
    pairs: Any, pf: Any, adj: Any, contacts: Any, memory: Any, memory_lam: Any, memory_count: Any,
    rows_i: Any, rows_f: Any, row_count: Any,
    events: Any, event_count: Any, ledger: Any, static_impulse: Any, status: Any,
) -> Any:  # fmt: skip
    """Run ``steps`` steps of ``dt`` from step ``first_step`` (module docstring). The bodies stay
    in the order given (``ids`` only names them in events). Everything after ``record`` is kept
    between calls; the arrays that can grow come back: ``(pairs, pf, adj, contacts, memory,
    memory_lam, rows_i, rows_f, events)``. ``rest_speed`` is the world's ``v_rest``."""
    n = pos.shape[0]
    h = 0.5 * dt
    hits = np.zeros(n, np.int64)
    empty = np.zeros(0, np.int64)
    lists = (pairs, pf, adj, empty, np.zeros(0), empty, empty)
    u = 0.0
    count = nl._int(0)
    for step in range(first_step, first_step + steps):
        if il._at_rest(vel, ima, asleep):
            il._carry(rows_i, rows_f, row_count, asleep, static_impulse)
            continue
        for i in range(n):
            tau[i] = 0.0
            for k in range(3):
                acc[i, k] = gravity[k] if ima[i] > 0.0 and asleep[i] == 0 else 0.0
        t = 0.0
        left = dt  # list the candidates for this much of the step before flying on (< 0: listed)
        for half in range(2):
            t_end = h if half == 0 else dt
            while half == 1:  # the solve at mid-step, after the first half's flight
                pairs, pf = lists[0], lists[1]
                contacts, _, memory, memory_lam, woken = cs._solve(
                    kind, pos, vel, acc, ext, ima, s_kind, s_a, s_b, asleep, pairs, count, pf, contacts, memory,
                    memory_lam, memory_count, gravity, dt, rest_speed, contact_margin, ledger, static_impulse, status,
                )  # fmt: skip
                if woken < 0:
                    if cc._speed_bound(vel, asleep, gravity, h) > u:
                        left = h
                    break
                il._wake(island, asleep, acc, ima, gravity, tau, h, island[woken], rows_i, rows_f, row_count,
                         static_impulse, 0.5)  # fmt: skip
                u, count, lists = cc._relist(kind, pos, vel, ext, asleep, s_kind, s_a, s_b, gravity, order, lo,
                                             start, lists, dims, h, contact_margin, status)  # fmt: skip
            hits[:] = 0
            while True:
                if left > 0.0:
                    u, count, lists = cc._relist(kind, pos, vel, ext, asleep, s_kind, s_a, s_b, gravity, order, lo,
                                                 start, lists, dims, left, contact_margin, status)  # fmt: skip
                    left = -1.0
                pairs, _, adj, ver, ht, hk, hv = lists
                code, t, events = ci._flight(
                    kind, pos, vel, acc, tau, ext, ima, eb, ids, s_kind, s_a, s_b, s_e, gravity, asleep, island,
                    pairs, count, ver, hits, ht, hk, hv, start, adj, t, t_end, u, e_default, rest_speed, step + 1,
                    dt, record, events, event_count, ledger, static_impulse, rows_i, rows_f, row_count, status,
                )  # fmt: skip
                if code == ci.DONE:
                    break
                left = dt - t
        pairs, pf, adj = lists[0], lists[1], lists[2]
        cp._push_apart(kind, pos, ext, ima, asleep, s_kind, s_a, s_b, pairs, count, gravity, slop, ledger,
                       nl._int(cp.PUSH_ROUNDS), nl._int(cp.PUSH_MPRGP), nl._int(cp.PUSH_APGD))  # fmt: skip
        asleep_before = asleep.copy()
        rows_i, rows_f = il._sleep(
            kind, pos, vel, ext, ima, s_kind, s_a, s_b, asleep, still, island, parent, memory, memory_lam,
            memory_count[0], gravity, dt, rows_i, rows_f, row_count, ledger, static_impulse, status,
        )  # fmt: skip
        if (asleep != asleep_before).any():  # an island fell asleep: it is left as it lies, so
            # without the overlaps one step's push-apart left (what a pile at rest shows)
            cp._push_apart(kind, pos, ext, ima, asleep_before, s_kind, s_a, s_b, pairs, count, gravity, slop,
                           ledger, nl._int(cp.SETTLE_ROUNDS), nl._int(cp.SETTLE_MPRGP),
                           nl._int(cp.SETTLE_APGD))  # fmt: skip
    return lists[0], lists[1], lists[2], contacts, memory, memory_lam, rows_i, rows_f, events
