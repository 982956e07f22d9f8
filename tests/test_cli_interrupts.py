"""Signals as the command line handles them (:mod:`collisionlab.cli.interrupts`)."""

from __future__ import annotations

import gc
import os
import signal
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
