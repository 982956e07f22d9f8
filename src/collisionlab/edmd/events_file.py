"""Stream the collisions of a run to a file, block by block: CSV or JSON lines.

Nothing is held in memory beyond one block of the compiled loop's buffer; the file is written
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
from collections.abc import Iterator
from pathlib import Path
from typing import TextIO

import numpy as np
from numpy.typing import NDArray

from ..atomic import atomic_path
from ..errors import InvalidInputError
from .world import EventSink

__all__ = ["EVENT_FORMATS", "event_file", "event_format", "wall_name"]

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


def _other(code: int) -> int | str:
    return code if code >= 0 else wall_name(code)


def _write(out: TextIO, kind: str, block: NDArray[np.float64]) -> None:
    times = block[:, 0].tolist()
    a = block[:, 1].astype(np.int64).tolist()
    b = block[:, 2].astype(np.int64).tolist()
    impulses = block[:, 3].tolist()
    if kind == "csv":
        out.write("".join(f"{t!r},{i},{_other(j)},{p!r}\n" for t, i, j, p in zip(times, a, b, impulses, strict=True)))
    else:
        out.write(
            "".join(
                json.dumps({"time": t, "pair": [i, _other(j)], "impulse": p}) + "\n"
                for t, i, j, p in zip(times, a, b, impulses, strict=True)
            )
        )


@contextlib.contextmanager
def event_file(path: str | Path) -> Iterator[EventSink]:
    """A sink for :meth:`EventDrivenWorld.run` writing to ``path`` (format from its extension)."""
    kind = event_format(path)
    with atomic_path(path) as temporary, open(temporary, "w", encoding="utf-8", newline="") as out:
        if kind == "csv":
            out.write("time,a,b,impulse\n")

        def sink(block: NDArray[np.float64]) -> None:
            _write(out, kind, block)

        yield sink
