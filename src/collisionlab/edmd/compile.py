"""How the event-driven kernels are compiled: numba, once per machine (``cache=True``).

``error_model="numpy"`` lets a division by zero give inf instead of raising (the predictions
divide by speeds that may be zero, and an infinite time is the right answer: never).
Contractions of ``a * b + c`` into fused multiply-adds stay off, so that results do not depend
on the instruction set of the machine that compiled them.

A caveat of numba's cache: a cached function is recompiled when *its own* file changes, not when
a function it inlines from another file does. After editing ``predict.py``, ``calendar.py`` or
``cells.py``, delete the ``__pycache__/*.nb*`` files of this package (a fresh install has none).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar, cast

from ..numba_cache import use_user_cache

use_user_cache()  # before numba is first imported: its cache goes to the user's cache folder

import numba  # noqa: E402  (after the cache folder is set)

__all__ = ["jit", "jit_inline"]

_F = TypeVar("_F", bound=Callable[..., Any])


def jit(function: _F) -> _F:
    """Compile ``function`` with numba (nopython, cached on disk)."""
    return cast(_F, numba.njit(cache=True, error_model="numpy")(function))


def jit_inline(function: _F) -> _F:
    """As :func:`jit`, and inlined into its callers by numba itself: the hot helpers of the
    event loop take a dozen arrays each, and a real call would pass every array's descriptor and
    adjust its reference count, which cost more than the work."""
    return cast(_F, numba.njit(cache=True, error_model="numpy", inline="always")(function))
