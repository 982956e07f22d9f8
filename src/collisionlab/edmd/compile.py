"""How the event-driven kernels are compiled: numba, once per machine (``cache=True``).

``error_model="numpy"`` lets a division by zero give inf instead of raising (the predictions
divide by speeds that may be zero, and an infinite time is the right answer: never).
Contractions of ``a * b + c`` into fused multiply-adds stay off, so that results do not depend
on the instruction set of the machine that compiled them.

numba recompiles a cached function when *its own* file changes, not when a function it inlines
from another file does: so the package's cached code is dropped, before anything compiles,
when any of its files, the engine's geometry kernels (the contact law and the time of impact of
two balls, inlined here) or the tolerances is newer than it.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar, cast

from ..numba_cache import cache_files, forget_stale, use_user_cache

use_user_cache()  # before numba is first imported: its cache goes to the user's cache folder
_HERE = Path(__file__).resolve().parent
#: The package's compiled modules (the rest is plain Python around them).
_COMPILED = ("calendar", "cells", "compile", "layout", "loop", "predict")
_INLINED = (_HERE.parent / "engine" / "geometry_kernels.py", _HERE.parent / "tolerances.py")
forget_stale(_HERE, _COMPILED, [*(_HERE / f"{stem}.py" for stem in _COMPILED), *_INLINED])

import numba  # noqa: E402  (after the cache folder is set)

__all__ = ["is_cached", "jit", "jit_inline"]

_F = TypeVar("_F", bound=Callable[..., Any])


def jit(function: _F) -> _F:
    """Compile ``function`` with numba (nopython, cached on disk)."""
    return cast(_F, numba.njit(cache=True, error_model="numpy")(function))


def jit_inline(function: _F) -> _F:
    """As :func:`jit`, and inlined into its callers by numba itself: the hot helpers of the
    event loop take a dozen arrays each, and a real call would pass every array's descriptor and
    adjust its reference count, which cost more than the work."""
    return cast(_F, numba.njit(cache=True, error_model="numpy", inline="always")(function))


def is_cached() -> bool:
    """Whether numba's cache seems to hold the event loop already (a guess from its index file:
    a run then loads it in well under a second instead of compiling it)."""
    return any(f.name.startswith("loop.run_events-") for f in cache_files(_HERE))
