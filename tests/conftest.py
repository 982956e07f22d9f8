"""Suite-wide settings: hypothesis', and the signals every test process starts with.

No deadline: a test must not fail because a machine is slow (the suite has no time limits
inside tests). The example count stays at hypothesis' default of 100.
"""

from __future__ import annotations

import io
import os
import signal

import pytest
from hypothesis import settings

settings.register_profile("collisionlab", deadline=None)
settings.load_profile("collisionlab")


def pytest_configure(config: pytest.Config) -> None:
    """A suite started under ``nohup``, or as a background job of a shell script, inherits
    SIGHUP or SIGINT (and SIGQUIT) ignored, and so would every program it starts: the tests that
    send a running command a signal would wait for it in vain, and those that check the
    handlers a command restores would see ``SIG_IGN`` (seen: 23 such failures in a clone run
    with ``nohup ... &``). Each test process (the main one and every xdist worker) starts with
    Python's own dispositions instead, which the programs it starts then inherit as the
    default."""
    for number in (signal.SIGINT, signal.SIGHUP, signal.SIGTERM, signal.SIGQUIT):
        if signal.getsignal(number) == signal.SIG_IGN:
            signal.signal(number, signal.default_int_handler if number == signal.SIGINT else signal.SIG_DFL)


@pytest.fixture(scope="session", autouse=True)
def _compiled_engine() -> None:
    """Compile the engine's kernels (or load numba's cache) once, before any test: a test that
    waits for a program's output must not wait for the compiler instead. All four steppers:
    Forward Euler, exact (events and the contact solver), event-driven, the particle kernels,
    and the kernel that lays out the JSON of a world's collisions (a bouncing ball's run written
    as JSON). Under pytest-xdist, two workers compile different kernels at once, and each then
    loads the other's from numba's cache (its writes are atomic)."""
    from collisionlab.cli.render import JsonWriter
    from collisionlab.demos import load_demo
    from collisionlab.edmd.observables import ExactGas
    from collisionlab.engine import WorldParams
    from collisionlab.engine.world import World
    from collisionlab.particles import warm_up

    def euler() -> None:
        World(load_demo("bouncing-ball").with_settings(mode="euler"), WorldParams(compiled=True)).step(2)

    def exact() -> None:
        World(load_demo("bouncing-ball").with_settings(mode="exact"), WorldParams(compiled=True)).step(2)

    def contacts() -> None:
        scenario = load_demo("bouncing-ball").with_settings(mode="exact", contacts="solve")
        World(scenario, WorldParams(compiled=True)).step(2)

    def event_driven() -> None:
        ExactGas(n=20, dim=2, fraction=0.1, time=0.1).world().run(0.1)

    def json_lines() -> None:
        world = World(load_demo("bouncing-ball").with_settings(mode="euler"), WorldParams(compiled=True))
        world.run(observer=JsonWriter(io.StringIO()), keep=False)

    # The exact kernel is the long compile, and it calls the step kernels: even workers compile
    # those (euler), then it; odd ones compile what shares nothing with them (the event-driven
    # kernels, the particles'), then the contact solver (its step kernels are in the cache by
    # then), then wait (numba_cache.compile_lock) and load the exact kernel, instead of
    # compiling anything twice. Each worker's share is then about half of the whole.
    odd = int(os.environ.get("PYTEST_XDIST_WORKER", "gw0").removeprefix("gw") or 0) % 2
    order = [event_driven, warm_up, json_lines, contacts, euler, exact] if odd else [euler, exact, json_lines]
    for compile_or_load in order + ([] if odd else [event_driven, warm_up, contacts]):
        compile_or_load()
