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

The phases live in files of their own, each owning one concept (this file is the loop):

* :mod:`.exact_sweeps` - phase 1's bounds: how far each body can move in the step's rest;
* :mod:`.exact_rest` - phase 2, resting contacts and the accelerations they leave;
* :mod:`.pair_time_of_impact` - phase 3's query, a pair's first time of impact;
* :mod:`.exact_impacts` - phases 3 and 4, the predictions and the impacts in time order;
* :mod:`.exact_settle` - what an impact touches, settled at its time: contacts, rests;
* :mod:`.exact_impulses` - the impulse of an impact, or of a rest's stop;
* :mod:`.exact_flight` - a body's exact flight between impacts;
* :mod:`.exact_step_end` - phase 5, the end of the step: depths for push-apart, the pairs in
  contact remembered;
* this file - the loop (:func:`run_exact_steps`), the phases in order.

This file imports those (and the Forward Euler stepper's files of the broad phase, the contacts'
order, push-apart, clamps and events: :mod:`.broad_phase_grid`, :mod:`.broad_phase_pairs`,
:mod:`.contact_order`, :mod:`.euler_push_apart`, :mod:`.euler_clamps`, :mod:`.event_rows`, with
:mod:`.pair_separation`, :mod:`.touching_memory` and :mod:`.non_literal`); none of them imports it.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

if "_BROAD_PHASE_GRID" in globals():  # the compiled copy: the kernels it calls are compiled too
    bg: Any = globals()["_BROAD_PHASE_GRID"]
    bp: Any = globals()["_BROAD_PHASE_PAIRS"]
    co: Any = globals()["_CONTACT_ORDER"]
    cl: Any = globals()["_EULER_CLAMPS"]
    pu: Any = globals()["_EULER_PUSH_APART"]
    evr: Any = globals()["_EVENT_ROWS"]
    nl: Any = globals()["_NON_LITERAL"]
    ps: Any = globals()["_PAIR_SEPARATION"]
    tm: Any = globals()["_TOUCHING_MEMORY"]
    ef: Any = globals()["_EXACT_FLIGHT"]
    er: Any = globals()["_EXACT_REST"]
    es: Any = globals()["_EXACT_SWEEPS"]
    st: Any = globals()["_EXACT_SETTLE"]
    ei: Any = globals()["_EXACT_IMPACTS"]
    se: Any = globals()["_EXACT_STEP_END"]
else:
    from . import broad_phase_grid as bg
    from . import broad_phase_pairs as bp
    from . import contact_order as co
    from . import euler_clamps as cl
    from . import euler_push_apart as pu
    from . import event_rows as evr
    from . import exact_flight as ef
    from . import exact_impacts as ei
    from . import exact_rest as er
    from . import exact_settle as st
    from . import exact_step_end as se
    from . import exact_sweeps as es
    from . import non_literal as nl
    from . import pair_separation as ps
    from . import touching_memory as tm

__all__ = ["MAX_IMPACTS_PER_STEP", "RELAX_IMPULSES", "STATUS_SIZE", "run_exact_steps"]

#: The stepper's limits, as a world reads them from its kernels (:mod:`.exact_impacts` and
#: :mod:`.exact_settle` own them).
MAX_IMPACTS_PER_STEP = ei.MAX_IMPACTS_PER_STEP
RELAX_IMPULSES = st.RELAX_IMPULSES
#: Counters returned to the world: steps that hit MAX_IMPACTS_PER_STEP, impacts resolved, times
#: the candidates had to be listed again within a step; then the step from which each body is
#: listed for its own bound again (``SWEEP_PAUSE``; kept here so that a run does not depend on
#: how its steps are split into calls).
STATUS_SIZE = 4


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
    sup = np.zeros((n, er.MAX_SUPPORTS, 3))
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
    # changed a body (look_changed), on one clock (look_clock): er._unchanged_since.
    look_seen = np.zeros(0, np.int64)
    look_changed = np.zeros(n, np.int64)
    look_clock = nl._int(0)
    near_idx = np.zeros(0, np.int64)
    seen = np.zeros(0, np.int64)
    g_size = math.sqrt(gravity[0] ** 2 + gravity[1] ** 2 + gravity[2] ** 2)
    resting_on = g_size > 0.0
    ht = np.zeros(64)
    hk = np.zeros(64, np.int64)
    hv = np.zeros(64, np.int64)
    width = bg._grid_width(ext, dims)  # the widest body in the grid; wider ones are met apart
    key_of = np.zeros(n, np.int64)
    cell_key = np.zeros(n, np.int64)
    hashed = np.zeros(0, np.int64)  # a hashed grid's buckets, held while this call runs
    ev = nl._int(0)  # the events resolved so far (the separations' memory)
    v_ref = np.zeros(3)  # the frame the candidates' sweep is measured in (es._velocity_bounds)
    table = np.zeros(16, np.int64)  # a hash table of the pairs in contact (_mark_touching)
    # Each candidate's unit normal where it was listed (phase 2 reads it), then where the step
    # ended (push-apart's first look); rows as ca.
    cn = np.zeros((ca.shape[0], 3))
    looked = np.zeros(0, np.int64)  # when push-apart last looked at a pair (_push_sweep)
    moved = np.zeros(n, np.int64)  # when push-apart last moved a body
    push_clock = nl._int(0)
    bound = np.zeros(n)  # each body's speed bound for the listing, relative to v_ref (es._sweeps)
    reach = np.zeros(n)  # how far that lets it move in the rest of the step
    for step in range(first_step, first_step + steps):
        start = step * dt
        t = 0.0
        impacts = nl._int(0)
        runaway = nl._bool(False)
        for i in range(n):
            tau[i] = 0.0
        count = 0
        touching = np.zeros(0, np.int8)
        floor = es.SWEEP_FLOOR if step >= status[3] else 1.0  # each body its own sweep, or the fastest's
        while True:  # one pass per listing of the candidates (more than one if a kick outran them)
            remaining = dt - t
            a_bound = es.ACCELERATION_HEADROOM * g_size
            v_bound = 0.0
            u_bound = 0.0
            rest = np.zeros(0, np.int8)
            ignored = np.zeros(0, np.int8)
            normals = np.zeros((0, 3))
            for _attempt in range(8):
                v_bound, u_bound = es._velocity_bounds(vel, v_ref)
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
                h, buckets = bg._grid_plan(pos, ext, dims, width, cell, max_cells, lo, shape)
                if buckets > 0 and hashed.shape[0] < buckets + 3:
                    hashed = np.zeros(buckets + 3, np.int64)
                starts = hashed if buckets > 0 else cell_start
                n_small = bg._bucket_sort(pos, ext, dims, lo, h, shape, width, buckets, starts, dest, key_of, cell_key)
                bg._store_in_cell_order(kind, pos, vel, ext, ima, eb, ids, scratch_f, scratch_i, dest)
                es._sweeps(vel, v_ref, u_bound, floor, remaining, drift, bound, reach)  # in the bodies' new order
                while True:  # listed again, into arrays twice as large, when they were too small
                    count = bp._find_pairs(
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
                er._base_accelerations(acc, ima, gravity, nsup)
                touching = np.zeros(count, np.int8)
                rest = np.zeros(count, np.int8)
                ignored = np.zeros(count, np.int8)
                normals = cn  # as listed: the positions have not changed since
                while table.shape[0] < 2 * touch_count[0]:
                    table = np.zeros(2 * table.shape[0], np.int64)
                tm._mark_touching(touch_keys, touch_count[0], table, ca, cb, ids, n, count, touching)
                if resting_on:
                    # Only pairs in contact can rest: order those alone. A pair is looked at again
                    # only once one of its bodies changed since (er._rest returns 0 again otherwise).
                    if near_idx.shape[0] < count:
                        near_idx = np.zeros(2 * count, np.int64)
                        seen = np.zeros(2 * count, np.int64)
                    n_near = nl._int(0)
                    for c in range(count):
                        if -cd[c] <= contact_margin:
                            near_idx[n_near] = c
                            n_near += 1
                            seen[c] = 0
                    order = co._order_coupled(pos, ca, cb, cd, near_idx, n_near, degree)
                    er._rest_passes(
                        order, n_near, seen, changed_at, ca, cb, normals, kind, vel, ext, ima, acc, sup, nsup, s_kind,
                        rest, touching, rest_speed, ledger,
                    )  # fmt: skip
                grown, a_bound = es._outrun(acc, vel, v_ref, v_bound, bound, a_bound)
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
            if ht.shape[0] < ei.HEAP_ROOM * count + 2:  # (event_heap.heap_compact); empty here: nothing to copy
                room = max(2 * ht.shape[0], ei.HEAP_ROOM * count + 2)
                ht = np.zeros(room)
                hk = np.zeros(room, np.int64)
                hv = np.zeros(room, np.int64)
            size = ei._predict_all(
                kind, pos, vel, acc, tau, ext, ima, s_kind, s_a, s_b, ca, cb, cd, rest, normals, count, ht, hk, hv,
                t, dt, gap, contact_margin,
            )  # fmt: skip
            # Phase 4: impacts in time order.
            event_room = 1 + min(count, st.RELAX_IMPULSES + max_degree)  # the most rows one impact writes
            while True:
                if record:
                    events = evr._events_with_room(events, event_count[0], event_room)
                code, size, ev, impacts, look_clock, runaway, when = ei._impacts(
                    kind, pos, vel, acc, tau, ext, ima, eb, ids, s_kind, s_a, s_b, s_e, gravity, ca, cb, cd, count,
                    adj_start, adj, rest, touching, ignored, normals, sup, nsup, ver, ht, hk, hv, size, sep_ev,
                    sep_val, look_seen, look_changed, look_clock, kicked, is_kicked, queue, queued, before, v_ref,
                    events, event_count, event_room, ledger, status, record, step, start, t, dt, gap, e_default,
                    contact_margin, rest_speed, resting_on, u_bound, v_bound, a_bound, bound, ev, impacts, runaway,
                )  # fmt: skip
                if code != ei.ROOM:
                    break
            restart = code == ei.RESTART
            if restart:  # list the candidates again from the time the bounds were outrun
                ef._advance_all(when, pos, vel, acc, tau, ima, gravity, ledger)
                near = np.zeros(count, np.int8)
                for c2 in range(count):
                    sep2 = ps._contact_separation(kind, pos, ext, s_kind, s_a, s_b, ca[c2], cb[c2])
                    near[c2] = 1 if sep2[0] <= contact_margin else 0
                touch_keys = se._save_touching(ca, cb, ids, n, count, touching, near, touch_keys, touch_count)
                t = when
                status[2] += 1
                if floor < 1.0:  # the fastest's sweep for the rest of this step and SWEEP_PAUSE more
                    floor = 1.0
                    status[3] = step + 1 + es.SWEEP_PAUSE
            if not restart:
                break
        # Phase 5: the end of the step.
        ef._advance_all(dt, pos, vel, acc, tau, ima, gravity, ledger)
        if near_idx.shape[0] < count:
            near_idx = np.zeros(2 * count, np.int64)
            seen = np.zeros(2 * count, np.int64)
        if looked.shape[0] < count:
            looked = np.zeros(2 * count, np.int64)
        n_push, overlap = se._end_separations(
            kind, pos, ext, s_kind, s_a, s_b, ca, cb, cd, cn, count, near_idx, dt - t, u_bound, v_bound, a_bound,
            contact_margin, gap, solver_margin,
        )  # fmt: skip
        # Push-apart moves only overlapping pairs (the others only once a push makes them
        # overlap): with none, its first pass would move nothing, so neither it nor its order
        # is needed.
        if overlap:
            order = co._order_coupled(pos, ca, cb, cd, near_idx, n_push, degree)
            found = push_clock  # every earlier tick is below it
            for p in range(passes):
                moves = pu._push_sweep(
                    kind, pos, ext, ima, s_kind, s_a, s_b, ca, cb, cd, cn, order, looked, moved, found,
                    found + 1 + p * n_push, p == 0, gravity, slop, solver_margin, ledger,
                )  # fmt: skip
                if moves == 0:
                    break
            push_clock = found + 1 + passes * n_push
        cl._clamp_to_walls(kind, pos, ext, ima, s_kind, s_a, s_b, ca, cb, count, gravity, slop, ledger)
        near = np.zeros(count, np.int8)
        for c in range(count):
            # a resting pair is in contact even where its flight past a curved support opened
            # its gap a little beyond the margin (er._support_expiry)
            near[c] = 1 if -cd[c] <= contact_margin or (c < rest.shape[0] and rest[c] == 1) else 0
        touch_keys = se._save_touching(ca, cb, ids, n, count, touching, near, touch_keys, touch_count)
    return touch_keys, ca, cb, cd, events
