"""The contact stepper's candidate pairs (phase 1 of :mod:`.contact_kernels`): every pair that can
meet before the step ends, by sort and sweep along x (the order kept from step to step, so the
insertion sort is nearly free; Ericson 7.2.1), each body's pairs (a counting sort), and the bound
``u`` on every awake body's speed that the listing is made for.

Owns ``HEAP_ROOM``, the listing (:func:`_list_pairs`, and :func:`_relist`, which sizes the pairs'
rows and the calendar to fit), each body's pairs (:func:`_adjacency`), the speed bound
(:func:`_speed_bound`) and the arrays grown when full (:func:`_grown_int`, :func:`_grown_float`,
which the islands' support rows use too). It imports :mod:`.non_literal` and
:mod:`.contact_time_of_impact` (a pair's separation); it must not import the impacts, the solve,
push-apart, the islands or the loop.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

if "_NON_LITERAL" in globals():  # the compiled copy: the kernels it calls are compiled too
    nl: Any = globals()["_NON_LITERAL"]
    ct: Any = globals()["_CONTACT_TIME_OF_IMPACT"]
else:
    from . import contact_time_of_impact as ct
    from . import non_literal as nl

#: The calendar has room for this many entries per candidate pair (and 2 more): a full one is
#: compacted (:func:`~collisionlab.engine.event_heap.heap_compact`) to at most the current ones.
HEAP_ROOM = 2

#: Inlined into its callers (:mod:`.compiled`): it copies arrays of either dtype, and a called
#: kernel is compiled once (one set of argument types, tests/test_numba_cache.py).
INLINE = ("_copy_rows",)


def _list_pairs(
    kind: Any, pos: Any, ext: Any, asleep: Any, s_kind: Any, s_a: Any, s_b: Any,
    order: Any, lo: Any, dims: int, reach: float, static_reach: float, pairs: Any,
) -> Any:  # fmt: skip
    """The candidate pairs (phase 1 of :mod:`.contact_kernels`) into ``pairs`` (grown when full);
    returns it and the count. ``order`` keeps the bodies sorted by their lower x bound from the last
    listing."""
    n = pos.shape[0]
    for i in range(n):
        lo[i] = pos[i, 0] - ext[i, 0] - reach
    for q in range(1, n):  # insertion sort: the order of the last step is nearly right
        i = order[q]
        key = lo[i]
        r = q - 1
        while r >= 0 and lo[order[r]] > key:
            order[r + 1] = order[r]
            r -= 1
        order[r + 1] = i
    count = nl._int(0)
    for q in range(n):
        i = order[q]
        hi = pos[i, 0] + ext[i, 0] + reach
        for r in range(q + 1, n):
            j = order[r]
            if lo[j] > hi:
                break
            if asleep[i] != 0 and asleep[j] != 0:
                continue
            if abs(pos[i, 1] - pos[j, 1]) > ext[i, 1] + ext[j, 1] + 2.0 * reach:
                continue
            if dims == 3 and abs(pos[i, 2] - pos[j, 2]) > ext[i, 2] + ext[j, 2] + 2.0 * reach:
                continue
            a, b = (i, j) if i < j else (j, i)
            sep = ct._sep_of(
                kind, ext, s_kind, s_a, s_b, a, b, pos[a, 0], pos[a, 1], pos[a, 2], pos[b, 0], pos[b, 1], pos[b, 2]
            )
            if sep[0] > 2.0 * reach:
                continue
            if count == pairs.shape[0]:
                pairs = _grown_int(pairs)
            pairs[count, 0] = a
            pairs[count, 1] = b
            count += 1
    for i in range(n):
        if asleep[i] != 0:
            continue
        for s in range(s_kind.shape[0]):
            sep = ct._sep_of(kind, ext, s_kind, s_a, s_b, -1 - s, i, 0.0, 0.0, 0.0, pos[i, 0], pos[i, 1], pos[i, 2])
            if sep[0] > static_reach:
                continue
            if count == pairs.shape[0]:
                pairs = _grown_int(pairs)
            pairs[count, 0] = -1 - s
            pairs[count, 1] = i
            count += 1
    return pairs, count


def _grown_int(a: Any) -> Any:
    grown = np.zeros((2 * a.shape[0] + 16, a.shape[1]), np.int64)
    _copy_rows(a, grown)
    return grown


def _grown_float(a: Any, rows: int) -> Any:
    if a.shape[0] >= rows:
        return a
    grown = np.zeros((max(rows, 2 * a.shape[0] + 16), a.shape[1]))
    _copy_rows(a, grown)
    return grown


def _copy_rows(a: Any, grown: Any) -> None:
    """``grown[:len(a)] = a``, element by element: numba compiles a slice copied from an array
    with its shape error's message, and that pulls its string formatting into the compile."""
    for r in range(a.shape[0]):
        for col in range(a.shape[1]):
            grown[r, col] = a[r, col]


def _adjacency(pairs: Any, count: int, n: int, start: Any, adj: Any) -> Any:
    """Each body's pairs: ``adj[start[i]:start[i + 1]]`` (a counting sort); returns ``adj``."""
    if adj.shape[0] < 2 * count:
        adj = np.zeros(4 * count + 16, np.int64)
    for i in range(n + 1):
        start[i] = 0
    for p in range(count):
        for end in range(2):
            i = pairs[p, end]
            if i >= 0:
                start[i + 1] += 1
    for i in range(n):
        start[i + 1] += start[i]
    fill = start[:n].copy()
    for p in range(count):
        for end in range(2):
            i = pairs[p, end]
            if i >= 0:
                adj[fill[i]] = p
                fill[i] += 1
    return adj


def _speed_bound(vel: Any, asleep: Any, gravity: Any, dt: float) -> float:
    """A bound on every awake body's speed over a step: the fastest now, plus what gravity adds
    in a step (and what the solve may give back of it)."""
    fastest = 0.0
    for i in range(vel.shape[0]):
        if asleep[i] == 0:
            fastest = max(fastest, math.sqrt(vel[i, 0] ** 2 + vel[i, 1] ** 2 + vel[i, 2] ** 2))
    g = math.sqrt(gravity[0] ** 2 + gravity[1] ** 2 + gravity[2] ** 2)
    return fastest + 2.0 * g * dt


def _relist(
    kind: Any, pos: Any, vel: Any, ext: Any, asleep: Any, s_kind: Any, s_a: Any, s_b: Any, gravity: Any,
    order: Any, lo: Any, start: Any, lists: Any, dims: int, left: float, contact_margin: float, status: Any,
) -> Any:  # fmt: skip
    """List the candidates for the ``left`` seconds of the step still to fly (every body at the
    same time). ``lists`` is ``(pairs, pf, adj, ver, ht, hk, hv)``: the pairs, their float rows,
    each body's pairs, and the calendar's arrays, grown to fit; returns ``(u, count, lists)``."""
    pairs, pf, adj, ver, ht, hk, hv = lists
    u = _speed_bound(vel, asleep, gravity, left)
    g = math.sqrt(gravity[0] ** 2 + gravity[1] ** 2 + gravity[2] ** 2)
    reach = u * left + contact_margin
    static_reach = u * left + 0.5 * g * left * left + contact_margin
    pairs, count = _list_pairs(kind, pos, ext, asleep, s_kind, s_a, s_b, order, lo, dims, reach, static_reach, pairs)
    adj = _adjacency(pairs, count, pos.shape[0], start, adj)
    pf = _grown_float(pf, count)
    if ver.shape[0] < count:
        ver = np.zeros(2 * count, np.int64)
        ht = np.zeros(HEAP_ROOM * 2 * count + 2)
        hk = np.zeros(ht.shape[0], np.int64)
        hv = np.zeros(ht.shape[0], np.int64)
    status[3] += 1
    return u, count, (pairs, pf, adj, ver, ht, hk, hv)
