"""Signals: SIGTERM and SIGHUP are handled as Ctrl-C (files written atomically are cleaned up,
one line, exit status 128 + the signal's number), and compiled loops that Python cannot
interrupt are stepped in chunks, each in a thread of its own while the main thread waits and
looks for a signal (:class:`ChunkWatch`: a chunk may last seconds). A compile
(numba's, whose LLVM passes run for seconds in C, where Python cannot run a signal's handler)
runs in a thread of its own while the main thread waits ready for a signal
(:func:`interruptible`). A signal the program was started ignoring (``nohup``, a background job)
stays ignored."""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Callable, Iterator
from types import FrameType
from typing import TypeVar

__all__ = [
    "ChunkWatch",
    "Pending",
    "Stopped",
    "abandon",
    "abandoned_work",
    "between_chunks",
    "deferred_interrupts",
    "interruptible",
    "interrupts_for",
    "remembered_interrupts",
    "stop_on_signals",
]

#: The signals handled as Ctrl-C, where the platform has them.
_SIGNALS = tuple(getattr(signal, name) for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name))

#: Seconds between two looks for a signal while :func:`interruptible` waits for its thread.
WAIT_SLICE = 0.1

_T = TypeVar("_T")

#: Threads :func:`interruptible` left running when a signal stopped the wait for them.
_abandoned: list[threading.Thread] = []


class Stopped(KeyboardInterrupt):
    """SIGTERM or SIGHUP, raised where Ctrl-C's KeyboardInterrupt would be.

    >>> Stopped(signal.SIGTERM).status, Stopped(signal.SIGTERM).name
    (143, 'SIGTERM')
    """

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum
        self.name = signal.Signals(signum).name
        self.status = 128 + signum


def _raise(signum: int, frame: FrameType | None) -> None:
    raise Stopped(signum)


@contextlib.contextmanager
def _handlers(signals: tuple[int, ...], handler: signal.Handlers | object) -> Iterator[None]:
    """Install ``handler`` for ``signals`` (only the main thread can), restoring them after. A
    signal the program was started ignoring stays ignored, as Python leaves Ctrl-C: ``nohup``
    (SIGHUP) and a shell's background jobs (SIGINT) ask for that."""
    saved: dict[int, object] = {}
    try:
        for signum in signals:
            if signal.getsignal(signum) != signal.SIG_IGN:
                saved[signum] = signal.signal(signum, handler)  # type: ignore[arg-type]
    except ValueError:  # not the main thread: leave the signals alone
        pass
    try:
        yield
    finally:
        for signum, previous in saved.items():
            signal.signal(signum, previous)  # type: ignore[arg-type]


@contextlib.contextmanager
def stop_on_signals() -> Iterator[None]:
    """Within: SIGTERM and SIGHUP raise :class:`Stopped` (a KeyboardInterrupt)."""
    with _handlers(_SIGNALS, _raise):
        yield


class Pending:
    """The first interrupt that arrived while deferred; :meth:`check` raises it."""

    def __init__(self) -> None:
        self.signum: int | None = None

    def note(self, signum: int, frame: FrameType | None) -> None:
        if self.signum is None:
            self.signum = signum

    def check(self) -> None:
        if self.signum == signal.SIGINT:
            raise KeyboardInterrupt
        if self.signum is not None:
            raise Stopped(self.signum)


@contextlib.contextmanager
def deferred_interrupts() -> Iterator[Pending]:
    """Within: Ctrl-C, SIGTERM and SIGHUP are only noted, for the caller to :meth:`Pending.check`
    between chunks of work that cannot be interrupted (a numba kernel: an exception raised in
    its middle surfaces as "SystemError: CPUDispatcher returned a result with an exception set")."""
    pending = Pending()
    with _handlers((signal.SIGINT, *_SIGNALS), pending.note):
        yield pending
    pending.check()  # one that came after the caller's last look still stops the program


@contextlib.contextmanager
def remembered_interrupts() -> Iterator[Pending]:
    """Within: Ctrl-C, SIGTERM and SIGHUP raise at once, as usual, and are also noted, for the
    caller to :meth:`Pending.check` again. Python prints and drops an exception raised while a
    garbage-collector callback runs (dask's ``distributed`` installs one), so the raise alone
    can be lost; the note is not."""
    pending = Pending()

    def note_and_raise(signum: int, frame: FrameType | None) -> None:
        pending.note(signum, frame)
        pending.check()

    with _handlers((signal.SIGINT, *_SIGNALS), note_and_raise):
        yield pending


def interrupts_for(compiled: bool) -> contextlib.AbstractContextManager[Pending]:
    """How a loop of steps hears Ctrl-C, SIGTERM and SIGHUP: a compiled kernel cannot be stopped
    inside a call, so the signal is only noted (:func:`deferred_interrupts`), and raised between
    chunks or by the thread waiting for one (:class:`ChunkWatch`); the
    kernels' Python form can, and one of its steps may take seconds (200,000 balls: about 5 s),
    so there the signal raises at once (:func:`remembered_interrupts`)."""
    return deferred_interrupts() if compiled else remembered_interrupts()


def between_chunks(pending: Pending, progress: Callable[[int, int], None] | None = None) -> Callable[[int, int], None]:
    """What runs between two chunks of compiled steps: a deferred signal is raised and
    ``progress`` is told (:class:`ChunkWatch` looks for a signal during a chunk too)."""

    def between(done: int, total: int) -> None:
        pending.check()
        if progress is not None:
            progress(done, total)

    return between


class ChunkWatch:
    """How the command line runs a compiled world's steps: a signal stops it within a moment
    even inside a chunk of steps that runs for seconds (a pile forming: one chunk, sized on the
    early fast steps, took 13.7 s; SIGINT waited for its end), and progress keeps being told.

    :meth:`call` (a world's ``calling=``) runs each chunk in a thread of its own (the compiled
    kernels release the GIL) while this thread waits, looking every :data:`WAIT_SLICE` seconds
    at ``pending`` (the signals are only noted meanwhile, :func:`deferred_interrupts`, never
    raised inside a compiled call) and telling ``progress`` again where the run stands (a
    progress line every 10 s goes on through a long chunk). A signal is raised here and the
    chunk is left behind, unfinished, as a compile is (:func:`interruptible`): the command leaves
    as for a signal between chunks, its files unwritten. :meth:`between` (a world's
    ``progress=``) runs between chunks: :func:`between_chunks`.
    """

    def __init__(self, pending: Pending, progress: Callable[[int, int], None] | None = None) -> None:
        self.pending = pending
        self.progress = progress
        self._between = between_chunks(pending, progress)
        self._reached: tuple[int, int] | None = None  # (done, total) at the last chunk's end

    def between(self, done: int, total: int) -> None:
        self._reached = (done, total)
        self._between(done, total)

    def call(self, work: Callable[[], None]) -> None:
        interruptible(work, tick=self._tick, name="collisionlab-steps")

    def _tick(self) -> None:
        self.pending.check()
        if self.progress is not None and self._reached is not None:
            self.progress(*self._reached)


def interruptible(
    work: Callable[[], _T], tick: Callable[[], None] | None = None, name: str = "collisionlab-compile"
) -> _T:
    """``work()``, run in a thread of its own while this one waits for it, looking for a signal
    every :data:`WAIT_SLICE` seconds; its result, or what it raised, raised here.

    For what compiles (a world's kernels loaded ahead: numba compiles them on a machine's first
    run): Python runs a signal's handler in the main thread only, between two of its bytecodes,
    and one call of LLVM's passes holds the thread in C for seconds (up to 3.1 s measured in a
    cold compile on 2 busy cores), so Ctrl-C, SIGTERM or SIGHUP waited for it. Here the main
    thread only waits, and the handler's exception (KeyboardInterrupt, :class:`Stopped`) is
    raised at once and leaves the compile behind, unfinished (a daemon thread: numba writes its
    cache only for a finished compile; the entry point then ends the process without waiting,
    :func:`abandoned_work`). ``tick()`` is called in this thread at every look (it may raise: a
    deferred signal, :class:`ChunkWatch`). Outside the main thread, ``work()`` is simply called.

    >>> interruptible(lambda: 6 * 7)
    42
    """
    if threading.current_thread() is not threading.main_thread():
        return work()
    result: list[_T] = []
    failure: list[BaseException] = []
    done = threading.Event()

    def run() -> None:
        try:
            result.append(work())
        except BaseException as error:  # raised again in the waiting thread
            failure.append(error)
        finally:
            done.set()

    thread = threading.Thread(target=run, name=name, daemon=True)
    thread.start()
    try:
        while not done.wait(WAIT_SLICE):  # a signal's handler runs, and may raise, between two waits
            if tick is not None:
                tick()
    except BaseException:
        abandon(thread)
        raise
    thread.join()
    if failure:
        raise failure[0]
    return result[0]


def abandon(thread: threading.Thread) -> None:
    """Note ``thread`` (a daemon) as work left running after a signal or an error stopped the
    command: :func:`abandoned_work` then says so."""
    _abandoned[:] = [*(t for t in _abandoned if t.is_alive()), thread]


def abandoned_work() -> bool:
    """Whether work that :func:`interruptible` left behind is still running: the process should
    then end without Python's usual exit, which would run finalizers beside it (numba's, LLVM's
    objects freed while their compile still uses them)."""
    return any(thread.is_alive() for thread in _abandoned)
