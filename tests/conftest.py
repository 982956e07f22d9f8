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
    waits for a program's output must not wait for the compiler instead."""
    from collisionlab.particles import warm_up

    warm_up()
