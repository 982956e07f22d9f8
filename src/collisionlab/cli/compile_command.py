"""``collisionlab compile``: every compiled kernel loaded from numba's cache now, or compiled
(once per machine, minutes on 2 cores), so that no later run waits for the compiler. Progress on
stderr, one line as each kind of kernels starts and one as it ends; then the time it all took on
stdout.

The kinds that are not in the cache yet compile side by side, one process each, as many at once
as ``--jobs`` (by default as many as the machine has cores, at most 4): numba compiles in one
thread, and the kinds share nothing but the cache. A helper two kinds call is compiled by
whichever comes to it first and loaded by the other if its files are written by then (or
compiled by both); numba writes each cache file whole, to a temporary name it then renames. The
longest first, so that the last to end is a short one (bench/README.md has each kind's time)."""

from __future__ import annotations

import argparse
import functools
import io
import os
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from typing import Any, Protocol

from ..engine.ahead import KERNEL_KINDS, is_cached, load_kernels
from ..errors import CollisionLabError
from .interrupts import deferred_interrupts, interruptible
from .streams import Streams

__all__ = ["add_parser", "compile_side_by_side"]

#: What each kind of kernels serves, for the progress lines.
_SERVES = {
    "euler": "Forward Euler (run, demo, gas)",
    "exact": "exact mode (--mode exact)",
    "solve": "solved contacts (--contacts solve)",
    "event-driven": "the event-driven gas (gas --mode exact)",
    "particles": "collisionlab.particles",
}

#: Every step of the command, in the order of its progress lines' numbers.
_STEPS = (*KERNEL_KINDS, "text")

#: The kinds whose compile takes minutes, longest first (bench/README.md, ``collisionlab compile``);
#: the others take a second or two and run in this process, after them (the text kernel is
#: compiled by a compiled Euler run, so it waits for Euler's kernels anyway).
_LONG = ("exact", "event-driven", "solve", "euler")

#: Seconds between two looks at the processes compiling side by side (a signal is handled within
#: one look).
_LOOK = 0.1
#: Seconds a compiling process is given to end after SIGTERM before it is killed.
_GRACE = 5.0


class _Child(Protocol):
    """What :func:`compile_side_by_side` needs of a process (:class:`subprocess.Popen`)."""

    returncode: int | None

    def poll(self) -> int | None: ...

    def communicate(self) -> tuple[str, str]: ...

    def terminate(self) -> None: ...

    def kill(self) -> None: ...

    def wait(self, timeout: float | None = None) -> int: ...


def add_parser(sub: Any) -> None:
    parser = sub.add_parser(
        "compile",
        help="compile every kernel now (once per machine), so that no run waits for the compiler",
        description=(
            "Load every compiled kernel from numba's cache, or compile it when the cache does not hold it "
            "(the first time on a machine: minutes; the kinds not in the cache compile side by side, one "
            "process each). Progress on stderr; then the time it took."
        ),
    )
    parser.add_argument(
        "--jobs",
        type=_jobs,
        default=min(4, os.cpu_count() or 1),
        metavar="N",
        help="kinds of kernels compiled at once, a process each (default: the cores, at most 4; 1: one after another)",
    )
    parser.add_argument("--only", choices=_LONG, help=argparse.SUPPRESS)  # one kind: what each process runs
    parser.set_defaults(func=_compile)


def _jobs(text: str) -> int:
    """``--jobs``: a whole number of at least 1."""
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a whole number of at least 1, got {text!r}")
    return value


def _text_kernel() -> None:
    """The output writers' text kernel: compiled by writing a compiled bouncing ball's run as JSON."""
    from ..demos import load_demo
    from ..engine import WorldParams
    from ..engine.world import World
    from .render import JsonWriter

    world = World(load_demo("bouncing-ball").with_settings(mode="euler"), WorldParams(compiled=True))
    world.run(observer=JsonWriter(io.StringIO()), keep=False)


def _in_process(kind: str) -> float:
    """Load or compile ``kind`` here; the seconds it took. In a thread of its own: a signal stops
    the command at once, even inside LLVM's calls."""
    if kind == "text":
        began = time.perf_counter()
        interruptible(_text_kernel)
        return time.perf_counter() - began
    return interruptible(functools.partial(load_kernels, kind))


def _launch(kind: str) -> _Child:
    """A process of this command that compiles ``kind`` alone and prints the seconds it took."""
    command = [sys.executable, "-m", "collisionlab", "compile", "--only", kind]
    return subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _label(kind: str) -> str:
    return f"[{_STEPS.index(kind) + 1}/{len(_STEPS)}] {kind}"


def compile_side_by_side(
    kinds: Sequence[str], jobs: int, streams: Streams, launch: Callable[[str], _Child] = _launch
) -> None:
    """Compile ``kinds`` in that order, up to ``jobs`` at once, a process each (``launch``); a line
    on stderr as each starts and as each ends. A process that fails stops the rest, and its
    stderr is raised as the error; so does a signal (the processes are stopped first). Signals
    are only noted while a process starts, and raised between two looks: one raised inside
    :class:`subprocess.Popen`, after its fork, would leave that process compiling unknown."""
    waiting = list(kinds)
    running: dict[str, tuple[_Child, float]] = {}
    with deferred_interrupts() as pending:
        try:
            while waiting or running:
                while waiting and len(running) < jobs:
                    kind = waiting.pop(0)
                    streams.err(f"{_label(kind)}: {_SERVES[kind]}...")
                    running[kind] = (launch(kind), time.perf_counter())
                    pending.check()
                time.sleep(_LOOK)
                pending.check()
                for kind, (child, began) in list(running.items()):
                    if child.poll() is None:
                        continue
                    del running[kind]
                    out, err = child.communicate()
                    if child.returncode != 0:
                        said = (err.strip() or out.strip() or f"exit status {child.returncode}").splitlines()[-1]
                        raise CollisionLabError(f"compiling the {kind} kernels failed: {said}")
                    streams.err(f"{_label(kind)}: {time.perf_counter() - began:.1f} s")
        finally:  # (a second signal is only noted: the processes are stopped all the same)
            for child, _ in running.values():
                child.terminate()
            for child, _ in running.values():
                try:
                    child.wait(timeout=_GRACE)
                except subprocess.TimeoutExpired:  # deaf to SIGTERM: not left compiling
                    child.kill()
                    child.wait()


def _compile(args: argparse.Namespace, streams: Streams) -> int:
    if args.only is not None:
        streams.out(f"{_in_process(args.only):.1f}")
        return 0
    started = time.perf_counter()
    apart = [kind for kind in _LONG if not is_cached(kind)] if args.jobs > 1 else []
    if len(apart) > 1:
        compile_side_by_side(apart, args.jobs, streams)
    for kind in _STEPS:
        if kind in apart and len(apart) > 1:
            continue
        streams.err(f"{_label(kind)}: {_SERVES.get(kind, 'the output writers')}...")
        streams.err(f"{_label(kind)}: {_in_process(kind):.1f} s")
    streams.out(f"compiled every kernel in {time.perf_counter() - started:.1f} s")
    return 0
