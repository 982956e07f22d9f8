"""Stream the collisions of a run to a file, block by block: CSV or JSON lines.

Nothing is held in memory beyond one block of events (what the world hands over after each
chunk of steps); the file is written
beside its target and renamed over it only when the run ends well (:mod:`collisionlab.atomic`),
so a failed run leaves no half-written file.

One line per collision: the time, the two bodies (indices from 0; a wall is named by its axis
and side, ``x-`` the wall at 0, ``x+`` the wall at ``L``), and the impulse magnitude
``|dp|`` each gave the other::

    time,a,b,impulse                       {"time": 1.0, "pair": [0, 1], "impulse": 2.0}
    1,0,1,2                                {"time": 1.5, "pair": [3, "y-"], "impulse": 0.4}
"""

from __future__ import annotations

import contextlib
import json
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import TextIO

import numpy as np
from numpy.typing import NDArray

from ..atomic import atomic_stream
from ..collision_events import EventBlock
from ..errors import InvalidInputError
from ..record import CollisionEvent, Frame, RunRecord, SkippedContact

__all__ = ["EVENT_FORMATS", "EventsFile", "event_file", "event_format", "rows_file", "wall_name"]

#: File extensions and the format each means.
EVENT_FORMATS: dict[str, str] = {".csv": "csv", ".jsonl": "jsonl", ".ndjson": "jsonl"}


def wall_name(code: int) -> str:
    """The name of the wall coded ``-1 - w`` in an event (``w = 2 axis + side``).

    >>> wall_name(-1), wall_name(-2), wall_name(-3)
    ('x-', 'x+', 'y-')
    """
    w = -1 - code
    return "xyz"[w // 2] + ("+" if w % 2 else "-")


def event_format(path: str | Path) -> str:
    """``"csv"`` or ``"jsonl"`` from the file's extension (:class:`InvalidInputError` otherwise)."""
    kind = EVENT_FORMATS.get(Path(path).suffix.lower())
    if kind is None:
        raise InvalidInputError("events", "must end in .csv or .jsonl (JSON lines)", got=str(path))
    return kind


class EventsFile:
    """Writes a world's collisions to an open text file as they happen, one line each: a
    :class:`~collisionlab.record.RunObserver` of the events alone (``World.listen``). Bodies are
    written by their index in the order given, a wall by its name (``x-``); a body comes first."""

    def __init__(self, out: TextIO, kind: str) -> None:
        self._out, self._kind = out, kind

    def begin(self, record: RunRecord) -> None:
        pass

    def frame(self, frame: Frame) -> None:
        pass

    def warning(self, text: str) -> None:
        pass

    def end(self, record: RunRecord) -> None:
        pass

    def events(self, events: Sequence[CollisionEvent], skipped: Sequence[SkippedContact], reached: int) -> None:
        if not isinstance(events, EventBlock):
            raise TypeError("an events file is written from a world's event blocks")
        self._write(events.time.tolist(), events.a.tolist(), events.b.tolist(), events.impulse.tolist())

    def rows(self, block: NDArray[np.float64]) -> None:
        """Write a block of :meth:`EventDrivenWorld.run <collisionlab.edmd.world.EventDrivenWorld.run>`'s
        rows (time, a, b or ``-1 - wall``, impulse): as the engine orders a pair, the lower
        index first (a mixture, run on its world alone, writes its events through this)."""
        a = block[:, 1].astype(np.int64)
        b = block[:, 2].astype(np.int64)
        low = np.where(b < 0, b, np.minimum(a, b))  # a wall (negative) first, as the engine's rows
        high = np.where(b < 0, a, np.maximum(a, b))
        self._write(block[:, 0].tolist(), low.tolist(), high.tolist(), block[:, 3].tolist())

    def _write(self, times: list[float], a: list[int], b: list[int], impulses: list[float]) -> None:
        wall = [x < 0 for x in a]
        first = [y if w else x for x, y, w in zip(a, b, wall, strict=True)]
        second: list[int | str] = [wall_name(x) if w else y for x, y, w in zip(a, b, wall, strict=True)]
        rows = zip(times, first, second, impulses, strict=True)
        if self._kind == "csv":
            self._out.write("".join(f"{t!r},{i},{j},{p!r}\n" for t, i, j, p in rows))
        else:
            self._out.write(
                "".join(json.dumps({"time": t, "pair": [i, j], "impulse": p}) + "\n" for t, i, j, p in rows)
            )


@contextlib.contextmanager
def rows_file(path: str | Path) -> Iterator[Callable[[NDArray[np.float64]], None]]:
    """:func:`event_file` as an :data:`~collisionlab.edmd.world.EventSink`: the writer of
    :meth:`EventsFile.rows`."""
    with event_file(path) as events:
        yield events.rows


@contextlib.contextmanager
def event_file(path: str | Path) -> Iterator[EventsFile]:
    """An :class:`EventsFile` writing to ``path`` (format from its extension), written whole or
    not at all."""
    kind = event_format(path)
    with atomic_stream(path, newline="") as out:
        if kind == "csv":
            out.write("time,a,b,impulse\n")
        yield EventsFile(out, kind)
