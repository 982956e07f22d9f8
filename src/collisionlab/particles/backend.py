"""Which implementation of the particle kernels runs: compiled (numba) or plain numpy.

numba is a dependency, but optional at run time (where it cannot be installed, the numpy path
still works). ``"auto"`` takes numba when it imports, else numpy; both give the same numbers to
the last bit, numba much faster (bench/README.md has the figures).

numba's compiled kernels are cached in the user's cache folder, never inside the installed
package (:mod:`collisionlab.numba_cache`).
"""

from __future__ import annotations

from types import ModuleType

import numpy as np

from ..errors import InvalidInputError
from ..numba_cache import use_user_cache

__all__ = ["BACKENDS", "compiled_kernels", "pick_backend", "warm_up"]


use_user_cache()  # numba reads NUMBA_CACHE_DIR once, when it is first imported: by compiled_kernels()

#: The backends by name; ``"auto"`` means numba when it is installed.
BACKENDS: tuple[str, ...] = ("auto", "numba", "numpy")


def compiled_kernels() -> ModuleType | None:
    """The numba kernels module, or ``None`` when numba is not installed."""
    try:
        from . import kernels
    except ImportError:
        return None
    return kernels


def pick_backend(name: str) -> str:
    """``"numba"`` or ``"numpy"`` for a requested backend name.

    >>> pick_backend("numpy")
    'numpy'
    """
    if name not in BACKENDS:
        raise InvalidInputError("backend", f"must be one of {', '.join(BACKENDS)}", got=name)
    if name == "numpy":
        return "numpy"
    if compiled_kernels() is None:
        if name == "numba":
            raise InvalidInputError("backend", "numba is not installed (pip install numba)")
        return "numpy"
    return "numba"


def warm_up() -> bool:
    """Compile the numba kernels now (or load them from numba's on-disk cache, which takes well
    under a second), so that a timed run does not include the compile. Returns whether numba is
    in use."""
    if compiled_kernels() is None:
        return False
    from .world import ParticleWorld

    world = ParticleWorld(
        np.array([[0.0, 0.0], [1.5, 0.0]]),
        np.array([[1.0, 0.0], [-1.0, 0.0]]),
        1.0,
        box=((-3.0, -3.0), (3.0, 3.0)),
        backend="numba",
    )
    world.step(0.1, steps=2)
    world.overlapping_pairs()
    return True
