"""``collisionlab compile``: every compiled kernel loaded from numba's cache now, or compiled
(once per machine, minutes on 2 cores), so that no later run waits for the compiler. Progress on
stderr, one line per kind of kernels; then the time it all took on stdout."""

from __future__ import annotations

import argparse
import functools
import io
import time
from typing import Any

from ..engine.ahead import KERNEL_KINDS, load_kernels
from .interrupts import interruptible
from .streams import Streams

__all__ = ["add_parser"]

#: What each kind of kernels serves, for the progress lines.
_SERVES = {
    "euler": "Forward Euler (run, demo, gas)",
    "exact": "exact mode (--mode exact)",
    "solve": "solved contacts (--contacts solve)",
    "event-driven": "the event-driven gas (gas --mode exact)",
    "particles": "collisionlab.particles",
}


def add_parser(sub: Any) -> None:
    parser = sub.add_parser(
        "compile",
        help="compile every kernel now (once per machine), so that no run waits for the compiler",
        description=(
            "Load every compiled kernel from numba's cache, or compile it when the cache does not hold it "
            "(the first time on a machine: minutes). Progress on stderr; then the time it took."
        ),
    )
    parser.set_defaults(func=_compile)


def _text_kernel() -> None:
    """The output writers' text kernel: compiled by writing a compiled bouncing ball's run as JSON."""
    from ..demos import load_demo
    from ..engine import WorldParams
    from ..engine.world import World
    from .render import JsonWriter

    world = World(load_demo("bouncing-ball").with_settings(mode="euler"), WorldParams(compiled=True))
    world.run(observer=JsonWriter(io.StringIO()), keep=False)


def _compile(args: argparse.Namespace, streams: Streams) -> int:
    started = time.perf_counter()
    steps = [*KERNEL_KINDS, "text"]
    for number, kind in enumerate(steps, 1):
        streams.err(f"[{number}/{len(steps)}] {kind}: {_SERVES.get(kind, 'the output writers')}...")
        # Each in a thread of its own: a signal stops the command at once, even inside LLVM's calls.
        if kind == "text":
            began = time.perf_counter()
            interruptible(_text_kernel)
            seconds = time.perf_counter() - began
        else:
            seconds = interruptible(functools.partial(load_kernels, kind))
        streams.err(f"[{number}/{len(steps)}] {kind}: {seconds:.1f} s")
    streams.out(f"compiled every kernel in {time.perf_counter() - started:.1f} s")
    return 0
