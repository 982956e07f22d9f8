"""A stepper's event rows (:data:`.event_rows.EVENT_COLUMNS`, one row a collision or a skipped
contact) as the record holds them: an :class:`~collisionlab.collision_events.EventBlock` of
collisions, each built only when read, and a list of
:class:`~collisionlab.record.SkippedContact`."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..collision_events import EventBlock
from ..record import SkippedContact
from . import event_rows

__all__ = ["recorded_events"]


def recorded_events(
    events: np.ndarray[Any, np.dtype[np.float64]],
    names: list[str],
    static_names: list[str],
    masses: np.ndarray[Any, np.dtype[np.float64]],
) -> tuple[EventBlock, list[SkippedContact]]:
    """The collisions of ``events`` (a body ``a < 0`` is the static ``static_names[-1 - a]``)
    and the contacts skipped as separating."""
    skipping = events[:, 0] == event_rows.EVENT_SKIPPED

    def pair(a: int, b: int) -> tuple[str, str]:
        return (static_names[-1 - a] if a < 0 else names[a], names[b])

    skipped = [
        SkippedContact(int(row[1]), row[2], pair(int(row[3]), int(row[4])), "separating")
        for row in events[skipping].tolist()
    ]
    rows = events[~skipping]
    block = EventBlock(
        step=rows[:, 1].astype(np.int64),
        time=rows[:, 2],
        a=rows[:, 3].astype(np.int64),
        b=rows[:, 4].astype(np.int64),
        normal=rows[:, 5:8],
        point=rows[:, 8:11],
        approach_speed=rows[:, 11],
        impulse=rows[:, 12],
        restitution=rows[:, 13],
        below_rest=(rows[:, 0] == event_rows.EVENT_BELOW_REST).astype(np.int64),
        before_a=rows[:, 14:17],
        before_b=rows[:, 17:20],
        after_a=rows[:, 20:23],
        after_b=rows[:, 23:26],
        names=names,
        static_names=static_names,
        masses=masses,
    )
    return block, skipped
