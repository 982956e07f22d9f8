"""A writer that works beside the stepper: :class:`BackgroundObserver` tells a run's observer
(the table, CSV or JSON writer) every frame, event and warning in a thread of its own, in the
order the world told them, while the world steps on.

A compiled world runs its kernels without the GIL (:mod:`collisionlab.engine.compiled`), so the
formatting of one chunk's events (numbers to text, lines laid out, written to disk) overlaps the
next chunk's steps instead of following it. The output is the same, byte for byte: one thread
makes every call, in order. At most ``depth`` calls wait, so memory does not grow with the run
however fast the world produces events.

Failure: whatever the writer raises (a full disk) is raised again in the caller's thread at its
next call, or at :meth:`~BackgroundObserver.end`; the calls after it are dropped. On leaving
the ``with`` block early (an error of the run, Ctrl-C), the waiting calls are dropped and the
thread is given :data:`LEAVE_WAIT` seconds to end its current call before the output file is
removed. A call that takes longer is left to end alone (its output is thrown away with the file):
on a machine's first run the writer's first block of many events compiles the text kernel
(:mod:`collisionlab.text_kernels`, about 2 s), and Ctrl-C must not wait for that.
"""

from __future__ import annotations

import contextlib
import queue
import threading
from collections.abc import Sequence
from types import TracebackType
from typing import Any

from ..record import CollisionEvent, Frame, RunObserver, RunRecord, SkippedContact
from .interrupts import abandon

__all__ = ["BackgroundObserver"]

#: Calls that may wait for the writer's thread; the world waits when they are all taken.
DEPTH = 2

#: Seconds the caller, leaving early, waits for the writer to end its current call.
LEAVE_WAIT = 0.5

_STOP = None  # put last: the thread ends


class BackgroundObserver:
    """``observer``'s calls made by a thread of their own (a :class:`RunObserver` itself); use it
    as a context manager around the run, which joins the thread on the way out.

    >>> calls = []
    >>> class Writer:
    ...     def begin(self, record): calls.append("begin")
    ...     def frame(self, frame): calls.append(f"frame {frame}")
    ...     def events(self, events, skipped, reached): calls.append(f"events {reached}")
    ...     def warning(self, text): calls.append(text)
    ...     def end(self, record): calls.append("end")
    >>> with BackgroundObserver(Writer()) as writer:
    ...     writer.begin(None); writer.frame(0); writer.events([], [], 5); writer.warning("w")
    ...     writer.frame(5); writer.end(None)
    >>> calls
    ['begin', 'frame 0', 'events 5', 'w', 'frame 5', 'end']
    """

    def __init__(self, observer: RunObserver, depth: int = DEPTH) -> None:
        self._observer = observer
        self._calls: queue.Queue[tuple[str, tuple[Any, ...]] | None] = queue.Queue(maxsize=depth)
        self._error: BaseException | None = None
        self._dropping = False  # the caller has left early: waiting calls are not made
        self._thread = threading.Thread(target=self._work, name="collisionlab-writer", daemon=True)
        self._thread.start()

    def _work(self) -> None:
        while True:
            call = self._calls.get()
            if call is _STOP:
                return
            if self._error is not None or self._dropping:
                continue
            name, arguments = call
            try:
                getattr(self._observer, name)(*arguments)
            except BaseException as error:  # raised again in the caller's thread
                self._error = error

    def _raise_error(self) -> None:
        if self._error is not None:
            error, self._error = self._error, None
            self._dropping = True
            raise error

    def _put(self, name: str, *arguments: Any) -> None:
        self._raise_error()
        self._calls.put((name, arguments))

    def _finish(self) -> None:
        """Wait until every call put so far has been made, and end the thread."""
        if self._thread.is_alive():
            self._calls.put(_STOP)
            self._thread.join()

    def begin(self, record: RunRecord) -> None:
        """Made here, at once (nothing waits yet): the record changes as the run goes on."""
        self._raise_error()
        self._observer.begin(record)

    def frame(self, frame: Frame) -> None:
        self._put("frame", frame)

    def events(self, events: Sequence[CollisionEvent], skipped: Sequence[SkippedContact], reached: int) -> None:
        self._put("events", events, skipped, reached)

    def warning(self, text: str) -> None:
        self._put("warning", text)

    def end(self, record: RunRecord) -> None:
        """The writer's last call, made here once every earlier call has been made (the record
        is final now, and read in this thread)."""
        self._finish()
        self._raise_error()
        self._observer.end(record)

    def __enter__(self) -> BackgroundObserver:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, trace: TracebackType | None
    ) -> None:
        if kind is None:
            self._finish()
            return
        self._dropping = True  # the output is thrown away: no need to write the rest
        with contextlib.suppress(queue.Empty):  # nor to wait for room behind the calls waiting
            while True:
                self._calls.get_nowait()
        self._calls.put_nowait(_STOP)  # room now: only this thread puts
        self._thread.join(LEAVE_WAIT)
        if self._thread.is_alive():
            abandon(self._thread)
