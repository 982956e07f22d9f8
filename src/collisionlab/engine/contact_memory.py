"""The contact stepper's contact memory: the pairs that pushed in the last solve, as sorted keys
with their impulses, which the next solve starts from (the warm start) and the islands join
bodies by.

Owns a pair's key (:func:`_key`: a key ``k`` is the pair ``(k // n - m, k % n)``) and its lookup
(:func:`_find`). It imports only :mod:`.non_literal`; it must not import any other contact file.
"""

from __future__ import annotations

from typing import Any

if "_NON_LITERAL" in globals():  # the compiled copy: the kernels it calls are compiled too
    nl: Any = globals()["_NON_LITERAL"]
else:
    from . import non_literal as nl

#: Helpers the compiled form inlines into their callers (:mod:`.compiled`).
INLINE = ("_key", "_find")


def _key(a: int, b: int, m: int, n: int) -> int:
    """A pair's key in the contact memory (a static ``a = -1 - s`` comes first)."""
    return (a + m) * n + b


def _find(keys: Any, count: int, key: int) -> int:
    """Where ``key`` is in the sorted ``keys[:count]``, or -1 (binary search)."""
    lo = nl._int(0)
    hi = count
    while lo < hi:
        mid = (lo + hi) // 2
        if keys[mid] < key:
            lo = mid + 1
        else:
            hi = mid
    return lo if lo < count and keys[lo] == key else -1
