"""Constants as ordinary values in the compiled form (:func:`_int`, :func:`_bool`): numba types a
variable that starts at a constant as that constant, and compiles each kernel it is passed to once
per type, so the steppers' counters and constant arguments start here (``nl._int(0)``).

Owns :func:`_int` and :func:`_bool`. It imports no other file of the engine, and every kernel file
may import it: it must stay so.
"""

from __future__ import annotations

__all__: list[str] = []  # helpers of the steppers' loops: nothing here is public

#: Helpers the compiled form inlines into their callers (:mod:`.compiled`): one conversion each,
#: less work than a call.
INLINE = ("_int", "_bool")


def _int(value: int) -> int:
    """``value`` as an ordinary integer in the compiled form. numba types a variable that starts
    at a constant (``k = 0``) as that constant (``Literal[int](0)``) until its inference reaches
    the loop that changes it, and compiles each kernel the variable is passed to for both types:
    twice (the exact stepper's ``_impacts`` took two minutes more to compile). So a counter passed
    to a kernel that is not inlined starts at ``_int(0)``, and a constant argument is ``_int(1)``;
    ``tests/test_numba_cache.py`` checks that no kernel is compiled twice.

    >>> _int(0)
    0
    """
    return int(value)


def _bool(value: bool) -> bool:
    """``value`` as an ordinary bool in the compiled form (:func:`_int`: ``Literal[bool]``).

    >>> _bool(False)
    False
    """
    return bool(value)
