"""Signals as the command line handles them (:mod:`collisionlab.cli.interrupts`)."""

from __future__ import annotations

import gc
import os
import signal
import subprocess
import sys
from typing import Any

import pytest

from collisionlab.cli.interrupts import remembered_interrupts


def test_an_interrupt_that_python_drops_inside_a_gc_callback_is_still_seen() -> None:
    # dask's distributed runs a garbage-collector callback; a Ctrl-C that lands while one runs is
    # printed as "Exception ignored in ..." and dropped by Python. CI once saw a sweep run on to
    # its end (exit 0) after such a Ctrl-C.
    dropped: list[Any] = []

    def callback(phase: str, info: dict[str, int]) -> None:
        if phase == "start":
            os.kill(os.getpid(), signal.SIGINT)
            for _ in range(10_000):  # the handler runs at the next bytecode boundary: here
                pass

    saved_hook = sys.unraisablehook
    sys.unraisablehook = dropped.append
    gc.callbacks.append(callback)
    try:
        with remembered_interrupts() as pending:
            gc.collect()  # returns: the interrupt raised in the callback was dropped
            assert [type(d.exc_value) for d in dropped] == [KeyboardInterrupt]  # the premise
            with pytest.raises(KeyboardInterrupt):
                pending.check()
    finally:
        gc.callbacks.remove(callback)
        sys.unraisablehook = saved_hook


def test_outside_the_block_the_handlers_are_restored() -> None:
    before = signal.getsignal(signal.SIGINT)
    with remembered_interrupts():
        assert signal.getsignal(signal.SIGINT) is not before
    assert signal.getsignal(signal.SIGINT) is before


def test_ctrl_c_stops_a_python_form_gas_inside_its_step(monkeypatch: pytest.MonkeyPatch) -> None:
    # The kernels' Python form can be stopped anywhere, and one of its steps of 200,000 balls
    # takes seconds: Ctrl-C must not wait for the step to end (it did: up to 5 s), as it must
    # for a compiled call. The signal arrives after the step's first phase (integrate); the
    # step's next phase (the grid) must not run.
    from collisionlab.engine import step_kernels
    from tests.cli_helpers import run_cli

    integrate, grid_plan = step_kernels._integrate, step_kernels._grid_plan
    later: list[int] = []

    def integrate_then_ctrl_c(*args: Any) -> None:
        integrate(*args)
        os.kill(os.getpid(), signal.SIGINT)
        for _ in range(10_000):  # the handler runs at the next bytecode boundary: here
            pass

    def grid_plan_seen(*args: Any) -> Any:
        later.append(1)
        return grid_plan(*args)

    monkeypatch.setattr(step_kernels, "_integrate", integrate_then_ctrl_c)
    monkeypatch.setattr(step_kernels, "_grid_plan", grid_plan_seen)
    result = run_cli(["gas", "--n", "50", "--steps", "5", "--backend", "python"])
    assert result.status == 130 and result.err.strip().splitlines()[-1] == "collisionlab: interrupted"
    assert later == []


def test_a_python_form_gas_interrupted_says_so_in_one_line() -> None:
    # The command as a user runs it: SIGINT once it has said it is stepping; the documented
    # status (130) and one line, no traceback. (20 steps of 20,000 balls in Python take seconds:
    # the run ends, and the test with it, even if the notice were never written.)
    command = [sys.executable, "-m", "collisionlab", "gas", "--n", "20000", "--steps", "20", "--backend", "python"]
    with subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as process:
        assert process.stderr is not None
        first = process.stderr.readline()
        assert "stepping with the kernels' Python form" in first
        process.send_signal(signal.SIGINT)
        out, err = process.communicate()
    assert process.returncode == 130
    assert err.strip() == "collisionlab: interrupted" and out == ""
