"""Which contacts were touching at the end of the step before (the touching memory of
:mod:`.step_kernels`): a pair's key that does not depend on storage (:func:`_key_of`,
:func:`_pair_key`), and the contacts whose keys were kept, found in a hash table
(:func:`_mark_touching`; Knuth's multiplicative hash, ``_KEY_MIX``).

It imports no other file of the engine; it must not import the impulses or any stepper's loop,
which read what it marks.
"""

from __future__ import annotations

from typing import Any

__all__: list[str] = []  # helpers of the steppers' loops: nothing here is public

#: Knuth's multiplicative hash of a pair's key (an odd constant near 2^62 / golden ratio), kept
#: to 62 bits so that the Python and compiled forms (unbounded and wrapping integers) agree.
_KEY_MIX = 0x278DDE6E5FD29F05
_LOW_62 = 2**62 - 1

#: Helpers the compiled form inlines into their callers (:mod:`.compiled`): they take arrays, and a
#: call that passes several numba arrays (each a struct of seven fields) costs more than the work inside.
INLINE = ("_pair_key", "_key_of")


def _key_of(ka: int, kb: int, n: int) -> int:
    """The key of the pair of ids (or ``n + s`` for static ``s``) ``ka`` and ``kb``."""
    low = min(ka, kb)
    high = max(ka, kb)
    return int(low) * (n + 1_000_000) + int(high)


def _pair_key(ca: Any, cb: Any, ids: Any, n: int, c: int) -> int:
    """A key for a contact that does not depend on storage: ids for bodies, ``n + s`` for statics."""
    a = ca[c]
    return _key_of(ids[a] if a >= 0 else n + (-1 - a), ids[cb[c]], n)


def _mark_touching(
    touch_keys: Any, kept: int, table: Any, ca: Any, cb: Any, ids: Any, n: int, count: int, touching: Any
) -> None:
    """``touching[c] = 1`` for each contact whose key (:func:`_pair_key`) is among
    ``touch_keys[:kept]`` (in any order): they go into the hash table ``table`` (open addressing,
    a power of two at least twice ``kept`` long, -1 where empty; Knuth's multiplicative hash),
    which each contact then looks up."""
    size = table.shape[0]
    shift = 62
    while (1 << (62 - shift)) < size:
        shift -= 1
    for u in range(size):
        table[u] = -1
    for u in range(kept):
        key = int(touch_keys[u])
        slot = ((key * _KEY_MIX) & _LOW_62) >> shift
        while table[slot] >= 0:
            slot = (slot + 1) & (size - 1)
        table[slot] = key
    for c in range(count):
        a = ca[c]
        key = _key_of(ids[a] if a >= 0 else n + (-1 - a), ids[cb[c]], n)
        slot = ((key * _KEY_MIX) & _LOW_62) >> shift
        while table[slot] >= 0 and table[slot] != key:
            slot = (slot + 1) & (size - 1)
        touching[c] = 1 if table[slot] == key else 0
