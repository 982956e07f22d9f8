"""The event calendar of the exact steppers: a binary heap of ``(time, key, version)`` entries in
three arrays, earliest first (ties by key). A stepper invalidates a key's entries lazily: it
bumps the key's version, and pops the entries whose version is not the current one.
"""

from __future__ import annotations

from typing import Any

__all__ = ["heap_compact", "heap_pop", "heap_push"]

#: The compiled form inlines both into their callers (they run for every prediction).
INLINE = ("heap_pop", "heap_push")


def heap_push(ht: Any, hk: Any, hv: Any, size: int, t: float, k: int, v: int) -> int:
    """Add ``(t, k, v)`` to the heap of ``size`` entries (it has room); returns the new size.
    Entries are ordered by time, then key, so the order never depends on how they came in.

    >>> import numpy as np
    >>> ht, hk, hv = np.zeros(4), np.zeros(4, np.int64), np.zeros(4, np.int64)
    >>> size = heap_push(ht, hk, hv, 0, 2.0, 7, 0)
    >>> size = heap_push(ht, hk, hv, size, 1.0, 9, 0)
    >>> size = heap_push(ht, hk, hv, size, 1.0, 3, 0)
    >>> float(ht[0]), int(hk[0]), heap_pop(ht, hk, hv, size), float(ht[0]), int(hk[0])
    (1.0, 3, 2, 1.0, 9)
    """
    i = size
    while i > 0:
        p = (i - 1) // 2
        if ht[p] < t or (ht[p] == t and hk[p] <= k):
            break
        ht[i] = ht[p]
        hk[i] = hk[p]
        hv[i] = hv[p]
        i = p
    ht[i] = t
    hk[i] = k
    hv[i] = v
    return size + 1


def heap_pop(ht: Any, hk: Any, hv: Any, size: int) -> int:
    """Remove the root (read it first); returns the new size."""
    size -= 1
    if size == 0:
        return 0
    t = ht[size]
    k = hk[size]
    v = hv[size]
    i = 0
    while True:
        c = 2 * i + 1
        if c >= size:
            break
        if c + 1 < size and (ht[c + 1] < ht[c] or (ht[c + 1] == ht[c] and hk[c + 1] < hk[c])):
            c += 1
        if t < ht[c] or (t == ht[c] and k <= hk[c]):
            break
        ht[i] = ht[c]
        hk[i] = hk[c]
        hv[i] = hv[c]
        i = c
    ht[i] = t
    hk[i] = k
    hv[i] = v
    return size


def heap_compact(ht: Any, hk: Any, hv: Any, size: int, ver: Any) -> int:
    """Make room for one more entry if the heap is full, in place: drop the stale entries (a
    version other than ``ver``'s) and heap the others again; returns the new size. A key has at
    most one current entry (each push takes a new version), so with ``HEAP_ROOM * count + 2``
    places for ``2 count`` keys (the exact stepper's ``HEAP_ROOM``) at least half the heap is then free."""
    if size < ht.shape[0]:
        return size
    kept = 0
    for i in range(size):
        if hv[i] == ver[hk[i]]:
            ht[kept] = ht[i]
            hk[kept] = hk[i]
            hv[kept] = hv[i]
            kept += 1
    size = 0
    for i in range(kept):  # heapify by pushing again
        size = heap_push(ht, hk, hv, size, ht[i], hk[i], hv[i])
    return size
