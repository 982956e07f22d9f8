"""Suite-wide hypothesis settings.

No deadline: a test must not fail because a machine is slow (the suite has no time limits
inside tests). The example count stays at hypothesis' default of 100.
"""

from __future__ import annotations

import pytest
from hypothesis import settings

settings.register_profile("collisionlab", deadline=None)
settings.load_profile("collisionlab")


@pytest.fixture(scope="session", autouse=True)
def _compiled_engine() -> None:
    """Compile the engine's kernels (or load numba's cache) once, before any test: a test that
    waits for a program's output must not wait for the compiler instead. All three steppers:
    Forward Euler, exact, event-driven."""
    from collisionlab.demos import load_demo
    from collisionlab.edmd.observables import ExactGas
    from collisionlab.engine import WorldParams
    from collisionlab.engine.world import World
    from collisionlab.particles import warm_up

    warm_up()
    World(load_demo("bouncing-ball"), WorldParams(compiled=True)).step(2)
    ExactGas(n=20, dim=2, fraction=0.1, time=0.1).world().run(0.1)
