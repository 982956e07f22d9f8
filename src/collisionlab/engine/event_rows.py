"""The steppers' event rows: what a row holds (``EVENT_COLUMNS``) and its kind (``EVENT_IMPACT``,
``EVENT_SKIPPED``, ``EVENT_BELOW_REST``), room for more rows (:func:`_events_with_room`), and a
row written (:func:`_put_event`; :func:`_write_event` makes room first).

It imports only :mod:`.non_literal`; it must not import the impulses or any stepper's loop, which
write their events through it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

if "_NON_LITERAL" in globals():  # the compiled copy: the kernels it calls are compiled too
    nl: Any = globals()["_NON_LITERAL"]
else:
    from . import non_literal as nl

__all__ = ["EVENT_BELOW_REST", "EVENT_COLUMNS", "EVENT_IMPACT", "EVENT_SKIPPED"]

#: An event row's kind: an impact; a contact skipped as separating; an impact whose e was set to 0
#: because its approach was below the rest threshold (``below_rest_threshold`` of the event).
EVENT_IMPACT = 0
EVENT_SKIPPED = 1
EVENT_BELOW_REST = 2
#: Columns of an event row: kind (``EVENT_*``), step, time, id of A (a
#: static is ``-1 - s``), id of B, normal (3), point (3), v_n, j, e, v_a before (3), v_b before (3),
#: v_a after (3), v_b after (3). (A slow approach is a resting contact, never an event.)
EVENT_COLUMNS = 26

#: Helpers the compiled form inlines into their callers (:mod:`.compiled`): they take arrays, and a
#: call that passes several numba arrays (each a struct of seven fields) costs more than the work inside.
INLINE = ("_put_event",)


def _events_with_room(events: Any, used: int, room: int) -> Any:
    """``events`` if at least ``room`` rows past the first ``used`` are free, else a copy at least
    twice as large (and ``used + room`` rows) with the first rows kept."""
    if events.shape[0] - used >= room:
        return events
    grown = np.zeros((max(2 * events.shape[0] + 16, used + room), events.shape[1]))
    # Element by element: numba compiles a slice copied from an array with its shape error's
    # message, and that pulls its string formatting into the compile (seconds, bench/LOG.md).
    for r in range(events.shape[0]):
        for col in range(events.shape[1]):
            grown[r, col] = events[r, col]
    return grown


def _write_event(
    events: Any,
    count: int,
    kind_code: int,
    step: int,
    time: float,
    id_a: int,
    id_b: int,
    sep: Any,
    vn: float,
    j: float,
    e: float,
    before: Any,
    vel: Any,
    a: int,
    b: int,
) -> Any:
    """Append an event row, growing the buffer when full; returns the buffer."""
    events = _events_with_room(events, count, nl._int(1))
    _put_event(events, count, kind_code, step, time, id_a, id_b, sep, vn, j, e, before, vel, a, b)
    return events


def _put_event(
    events: Any,
    count: int,
    kind_code: int,
    step: int,
    time: float,
    id_a: int,
    id_b: int,
    sep: Any,
    vn: float,
    j: float,
    e: float,
    before: Any,
    vel: Any,
    a: int,
    b: int,
) -> None:
    """Write event row ``count`` (the buffer has room: :func:`_events_with_room`)."""
    events[count, 0] = kind_code
    events[count, 1] = step
    events[count, 2] = time
    events[count, 3] = id_a
    events[count, 4] = id_b
    for k in range(6):
        events[count, 5 + k] = sep[1 + k]
    events[count, 11] = vn
    events[count, 12] = j
    events[count, 13] = e
    for k in range(6):
        events[count, 14 + k] = before[k]
    for k in range(3):
        events[count, 20 + k] = vel[a, k] if a >= 0 else 0.0
        events[count, 23 + k] = vel[b, k]
