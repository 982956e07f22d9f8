"""The writer beside the stepper (:mod:`collisionlab.cli.background`)."""

from __future__ import annotations

import threading
import time
from typing import Any

import pytest

from collisionlab.cli.background import DEPTH, BackgroundObserver


class Recorder:
    """A writer that notes each call and the thread that made it; ``gate`` holds its frames."""

    def __init__(self, fail_at: str | None = None) -> None:
        self.calls: list[tuple[str, Any, str]] = []
        self.fail_at = fail_at
        self.gate = threading.Event()
        self.gate.set()

    def _note(self, name: str, value: Any) -> None:
        self.calls.append((name, value, threading.current_thread().name))
        if name == self.fail_at:
            raise OSError(28, "No space left on device")

    def begin(self, record: Any) -> None:
        self._note("begin", record)

    def frame(self, frame: Any) -> None:
        self.gate.wait()
        self._note("frame", frame)

    def events(self, events: Any, skipped: Any, reached: int) -> None:
        time.sleep(0.001)  # slower than the caller: calls wait in the queue
        self._note("events", reached)

    def warning(self, text: str) -> None:
        self._note("warning", text)

    def end(self, record: Any) -> None:
        self._note("end", record)


def _writer_threads() -> list[threading.Thread]:
    return [t for t in threading.enumerate() if t.name == "collisionlab-writer"]


def _writer_threads_left() -> list[threading.Thread]:
    """The writer threads still alive once each has had (a generous) while to end: leaving the
    ``with`` block early waits for the writer only so long (background.LEAVE_WAIT)."""
    for thread in _writer_threads():
        thread.join(timeout=60)
    return _writer_threads()


def test_every_call_is_made_in_order_and_the_middle_ones_in_the_writers_thread() -> None:
    recorder = Recorder()
    with BackgroundObserver(recorder) as observer:
        observer.begin("record")
        for step in range(50):
            observer.frame(step)
            observer.events([], [], step)
            if step % 10 == 0:
                observer.warning(f"w{step}")
        observer.end("final")
    expected = [("begin", "record")]
    for step in range(50):
        expected += [("frame", step), ("events", step)] + ([("warning", f"w{step}")] if step % 10 == 0 else [])
    expected.append(("end", "final"))
    assert [(name, value) for name, value, _ in recorder.calls] == expected
    # begin and end in the caller's thread (the record changes during the run; at the end it is
    # final), the rest in the writer's.
    here = threading.current_thread().name
    assert {thread for name, _, thread in recorder.calls if name in ("begin", "end")} == {here}
    assert {thread for name, _, thread in recorder.calls if name not in ("begin", "end")} == {"collisionlab-writer"}
    assert _writer_threads() == []


def test_at_most_depth_calls_wait_so_memory_stays_bounded() -> None:
    recorder = Recorder()
    recorder.gate.clear()  # the writer is stuck in its first frame
    made = []

    def caller() -> None:
        for step in range(DEPTH + 5):
            observer.frame(step)
            made.append(step)

    with BackgroundObserver(recorder) as observer:
        thread = threading.Thread(target=caller)
        thread.start()
        deadline = time.monotonic() + 10.0
        while len(made) < DEPTH + 1 and time.monotonic() < deadline:
            time.sleep(0.01)
        time.sleep(0.1)  # had the queue no bound, the caller would have gone on meanwhile
        # One call taken by the writer (stuck), DEPTH waiting: the caller is held at the next.
        assert len(made) == DEPTH + 1
        recorder.gate.set()
        thread.join()
        observer.end(None)
    assert [value for name, value, _ in recorder.calls if name == "frame"] == list(range(DEPTH + 5))


def test_a_writers_error_is_raised_in_the_callers_thread_and_the_later_calls_are_dropped() -> None:
    recorder = Recorder(fail_at="events")
    with pytest.raises(OSError, match="No space left"), BackgroundObserver(recorder) as observer:
        observer.begin(None)
        observer.frame(0)
        observer.events([], [], 1)  # fails in the writer's thread
        for step in range(1, 100):  # raised at one of these calls, or at the end
            observer.frame(step)
        observer.end(None)
    names = [name for name, _, _ in recorder.calls]
    assert names[:3] == ["begin", "frame", "events"]
    assert "end" not in names
    assert len(names) < 100
    assert _writer_threads_left() == []


def test_leaving_early_drops_the_waiting_calls_and_joins_the_thread() -> None:
    recorder = Recorder()
    with pytest.raises(KeyboardInterrupt), BackgroundObserver(recorder) as observer:
        observer.frame(0)
        raise KeyboardInterrupt
    # Nothing held the writer: its thread ended (joined on the way out).
    assert [value for _, value, _ in recorder.calls] in ([0], [])
    assert _writer_threads_left() == []


def test_leaving_early_does_not_wait_for_a_writer_stuck_in_a_call() -> None:
    # A writer's call may take seconds (its first block of many events compiles the text kernel
    # on a machine's first run): Ctrl-C must not wait for it. The caller leaves; the writer's
    # call ends alone later, and the calls that were waiting are never made.
    from collisionlab.cli.interrupts import abandoned_work

    recorder = Recorder()
    recorder.gate.clear()
    try:
        with pytest.raises(KeyboardInterrupt), BackgroundObserver(recorder) as observer:
            observer.frame(0)  # taken, then stuck at the gate
            observer.frame(1)  # waiting
            observer.frame(2)  # waiting
            raise KeyboardInterrupt  # the queue is full: leaving must not wait for room either
        assert abandoned_work()  # the entry point then ends the process without waiting
    finally:
        recorder.gate.set()
    assert _writer_threads_left() == []
    assert [value for _, value, _ in recorder.calls] == [0]
    assert not abandoned_work()


@pytest.mark.parametrize(
    "module, entry",
    [("kernels", "run_steps"), ("exact_kernels", "run_exact_steps"), ("contact_kernels", "run_contact_steps")],
)
def test_the_compiled_kernels_release_the_gil_so_the_writers_thread_runs_meanwhile(module: str, entry: str) -> None:
    # The overlap rests on the kernels releasing the GIL (compiled with nogil): another Python
    # thread then runs while a chunk of steps does. (Counting what that thread did within one
    # call measured the machine's load, not this: a flaky test, so the option itself is read.)
    from collisionlab.engine import compiled

    kernel = getattr(getattr(compiled, module)(), entry)
    assert kernel.targetoptions["nogil"] is True
