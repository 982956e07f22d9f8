"""The event calendar: one scheduled event per body, the soonest found in O(log n) or better.

The idea of Smallenburg's EDMD (Eur. Phys. J. E 45, 22 (2022), section 2.3, after Paul's
"complete binary tree plus linear lists"), in flat arrays: time is cut into blocks of length
``P[P_BLOCK]``. Events of the current block (and any earlier) sit in a binary min-heap, the
small "tree for the near future"; events of the next ``nb`` blocks sit unordered in one
doubly linked list per block (a ring, indexed by block number modulo ``nb``); anything later
goes to an overflow list that is spread again each time the ring comes round. When the heap
runs dry, the next block's list is poured into it. Inserting a far event is O(1), removing any
event is O(1) from a list or O(log h) from the heap of h near events.

Every body has at most one event (its time in ``F[i, EVT]``); ``IX[i, HPOS]`` says where it is:
its index in the heap, -1 in list ``IX[i, QID]``, or ``NB_UNSCHEDULED``. Events made stale by
another collision are not searched for and removed: they are found stale when they come up
(the partner's collision counter has changed) and the body is simply predicted again
("lazy invalidation").
"""

from __future__ import annotations

from typing import Any

from .compile import jit, jit_call, jit_inline, prefetch
from .layout import EVT, HPOS, K_AHEAD, K_BUCKETED, K_CUR, K_HEAP, NB_UNSCHEDULED, P_BLOCK, Q_NB, QID, QNEXT, QPREV, X

__all__ = [
    "calendar_clear",
    "calendar_fetch_ahead",
    "calendar_insert",
    "calendar_next",
    "calendar_pop",
    "calendar_remove",
]

#: Blocks further than this are all "far" (keeps the block number inside int64).
_FAR_BLOCKS = 1e17


@jit_call
def _sift_up(heap: Any, F: Any, IX: Any, pos: int) -> None:
    i = heap[pos]
    t = F[i, EVT]
    while pos > 0:
        up = (pos - 1) >> 1
        p = heap[up]
        if F[p, EVT] <= t:
            break
        heap[pos] = p
        IX[p, HPOS] = pos
        pos = up
    heap[pos] = i
    IX[i, HPOS] = pos


@jit_call
def _sift_down(heap: Any, F: Any, IX: Any, pos: int, size: int) -> None:
    i = heap[pos]
    t = F[i, EVT]
    while True:
        child = 2 * pos + 1
        if child >= size:
            break
        c = heap[child]
        tc = F[c, EVT]
        if child + 1 < size:
            c2 = heap[child + 1]
            t2 = F[c2, EVT]
            if t2 < tc:
                child += 1
                c = c2
                tc = t2
        if tc >= t:
            break
        heap[pos] = c
        IX[c, HPOS] = pos
        pos = child
    heap[pos] = i
    IX[i, HPOS] = pos


@jit_call
def _heap_push(heap: Any, F: Any, IX: Any, K: Any, i: int) -> None:
    pos = K[K_HEAP]
    K[K_HEAP] = pos + 1
    heap[pos] = i
    _sift_up(heap, F, IX, pos)


@jit_inline
def _heap_delete(heap: Any, F: Any, IX: Any, K: Any, pos: int) -> None:
    size = K[K_HEAP] - 1
    K[K_HEAP] = size
    if pos == size:
        return
    last = heap[size]
    heap[pos] = last
    IX[last, HPOS] = pos
    if pos > 0 and F[heap[(pos - 1) >> 1], EVT] > F[last, EVT]:
        _sift_up(heap, F, IX, pos)
    else:
        _sift_down(heap, F, IX, pos, size)


@jit_call
def _block_of(t: float, block: float) -> int:
    q = t / block
    if q >= _FAR_BLOCKS:
        q = _FAR_BLOCKS
    return int(q)


@jit_call
def _list_push(IX: Any, lists: Any, q: int, i: int) -> None:
    head = lists[q]
    IX[i, QNEXT] = head
    IX[i, QPREV] = -1
    if head >= 0:
        IX[head, QPREV] = i
    lists[q] = i
    IX[i, QID] = q
    IX[i, HPOS] = -1


@jit_inline
def calendar_insert(heap: Any, lists: Any, F: Any, IX: Any, P: Any, Q: Any, K: Any, i: int) -> None:
    """Schedule body ``i``'s event at ``F[i, EVT]`` (finite, not already scheduled)."""
    blk = _block_of(F[i, EVT], P[P_BLOCK])
    cur = K[K_CUR]
    nb = Q[Q_NB]
    if blk <= cur:
        _heap_push(heap, F, IX, K, i)
    elif blk - cur < nb:
        _list_push(IX, lists, blk % nb, i)
        K[K_BUCKETED] += 1
    else:
        _list_push(IX, lists, nb, i)


@jit_inline
def calendar_remove(heap: Any, lists: Any, F: Any, IX: Any, Q: Any, K: Any, i: int) -> None:
    """Take body ``i``'s event out of the calendar, wherever it is (nothing if unscheduled)."""
    pos = IX[i, HPOS]
    if pos >= 0:
        _heap_delete(heap, F, IX, K, pos)
    elif pos == -1:
        q = IX[i, QID]
        prev = IX[i, QPREV]
        nxt = IX[i, QNEXT]
        if nxt >= 0:
            IX[nxt, QPREV] = prev
        if prev >= 0:
            IX[prev, QNEXT] = nxt
        else:
            lists[q] = nxt
        if q < Q[Q_NB]:
            K[K_BUCKETED] -= 1
    IX[i, HPOS] = NB_UNSCHEDULED


@jit
def _spread_overflow(heap: Any, lists: Any, F: Any, IX: Any, P: Any, Q: Any, K: Any) -> None:
    nb = Q[Q_NB]
    i = lists[nb]
    lists[nb] = -1
    while i >= 0:
        nxt = IX[i, QNEXT]
        calendar_insert(heap, lists, F, IX, P, Q, K, i)
        i = nxt


@jit_inline
def calendar_next(heap: Any, lists: Any, F: Any, IX: Any, P: Any, Q: Any, K: Any) -> int:
    """The body whose event comes first (left in the calendar), or -1 if nothing is scheduled."""
    nb = Q[Q_NB]
    while K[K_HEAP] == 0:
        if K[K_BUCKETED] == 0:
            # Only far events (or none): jump straight to the block of the soonest.
            i = lists[nb]
            if i < 0:
                return -1
            soonest = F[i, EVT]
            while i >= 0:
                soonest = min(soonest, F[i, EVT])
                i = IX[i, QNEXT]
            K[K_CUR] = _block_of(soonest, P[P_BLOCK])
            _spread_overflow(heap, lists, F, IX, P, Q, K)
            continue
        cur = K[K_CUR] + 1
        K[K_CUR] = cur
        if cur % nb == 0:
            _spread_overflow(heap, lists, F, IX, P, Q, K)
        q = cur % nb
        i = lists[q]
        lists[q] = -1
        while i >= 0:
            nxt = IX[i, QNEXT]
            K[K_BUCKETED] -= 1
            _heap_push(heap, F, IX, K, i)
            i = nxt
        _start_ahead(F, IX, K, lists[(cur + 1) % nb])
    return int(heap[0])


@jit_call
def _start_ahead(F: Any, IX: Any, K: Any, i: int) -> None:
    """Fetch the rows of body ``i`` of the next block's list (see :func:`calendar_fetch_ahead`)."""
    K[K_AHEAD] = i
    if i >= 0:
        prefetch(IX, i, QNEXT)
        prefetch(F, i, X)  # its flight: the event's handling reads it first
        prefetch(F, i, EVT)


@jit_call
def calendar_fetch_ahead(F: Any, IX: Any, K: Any) -> None:
    """One step along the next block's list: fetch the rows of its next body.

    When the heap runs dry the next block's list is poured into it, following its links
    through the bodies' rows: with a million bodies each link is a cache miss, and each one's
    address is known only when the one before has arrived, so the ~10 misses of a block came
    one after another (perf at 1M: 8 % of the samples on those two reads, the link and the
    event time). Called once per event, this walks the same chain a link per event while the
    block before is handled, each row asked for an event before it is read: the pour finds
    them at hand. Only a hint: a body taken out of the list (or moved to another) while the
    walk stands on it leads the walk astray, never the calendar."""
    i = K[K_AHEAD]
    if i >= 0:
        _start_ahead(F, IX, K, IX[i, QNEXT])


@jit_inline
def calendar_pop(heap: Any, F: Any, IX: Any, K: Any) -> None:
    """Remove the heap's first event (after :func:`calendar_next` returned its body)."""
    i = heap[0]
    _heap_delete(heap, F, IX, K, 0)
    IX[i, HPOS] = NB_UNSCHEDULED


@jit
def calendar_clear(lists: Any, IX: Any, P: Any, K: Any, now: float) -> None:
    """Empty the calendar and make the block of ``now`` the current one."""
    for q in range(lists.shape[0]):
        lists[q] = -1
    for i in range(IX.shape[0]):
        IX[i, HPOS] = NB_UNSCHEDULED
    K[K_HEAP] = 0
    K[K_BUCKETED] = 0
    K[K_AHEAD] = -1
    K[K_CUR] = _block_of(now, P[P_BLOCK])
