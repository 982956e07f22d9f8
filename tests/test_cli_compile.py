"""``collisionlab compile`` (issue 28): every kernel loaded or compiled ahead of any run."""

from __future__ import annotations

import io
import os
import re
import signal
import subprocess

import pytest

from collisionlab.cli.compile_command import compile_side_by_side
from collisionlab.cli.streams import Streams
from collisionlab.errors import CollisionLabError
from tests.cli_helpers import run_cli


def test_compile_exits_0_with_progress_on_stderr_and_its_time_on_stdout() -> None:
    result = run_cli(["compile"])
    assert result.status == 0, result.err
    assert re.fullmatch(r"compiled every kernel in \d+\.\d s\n", result.out)
    progress = result.err.splitlines()
    assert progress[0].startswith("[1/6] euler") and progress[-1].startswith("[6/6] text: ")


# --- kinds compiled side by side (a process each) -------------------------------------------------
class _Fake:
    """A stand-in for a compiling process: done after ``polls`` looks, with ``status``."""

    def __init__(self, kind: str, polls: int, status: int, log: list[str]) -> None:
        self.kind, self.left, self.status, self.log = kind, polls, status, log
        self.returncode: int | None = None
        log.append(f"start {kind}")

    def poll(self) -> int | None:
        self.left -= 1
        if self.left <= 0:
            self.returncode = self.status
        return self.returncode

    def communicate(self) -> tuple[str, str]:
        self.log.append(f"end {self.kind}")
        return "1.0\n", "" if self.status == 0 else "Traceback ...\ncollisionlab: no space left\n"

    def terminate(self) -> None:
        self.log.append(f"terminate {self.kind}")

    def kill(self) -> None:
        self.log.append(f"kill {self.kind}")

    def wait(self, timeout: float | None = None) -> int:
        return -15


def test_kinds_compile_at_most_jobs_at_a_time_longest_first_and_each_says_when_it_ends() -> None:
    log: list[str] = []
    polls = {"exact": 3, "event-driven": 1, "solve": 1}
    streams, out, err = _streams()
    compile_side_by_side(["exact", "event-driven", "solve"], 2, streams, lambda k: _Fake(k, polls[k], 0, log))
    # two at once: solve starts only when event-driven has ended, and exact (the longest) goes on
    assert log == ["start exact", "start event-driven", "end event-driven", "start solve", "end solve", "end exact"]
    lines = err.getvalue().splitlines()
    assert lines[:2] == [
        "[2/6] exact: exact mode (--mode exact)...",
        "[4/6] event-driven: the event-driven gas (gas --mode exact)...",
    ]
    assert [line.split(":")[0] for line in lines if line.endswith(" s")] == [
        "[4/6] event-driven",
        "[3/6] solve",
        "[2/6] exact",
    ]
    assert out.getvalue() == ""


def test_a_failing_kind_stops_the_others_and_says_its_last_line() -> None:
    log: list[str] = []
    streams, _, _ = _streams()
    with pytest.raises(CollisionLabError, match=r"^compiling the solve kernels failed: collisionlab: no space left$"):
        compile_side_by_side(["exact", "solve"], 2, streams, lambda k: _Fake(k, 5 if k == "exact" else 1, 1, log))
    assert "terminate exact" in log and "end exact" not in log


def _streams() -> tuple[Streams, io.StringIO, io.StringIO]:
    out, err = io.StringIO(), io.StringIO()
    return Streams(stdin=io.StringIO(), stdout=out, stderr=err, interactive=False, err_terminal=False), out, err


class _Deaf(_Fake):
    """A compiling process that does not end on SIGTERM."""

    def wait(self, timeout: float | None = None) -> int:
        if timeout is not None:
            raise subprocess.TimeoutExpired("collisionlab compile --only exact", timeout)
        return -9


def test_a_process_deaf_to_sigterm_is_killed_rather_than_left_compiling() -> None:
    log: list[str] = []
    streams, _, _ = _streams()
    children = {"exact": lambda: _Deaf("exact", 5, 0, log), "solve": lambda: _Fake("solve", 1, 1, log)}
    with pytest.raises(CollisionLabError):
        compile_side_by_side(["exact", "solve"], 2, streams, lambda k: children[k]())
    assert log[-2:] == ["terminate exact", "kill exact"]


def test_a_signal_while_a_process_starts_still_stops_that_process() -> None:
    # Under load, SIGTERM reached the command inside subprocess.Popen, after its fork: raised
    # there, the process it was starting was never known, and went on compiling after the command
    # ended (a fresh clone's test run, two copies at once). Here the signal comes inside launch.
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        pytest.skip("SIGINT is ignored in this process (it then stays ignored, as the command leaves it)")
    log: list[str] = []
    streams, _, _ = _streams()

    def launch(kind: str) -> _Fake:
        if kind == "solve":
            os.kill(os.getpid(), signal.SIGINT)  # Ctrl-C, between the fork and Popen's return
        return _Fake(kind, 1000, 0, log)

    with pytest.raises(KeyboardInterrupt):
        compile_side_by_side(["exact", "solve"], 2, streams, launch)
    assert "terminate exact" in log and "terminate solve" in log
