"""Which form of the engine's kernels runs: compiled (numba) or the same source as Python.

numba is a dependency: ``"auto"`` and ``"numba"`` run the compiled kernels. ``"python"`` runs
the very same functions uncompiled (for small worlds and tests: it gives the same numbers, far
more slowly). There is no second, hand-kept implementation.

numba's compiled kernels are cached in the user's cache folder, never inside the installed
package (:mod:`collisionlab.numba_cache`). ``warm_up`` (compile them ahead of a timed run) builds
a :class:`~collisionlab.particles.world.ParticleWorld`, so it lives in :mod:`.world`, which
imports this file.
"""

from __future__ import annotations

from types import ModuleType

from ..errors import InvalidInputError
from ..numba_cache import use_user_cache

__all__ = ["BACKENDS", "engine_kernels", "pick_backend"]


use_user_cache()  # numba reads NUMBA_CACHE_DIR once, when it is first imported

#: The backends by name; ``"auto"`` means numba.
BACKENDS: tuple[str, ...] = ("auto", "numba", "python")


def pick_backend(name: str) -> str:
    """``"numba"`` or ``"python"`` for a requested backend name.

    >>> pick_backend("python"), pick_backend("auto")
    ('python', 'numba')
    """
    if name not in BACKENDS:
        raise InvalidInputError("backend", f"must be one of {', '.join(BACKENDS)}", got=name)
    return "python" if name == "python" else "numba"


def engine_kernels(backend: str) -> ModuleType:
    """The engine's step kernels in the form ``backend`` names (``"numba"`` or ``"python"``)."""
    if backend == "python":
        from ..engine import step_kernels

        return step_kernels
    from ..engine import compiled

    return compiled.kernels()
