"""The Forward Euler stepper over arrays, written once: it runs as Python for small worlds and
compiled by numba (:mod:`collisionlab.engine.compiled`) for large ones, the same source both ways.

One step, in this fixed order (the lab's part VI, for any number of bodies):

1. **Integrate** with Forward Euler: ``x += v dt``, then ``v += g dt`` (bodies of finite mass).
   A body whose centre this carries onto or across a line or plane it started the step on one
   side of is put back on that side, ``slop`` into it (:func:`~.euler_clamps._uncross`): the contact found
   next bounces it there, so nothing ends on the far side of a line or plane.
2. **Broad phase**: a uniform grid of cells as wide as the bodies it holds (plus
   ``contact_margin``): all but the widest one in ``LARGE_SHARE``, so a few large boxes leave the
   cells small. Bodies are sorted into it by a counting sort and stored in cell order; each cell
   meets itself and half its neighbours, so every unordered pair of cells is visited once
   (Ericson, *Real-Time Collision Detection*, 7.1-7.1.3). A grid of more cells than its budget
   (a sparse or spread-out scene) is hashed into buckets instead of being coarsened (7.1.3). Each
   of the larger bodies meets the grid's bodies in the cells its box covers, and the other larger
   bodies. Statics (lines, planes, walls, fixed boxes) meet every body.
3. **Narrow phase**: each candidate pair's separation from
   :mod:`collisionlab.engine.geometry_kernels` (one kernel per pair of features). Pairs closer
   than ``contact_margin`` are "near"; those closer than ``solver_margin`` are contacts. Each
   contact's normal is kept: positions do not change until push-apart.
4. **Order**: contacts deepest first; ties broken by geometry (the positions of the two bodies,
   lexicographically, lower first), never by storage, so permuting the bodies permutes the
   result exactly; body pairs before static contacts, statics by their number. Only the
   contacts that share a body with another are sorted: a contact alone on its bodies (a ball
   touching only the floor) changes nothing in a sweep wherever it comes, so those come after
   the others, and each pass's events are then put back in the order of all of them.
5. **Impulses**, contact after contact in that order, each from the current velocities
   (sequential impulses): ``v_n = (v_b - v_a) . n``; nothing if ``v_n >= 0``; else
   ``j = -(1 + e) v_n / (1/m_a + 1/m_b)``, ``v_a -= (j/m_a) n``,
   ``v_b += (j/m_b) n`` (lab eqs. 12, 15, 24). Swept again while a sweep applies one, at most
   ``passes`` times (under gravity up to ``settle_passes`` while a sweep still changes some
   speed by more than ``rest_speed``, so a stack settles); a sweep after the first looks again
   only at the contacts one of whose bodies' velocity changed since they were last looked at
   (the others would give the same result: nothing). A pair gets an impulse when it touches or
   overlaps, or, if it was already in contact, when it is within ``solver_margin`` (so a
   resting stack stays supported). An impulse on a pair that was not already in contact is a
   collision event, unless it rests on a support that does not fall (a static or a kinematic
   body): an approach no faster than ``rest_speed + |g . n| dt`` (what gravity alone adds in
   one step) is a body pressed onto its support, and gets no event; and e = 0 below
   ``rest_speed + 2 |g . n| dt / e^2``, where the bounce would not rise above the depth one step
   of approach makes (the same for two bodies already touching: one holds the other up, as in
   a stack). So a ball on a floor or an incline stays on it and slides without hops or events,
   a stack does not bounce inside, and a dropped ball comes to rest after a few bounces instead
   of hopping forever.
6. **Push apart**, in the same order, from current positions: a pair still overlapping by ``d``
   moves apart to a gap of ``slop``, shared in inverse proportion to mass; swept the same way
   (after the first sweep only contacts one of whose bodies moved since they were last looked at).
   Finally every body past a one-sided wall is put back inside it (walls are hard), and every
   body a push left overlapping a line or plane, on the side it is on, is put back clear of it
   (:func:`~.euler_clamps._clamp_to_sides`). Under gravity, a body these corrections lifted above where it
   started the step pays that potential energy from its kinetic energy
   (:func:`~.euler_clamps._no_energy_from_corrections`): push-apart makes no energy.

Each body pair is oriented as the scenario orders pairs: A is the body given first (a ball-box
pair is computed ball first and its normal negated, as the scalar API mirrors it); a static is
always A. Negation is exact, so the orientation never changes a number.

The phases live in files of their own, each owning one concept (this file is the loop):

* :mod:`.broad_phase_grid` - phase 2's grid: the cells' width, dense or hashed, bodies in cell
  order;
* :mod:`.broad_phase_pairs` - phases 2 and 3: the candidate pairs met, their separations;
* :mod:`.contact_order` - phase 4, the contacts' order;
* :mod:`.euler_integrate` - phase 1, the integration;
* :mod:`.touching_memory` - the pairs in contact at the end of the step before;
* :mod:`.euler_impulses` - phase 5, the impulses;
* :mod:`.euler_push_apart` - phase 6's push-apart;
* :mod:`.euler_clamps` - the corrections of phases 1 and 6: walls, lines and planes, no energy
  from corrections;
* below them, and called by the other steppers too: :mod:`.pair_separation` (the body and static
  kinds, a pair's separation), :mod:`.event_rows` (the events) and :mod:`.non_literal`;
* this file - the loop (:func:`run_steps`) and :func:`find_near`.

This file imports those; none of them imports it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

if "_BROAD_PHASE_GRID" in globals():  # the compiled copy: the kernels it calls are compiled too
    bg: Any = globals()["_BROAD_PHASE_GRID"]
    bp: Any = globals()["_BROAD_PHASE_PAIRS"]
    co: Any = globals()["_CONTACT_ORDER"]
    cl: Any = globals()["_EULER_CLAMPS"]
    eu: Any = globals()["_EULER_IMPULSES"]
    pu: Any = globals()["_EULER_PUSH_APART"]
    nl: Any = globals()["_NON_LITERAL"]
    tm: Any = globals()["_TOUCHING_MEMORY"]
    ig: Any = globals()["_EULER_INTEGRATE"]
else:
    from . import broad_phase_grid as bg
    from . import broad_phase_pairs as bp
    from . import contact_order as co
    from . import euler_clamps as cl
    from . import euler_impulses as eu
    from . import euler_integrate as ig
    from . import euler_push_apart as pu
    from . import non_literal as nl
    from . import touching_memory as tm

__all__ = ["LEDGER_SIZE", "find_near", "run_steps"]

#: Ledger accumulators: integrator energy change, collisions' energy change, push-apart's,
#: the collisions' predicted loss sum (1 - e^2)/2 mu v_n^2, the deepest overlap undone,
#: body impulses applied, static impulses applied.
LEDGER_SIZE = 7
#: The tick of a contact never looked at (later than any).
_NEVER = 2**62


# --- the loop -----------------------------------------------------------------------------------
def run_steps(
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
    settle_passes: int,
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
) -> Any:
    """Advance ``steps`` steps in place (the module docstring's order). The state is re-sorted by
    cell each step and ``ids`` follows the bodies; ``scratch_f`` ``(n, 11)`` and ``scratch_i``
    ``(n, 2)`` are scratch space. ``touch_keys[:touch_count[0]]`` (keys of :func:`~.touching_memory._pair_key`, in
    no order) are the pairs in contact, carried from step to step. A hashed grid's buckets
    (``BUCKETS_PER_BODY`` per body) are held only while the call runs. Returns the buffers
    ``(touch_keys, ca, cb, cd, events)``, grown if they had to be; ``event_count[0]`` counts the
    event rows written."""
    n = pos.shape[0]
    max_cells = cell_start.shape[0] - 2
    lo = np.zeros(3)
    shape = np.zeros(3, np.int64)
    cn = np.zeros((ca.shape[0], 3))  # each contact's normal, kept while positions stay
    width = bg._grid_width(ext, dims)  # the widest body in the grid; wider ones are met apart
    key_of = np.zeros(n, np.int64)
    cell_key = np.zeros(n, np.int64)
    hashed = np.zeros(0, np.int64)  # a hashed grid's buckets, held while this call runs
    no_reach = np.zeros(0)  # one margin for every pair (_find_pairs)
    # Ticks of the sweeps (see _impulses): a body's last velocity change, its last move; they
    # only grow, so values from earlier steps (other bodies, after the re-sort) are all older.
    table = np.zeros(16, np.int64)  # a hash table of the pairs in contact (_mark_touching)
    changed = np.full(n, -1, np.int64)
    moved = np.full(n, -1, np.int64)
    clock = nl._int(0)
    degree = np.zeros(n, np.int64)  # _order_coupled's count of contacts per body
    largest = np.zeros(1)  # the largest change of speed of a sweep of impulses (_impulses)
    every = np.arange(ca.shape[0])  # every contact's number
    side = np.zeros((n, s_kind.shape[0]))  # each body's side of each line and plane (_sides)
    # Under gravity, each body's position at the start of the step, in the order then and in the
    # order of the grid (_no_energy_from_corrections).
    lifts = gravity[0] != 0.0 or gravity[1] != 0.0 or gravity[2] != 0.0
    start = np.zeros((n if lifts else 0, 3))
    start_sorted = np.zeros((n if lifts else 0, 3))
    held = np.zeros((n if lifts else 0, 3))
    driven = np.zeros(n if lifts else 0, np.int8)
    for step in range(first_step, first_step + steps):
        time = (step + 1) * dt  # the time at the end of this step, when its contacts are resolved
        lines = cl._sides(pos, s_kind, s_a, s_b, side)
        if lifts:
            for i in range(n):
                for k in range(3):
                    start[i, k] = pos[i, k]
        ig._integrate(pos, vel, ima, gravity, dt, ledger)
        if lines:
            cl._uncross(kind, pos, ext, ima, s_kind, s_a, s_b, side, gravity, slop, ledger)
        # Sort the state by cell (Ericson 7.1.3): the pair search then reads memory in sequence.
        h, buckets = bg._grid_plan(pos, ext, dims, width, width + contact_margin, max_cells, lo, shape)
        if buckets > 0 and hashed.shape[0] < buckets + 3:
            hashed = np.zeros(buckets + 3, np.int64)
        starts = hashed if buckets > 0 else cell_start
        n_small = bg._bucket_sort(pos, ext, dims, lo, h, shape, width, buckets, starts, dest, key_of, cell_key)
        bg._store_in_cell_order(kind, pos, vel, ext, ima, eb, ids, scratch_f, scratch_i, dest)
        if lines:
            cl._sides(pos, s_kind, s_a, s_b, side)  # in the new order
        if lifts:
            bg._scatter_rows(start, start_sorted, dest)
        while True:  # listed again, into arrays twice as large, when they were too small
            count = bp._find_pairs(
                kind, pos, ext, ids, s_kind, s_a, s_b, dims, lo, h, shape, buckets, n_small, starts, stencil,
                cell_key, ca, cb, cd, cn, contact_margin, contact_margin, no_reach, 0.0,
            )  # fmt: skip
            if count <= ca.shape[0]:
                break
            ca = np.zeros(2 * count, np.int64)
            cb = np.zeros(2 * count, np.int64)
            cd = np.zeros(2 * count)
            cn = np.zeros((2 * count, 3))
        # Only the contacts sharing a body with another need the order (_order_coupled); the
        # events are put back in the order of all of them after each pass (_events_in_order).
        if every.shape[0] < count:
            every = np.arange(2 * count)
        order = co._order_coupled(pos, ca, cb, cd, every, count, degree)
        # The contacts in that order, so that the sweeps read them in sequence.
        oa = ca[order]
        ob = cb[order]
        od = cd[order]
        on = cn[order]
        touching = np.zeros(count, np.int8)
        while table.shape[0] < 2 * touch_count[0]:
            table = np.zeros(2 * table.shape[0], np.int64)
        tm._mark_touching(touch_keys, touch_count[0], table, oa, ob, ids, n, count, touching)
        seen = np.full(count, _NEVER, np.int64)
        event_of = np.empty(count, np.int64)
        for p in range(max(passes, settle_passes)):
            event_count[1] = 0
            largest[0] = 0.0
            first_event = event_count[0]
            events = eu._impulses(
                kind,
                pos,
                vel,
                ext,
                ima,
                eb,
                ids,
                s_kind,
                s_a,
                s_b,
                s_e,
                oa,
                ob,
                od,
                on,
                touching,
                seen,
                changed,
                clock,
                e_default,
                rest_speed,
                gravity,
                dt,
                solver_margin,
                p == 0,
                step + 1,
                time,
                record,
                events,
                event_count,
                event_of,
                largest,
                ledger,
            )
            co._events_in_order(events, first_event, event_count[0], event_of, order, pos, ca, cb, cd)
            clock += count
            if event_count[1] == 0:
                break
            # Past ``passes``, only while a sweep still changes some velocity by more than
            # rest_speed (a world with gravity): a stack or pile then settles instead of sinking.
            if p + 1 >= passes and not (rest_speed > 0.0 and largest[0] > rest_speed):
                break
        found = clock
        if lifts:  # where the corrections start from, and who a kinematic body touches
            for i in range(n):
                driven[i] = 0
                for k in range(3):
                    held[i, k] = pos[i, k]
            for c in range(count):
                if oa[c] >= 0 and ima[oa[c]] == 0.0:
                    driven[ob[c]] = 1
                if oa[c] >= 0 and ima[ob[c]] == 0.0:
                    driven[oa[c]] = 1
        resolution_order = np.arange(od.shape[0])
        for p in range(passes):
            moves = pu._push_sweep(
                kind,
                pos,
                ext,
                ima,
                s_kind,
                s_a,
                s_b,
                oa,
                ob,
                od,
                on,
                resolution_order,
                seen,
                moved,
                found,
                clock,
                p == 0,
                gravity,
                slop,
                solver_margin,
                ledger,
            )
            clock += count
            if moves == 0:
                break
        cl._clamp_to_walls(kind, pos, ext, ima, s_kind, s_a, s_b, oa, ob, count, gravity, slop, ledger)
        if lines:
            cl._clamp_to_sides(kind, pos, ext, ima, s_kind, s_a, s_b, side, oa, ob, count, gravity, slop, ledger)
        if lifts:
            cl._no_energy_from_corrections(pos, vel, ima, start_sorted, held, driven, gravity, ledger)
        # The pairs now in contact: near this step and already touching, or newly hit.
        kept = 0
        if count > touch_keys.shape[0]:
            touch_keys = np.zeros(2 * count, np.int64)
        for c in range(count):
            if touching[c] == 1:
                a = oa[c]
                touch_keys[kept] = tm._key_of(ids[a] if a >= 0 else n + (-1 - a), ids[ob[c]], n)
                kept += 1
        touch_count[0] = kept
    return touch_keys, ca, cb, cd, events


def find_near(
    kind: Any,
    pos: Any,
    ext: Any,
    ids: Any,
    s_kind: Any,
    s_a: Any,
    s_b: Any,
    stencil: Any,
    dims: int,
    min_cell: float,
    max_cells: int,
    margin: float,
) -> Any:
    """Every pair closer than ``margin`` now, as rows ``(A, B)`` of ids (a static is ``-1 - s``)
    and their depths, without changing the state (the grid of :func:`run_steps`, on sorted
    copies; cells of ``min_cell`` if the bodies have no size and ``margin`` is 0)."""
    n = pos.shape[0]
    lo = np.zeros(3)
    shape = np.zeros(3, np.int64)
    width = bg._grid_width(ext, dims)
    h, buckets = bg._grid_plan(
        pos, ext, dims, width, width + margin if width + margin > 0.0 else min_cell, max_cells, lo, shape
    )
    starts = np.zeros((buckets if buckets > 0 else max_cells) + 3, np.int64)
    dest = np.zeros(n, np.int64)
    key_of = np.zeros(n, np.int64)
    cell_key = np.zeros(n, np.int64)
    n_small = bg._bucket_sort(pos, ext, dims, lo, h, shape, width, buckets, starts, dest, key_of, cell_key)
    spos = np.zeros_like(pos)
    sext = np.zeros_like(ext)
    skind = np.zeros_like(kind)
    sids = np.zeros_like(ids)
    bg._scatter_rows(pos, spos, dest)
    bg._scatter_rows(ext, sext, dest)
    bg._scatter(kind, skind, dest)
    bg._scatter(ids, sids, dest)
    cap = max(16, n)
    ca = np.zeros(cap, np.int64)
    cb = np.zeros(cap, np.int64)
    cd = np.zeros(cap)
    no_normals = np.zeros((0, 3))
    while True:  # listed again, into arrays large enough, when they were too small
        count = bp._find_pairs(
            skind, spos, sext, sids, s_kind, s_a, s_b, dims, lo, h, shape, buckets, n_small, starts, stencil,
            cell_key, ca, cb, cd, no_normals, margin, margin, np.zeros(0), 0.0,
        )  # fmt: skip
        if count <= ca.shape[0]:
            break
        ca = np.zeros(count, np.int64)
        cb = np.zeros(count, np.int64)
        cd = np.zeros(count)
    pairs = np.zeros((count, 2), np.int64)
    for t in range(count):
        pairs[t, 0] = sids[ca[t]] if ca[t] >= 0 else ca[t]
        pairs[t, 1] = sids[cb[t]]
    return pairs, cd[:count].copy()
