"""The contacts' order (phase 4 of :mod:`.step_kernels`; the exact stepper's sweeps too): deepest
first, ties broken by geometry (the two bodies' positions, lexicographically: :func:`_lex3`,
:func:`_contact_cmp`), never by storage; body pairs before static contacts, statics by their
number (:func:`_order_contacts`). Only the contacts that share a body with another are sorted
(:func:`_order_coupled`, :func:`_order_subset`, by the keys of :func:`_tie_key`), and each pass's
events are then put back in the order of all of them (:func:`_events_in_order`).

Owns ``TIE_KEY_SIZE`` and the sorts. It imports only :mod:`.non_literal`; it must not import the
pairs' search, the impulses or any stepper's loop.
"""

from __future__ import annotations

from typing import Any

import numpy as np

if "_NON_LITERAL" in globals():  # the compiled copy: the kernels it calls are compiled too
    nl: Any = globals()["_NON_LITERAL"]
else:
    from . import non_literal as nl

__all__ = ["TIE_KEY_SIZE"]

#: Runs of contacts of equal depth up to this long are sorted by insertion, longer ones by their
#: first coordinate (bodies resting on a plane at the same depth make runs of hundreds).
_SHORT_RUN = 16
#: Columns of a contact's tie-break key (:func:`_tie_key`): its group, then six coordinates.
TIE_KEY_SIZE = 7

#: Helpers the compiled form inlines into their callers (:mod:`.compiled`): they take arrays, and a
#: call that passes several numba arrays (each a struct of seven fields) costs more than the work inside.
INLINE = ("_lex3", "_contact_cmp")


def _lex3(x0: float, y0: float, z0: float, x1: float, y1: float, z1: float) -> int:
    """-1, 0 or 1 as ``(x0, y0, z0)`` is lexicographically before, equal to or after ``(x1, y1, z1)``."""
    if x0 != x1:
        return -1 if x0 < x1 else 1
    if y0 != y1:
        return -1 if y0 < y1 else 1
    if z0 != z1:
        return -1 if z0 < z1 else 1
    return 0


def _contact_cmp(pos: Any, ca: Any, cb: Any, p: int, q: int) -> int:
    """Tie-break of two contacts of equal depth, from geometry only: body pairs before static
    contacts; body pairs by the lower then the higher position of their two bodies; static
    contacts by the body's position, then the static's number."""
    ap = ca[p]
    aq = ca[q]
    if ap >= 0 and aq < 0:
        return -1
    if ap < 0 and aq >= 0:
        return 1
    bp = cb[p]
    bq = cb[q]
    if ap < 0:
        c = _lex3(pos[bp, 0], pos[bp, 1], pos[bp, 2], pos[bq, 0], pos[bq, 1], pos[bq, 2])
        if c != 0:
            return c
        if ap > aq:  # statics are -1 - s: the larger code is the lower number
            return -1
        if ap < aq:
            return 1
        return 0
    lp, hp = (
        (ap, bp) if _lex3(pos[ap, 0], pos[ap, 1], pos[ap, 2], pos[bp, 0], pos[bp, 1], pos[bp, 2]) <= 0 else (bp, ap)
    )
    lq, hq = (
        (aq, bq) if _lex3(pos[aq, 0], pos[aq, 1], pos[aq, 2], pos[bq, 0], pos[bq, 1], pos[bq, 2]) <= 0 else (bq, aq)
    )
    c = _lex3(pos[lp, 0], pos[lp, 1], pos[lp, 2], pos[lq, 0], pos[lq, 1], pos[lq, 2])
    if c != 0:
        return c
    return _lex3(pos[hp, 0], pos[hp, 1], pos[hp, 2], pos[hq, 0], pos[hq, 1], pos[hq, 2])


def _insertion_sort(pos: Any, ca: Any, cb: Any, order: Any, s: int, t: int) -> None:
    """Sort ``order[s:t]`` by :func:`_contact_cmp`, equal contacts by their storage index (so the
    order the run comes in does not matter)."""
    for u in range(s + 1, t):
        key = order[u]
        v = u - 1
        while v >= s:
            c = _contact_cmp(pos, ca, cb, key, order[v])
            if c > 0 or (c == 0 and key > order[v]):
                break
            order[v + 1] = order[v]
            v -= 1
        order[v + 1] = key


def _sort_run(pos: Any, ca: Any, cb: Any, order: Any, s: int, t: int, spare: Any) -> None:
    """:func:`_insertion_sort` for a long run, the same order: body pairs first, each part sorted
    by the first coordinate of the position :func:`_contact_cmp` compares first (the lower
    body's, or the body's), then the rare runs of equal first coordinates by
    :func:`_insertion_sort`."""
    k = s
    for u in range(s, t):
        if ca[order[u]] >= 0:
            spare[k] = order[u]
            k += 1
    middle = k
    for u in range(s, t):
        if ca[order[u]] < 0:
            spare[k] = order[u]
            k += 1
    for u in range(s, t):
        order[u] = spare[u]
    for part in range(2):
        u0 = s if part == 0 else middle
        u1 = middle if part == 0 else t
        if u1 - u0 < 2:
            continue
        first = np.empty(u1 - u0)
        for u in range(u0, u1):
            a = ca[order[u]]
            b = cb[order[u]]
            low = a if a >= 0 and _lex3(pos[a, 0], pos[a, 1], pos[a, 2], pos[b, 0], pos[b, 1], pos[b, 2]) <= 0 else b
            first[u - u0] = pos[low, 0]
        rank = np.argsort(first)
        for u in range(u0, u1):
            spare[u] = order[u0 + rank[u - u0]]
        for u in range(u0, u1):
            order[u] = spare[u]
        v = 0
        while v < u1 - u0:
            w = v + 1
            while w < u1 - u0 and first[rank[w]] == first[rank[v]]:
                w += 1
            if w - v > 1:
                _insertion_sort(pos, ca, cb, order, u0 + v, u0 + w)
            v = w


def _order_contacts(pos: Any, ca: Any, cb: Any, cd: Any, count: int) -> Any:
    """Contacts deepest first; runs of equal depth sorted by :func:`_contact_cmp`, then by storage
    index (as a stable sort of the depths would leave them): by insertion, or :func:`_sort_run`
    for runs longer than ``_SHORT_RUN``, as resting contacts make. Every step of it may sort
    unstably: the order is total."""
    order = np.argsort(-cd[:count])
    spare = np.empty(count, np.int64)
    s = nl._int(0)
    while s < count:
        t = s + 1
        while t < count and cd[order[t]] == cd[order[s]]:
            t += 1
        if t - s > _SHORT_RUN:
            _sort_run(pos, ca, cb, order, s, t, spare)
        elif t - s > 1:
            _insertion_sort(pos, ca, cb, order, s, t)
        s = t
    return order


def _tie_key(pos: Any, ca: Any, cb: Any, c: int, keys: Any, row: int) -> None:
    """Write into ``keys[row]`` what :func:`_contact_cmp` compares for contact ``c``, so that a
    sort compares rows of numbers instead of reading and ordering positions at every comparison:
    0 and the lower then the higher of its two bodies' positions for a body pair, 1, the body's
    position and minus the static's code for a static contact (the larger code, the lower number,
    comes first). Rows compare lexicographically as ``_contact_cmp`` compares the contacts."""
    a = ca[c]
    b = cb[c]
    if a < 0:
        keys[row, 0] = 1.0
        for k in range(3):
            keys[row, 1 + k] = pos[b, k]
        keys[row, 4] = float(-a)
        keys[row, 5] = 0.0
        keys[row, 6] = 0.0
        return
    low = a
    high = b
    if _lex3(pos[a, 0], pos[a, 1], pos[a, 2], pos[b, 0], pos[b, 1], pos[b, 2]) > 0:
        low = b
        high = a
    keys[row, 0] = 0.0
    for k in range(3):
        keys[row, 1 + k] = pos[low, k]
        keys[row, 4 + k] = pos[high, k]


def _key_before(keys: Any, order: Any, p: int, q: int) -> bool:
    """Whether the contact at ``order[p]`` comes before the one at ``order[q]`` (their rows of
    ``keys`` are rows ``p`` and ``q``): by the rows, then by number (as a stable sort of the
    depths leaves a tie)."""
    for k in range(TIE_KEY_SIZE):
        if keys[p, k] != keys[q, k]:
            return bool(keys[p, k] < keys[q, k])
    return bool(order[p] < order[q])


def _keyed_insertion_sort(keys: Any, order: Any, s: int, t: int, row: Any) -> None:
    """Sort ``order[s:t]`` and its rows of ``keys`` by :func:`_key_before` (``row``: room for
    one row)."""
    for u in range(s + 1, t):
        v = u
        while v > s and _key_before(keys, order, v, v - 1):
            c = order[v]
            order[v] = order[v - 1]
            order[v - 1] = c
            for k in range(TIE_KEY_SIZE):
                row[k] = keys[v, k]
                keys[v, k] = keys[v - 1, k]
                keys[v - 1, k] = row[k]
            v -= 1


def _keyed_run_sort(keys: Any, order: Any, s: int, t: int, spare: Any, spare_keys: Any, row: Any) -> None:
    """Sort a long run ``order[s:t]`` by :func:`_key_before`: by the first two columns (group,
    then first coordinate) with one ``argsort``, then the runs equal in both by insertion."""
    m = t - s
    first = np.empty(m)
    for u in range(m):
        first[u] = keys[s + u, 1]
    rank = np.argsort(first)  # then body pairs (group 0) before static contacts, each in rank order
    k = 0
    for group in range(2):
        for u in range(m):
            if keys[s + rank[u], 0] == group:
                spare[k] = order[s + rank[u]]
                for col in range(TIE_KEY_SIZE):
                    spare_keys[k, col] = keys[s + rank[u], col]
                k += 1
    for u in range(m):
        order[s + u] = spare[u]
        for col in range(TIE_KEY_SIZE):
            keys[s + u, col] = spare_keys[u, col]
    v = s
    while v < t:
        w = v + 1
        while w < t and keys[w, 0] == keys[v, 0] and keys[w, 1] == keys[v, 1]:
            w += 1
        if w - v > 1:
            _keyed_insertion_sort(keys, order, v, w, row)
        v = w


def _order_subset(pos: Any, ca: Any, cb: Any, cd: Any, idx: Any, m: int) -> Any:
    """The contacts ``idx[:m]`` (in any order) in the order :func:`_order_contacts` gives all of
    them: deepest first, runs of equal depth by geometry, then by number; a sort of these alone,
    so the others cost nothing. The order is total, so any sort gives it: the depths by an
    unstable ``argsort``, then each run of equal depth by the numbers :func:`_tie_key` writes for
    it once (resting contacts make hundreds of short runs, and comparing positions again at every
    step of their sorts cost more than the ``argsort``)."""
    sub = idx[:m]
    depth = np.empty(m)
    for u in range(m):
        depth[u] = -cd[sub[u]]
    order = sub[np.argsort(depth)]
    keys = np.empty((m, TIE_KEY_SIZE))
    spare = np.empty(m, np.int64)
    spare_keys = np.empty((m, TIE_KEY_SIZE))
    row = np.empty(TIE_KEY_SIZE)
    s = nl._int(0)
    while s < m:
        t = s + 1
        while t < m and cd[order[t]] == cd[order[s]]:
            t += 1
        if t - s > 1:
            for u in range(s, t):
                _tie_key(pos, ca, cb, order[u], keys, u)
            if t - s > _SHORT_RUN:
                _keyed_run_sort(keys, order, s, t, spare, spare_keys, row)
            else:
                _keyed_insertion_sort(keys, order, s, t, row)
        s = t
    return order


def _order_coupled(pos: Any, ca: Any, cb: Any, cd: Any, idx: Any, m: int, degree: Any) -> Any:
    """The contacts ``idx[:m]`` in the order a sweep through them (impulses, the resting passes,
    push-apart) takes: those that share a body with another of them in :func:`_order_subset`'s
    order, then those alone on their bodies, in increasing number. A sweep reads and writes only
    a contact's two bodies (a static never changes), so where a contact alone on its bodies comes
    in the sweep changes nothing it computes (sums into the ledger aside, to rounding); among
    the others, each group sharing bodies meets in the order of the whole. On a slope where most
    bodies touch only the floor this sorts a few contacts instead of all of them. ``degree``:
    one zero per body, left zero.

    >>> pos = np.array([[0.0, 0, 0], [1.0, 0, 0], [5.0, 0, 0]])
    >>> ca, cb = np.array([-1, -1, 0, -1]), np.array([0, 1, 1, 2])
    >>> cd = np.array([1e-9, 2e-9, 0.0, 3e-9])  # the deepest, floor-2, is alone on body 2
    >>> _order_coupled(pos, ca, cb, cd, np.arange(4), 4, np.zeros(3, np.int64)).tolist()
    [1, 0, 2, 3]
    """
    for u in range(m):
        c = idx[u]
        if ca[c] >= 0:
            degree[ca[c]] += 1
        degree[cb[c]] += 1
    shared = np.empty(m, np.int64)
    order = np.empty(m, np.int64)
    k = nl._int(0)
    alone = m
    for u in range(m - 1, -1, -1):  # from the end, so those alone keep their increasing numbers
        c = idx[u]
        if degree[cb[c]] > 1 or (ca[c] >= 0 and degree[ca[c]] > 1):
            shared[k] = c
            k += 1
        else:
            alone -= 1
            order[alone] = c
    for u in range(m):
        c = idx[u]
        if ca[c] >= 0:
            degree[ca[c]] = 0
        degree[cb[c]] = 0
    first = _order_subset(pos, ca, cb, cd, shared, k)  # a total order: any input order gives it
    for u in range(k):
        order[u] = first[u]
    return order


def _events_in_order(
    events: Any, first: int, end: int, event_of: Any, order: Any, pos: Any, ca: Any, cb: Any, cd: Any
) -> None:
    """Put event rows ``first:end`` of one pass of :func:`_impulses` (row ``first + k`` from
    contact ``order[event_of[k]]``) in the order of their contacts in :func:`_order_contacts`:
    the order they would have been resolved in had every contact been sorted."""
    m = end - first
    if m < 2:
        return
    of = np.empty(m, np.int64)
    of_key = np.empty(m)  # the same numbers as floats (exact below 2^53): the kernels' one argsort
    for k in range(m):
        of[k] = order[event_of[k]]
        of_key[k] = of[k]
    wanted = _order_subset(pos, ca, cb, cd, of, m)
    by_contact = np.argsort(of_key)
    rows = events[first:end].copy()
    sorted_of = of[by_contact]
    for q in range(m):
        lo, hi = 0, m  # the first place holding wanted[q] (np.searchsorted, which costs numba's
        while lo < hi:  # compile seconds of comparators)
            mid = (lo + hi) // 2
            if sorted_of[mid] < wanted[q]:
                lo = mid + 1
            else:
                hi = mid
        k = by_contact[lo]
        for col in range(events.shape[1]):
            events[first + q, col] = rows[k, col]
