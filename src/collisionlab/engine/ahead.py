"""The compiled kernels loaded (or compiled, the first time on a machine) ahead of a run, so that
no timed stepping waits for numba: a world's :meth:`~collisionlab.engine.world.World.load_kernels`
and ``collisionlab compile`` call :func:`load_kernels`.

numba compiles a kernel at its first call, for the types of its arguments; a world's kernels take
the same types whatever its size, so a tiny world of the same stepper, stepped twice, loads the
very machine code the real one will run (the test suite's ``conftest.py`` relies on the same;
checked: after it, a gas of 500 spheres, the ``spheres`` demo in exact mode and the ``stack`` demo
with solved contacts each found their kernel among numba's overloads, one, with no cache miss).
"""

from __future__ import annotations

import time
from collections.abc import Callable

from ..errors import InvalidInputError
from ..numba_cache import compiled_notice, compiling_notice
from .world import load_stepper_kernels

__all__ = ["KERNEL_CHOICES", "KERNEL_KINDS", "compiled_choice", "is_cached", "load_kernels"]

#: ``--kernels``: ``auto`` lets the world choose by its expected cost (:data:`~.params.COMPILE_ABOVE`),
#: ``python`` runs the kernels' Python form, ``compiled`` the numba form.
KERNEL_CHOICES: tuple[str, ...] = ("auto", "python", "compiled")

#: The kinds of kernels :func:`load_kernels` loads: one per stepper.
KERNEL_KINDS: tuple[str, ...] = ("euler", "exact", "solve", "event-driven", "particles")

_loaded: set[str] = set()


def compiled_choice(kernels: str) -> bool | None:
    """:attr:`WorldParams.compiled <collisionlab.engine.WorldParams>` for a ``--kernels`` choice.

    >>> compiled_choice("auto"), compiled_choice("python"), compiled_choice("compiled")
    (None, False, True)
    """
    if kernels not in KERNEL_CHOICES:
        raise InvalidInputError("kernels", f"must be one of {', '.join(KERNEL_CHOICES)}", got=kernels)
    return None if kernels == "auto" else kernels == "compiled"


def _event_driven(notify: Callable[[str], None] | None) -> None:
    """The event loop (one kernel for one kind of ball and for mixtures), ``--observe``'s pair
    count and a dense mixture's start, on tiny gases: the arrays the real runs pass them, of the
    same types."""
    import numpy as np

    from ..edmd.compile import is_cached
    from ..edmd.exact_gas import ExactGas, Species
    from ..edmd.structure import pair_histogram

    compiling = notify is not None and not is_cached()
    if notify is not None and compiling:
        notify(compiling_notice("event-driven"))
    started = time.perf_counter()
    world = ExactGas(n=20, dim=2, fraction=0.1, time=0.1, boundary="periodic").world()
    world.run(0.1)
    pos, _ = world.state()
    pair_histogram(pos, np.zeros(len(pos), dtype=np.int64), 1, world.sides, 0.1, np.zeros((1, 4), dtype=np.int64))
    dense_binary = (Species("a", 0.5, 1.0), Species("b", 0.5, 0.5))  # too dense for a lattice: spread apart
    ExactGas(n=20, dim=2, fraction=0.6, time=0.1, boundary="walls", species=dense_binary).world()
    if notify is not None and compiling:  # the wait announced is over
        notify(compiled_notice("event-driven", time.perf_counter() - started))


def _particles() -> None:
    from ..particles import warm_up

    warm_up()


#: The kernel file and entry whose cached code tells whether a stepper's kernels are compiled.
_ENTRIES = {
    "euler": ("step_kernels", "run_steps"),
    "exact": ("exact_kernels", "run_exact_steps"),
    "solve": ("contact_kernels", "run_contact_steps"),
}


def is_cached(kind: str) -> bool:
    """Whether numba's cache seems to hold the kernels of ``kind`` (one of :data:`KERNEL_KINDS`)
    already: loading them then takes well under a second. A guess from the cache's index files
    (``particles`` and the output writers' kernel compile in a second or two: always False)."""
    if kind in _ENTRIES:
        from . import compiled

        return compiled.is_cached(*_ENTRIES[kind])
    if kind == "event-driven":
        from ..edmd import compile as edmd_compile

        return edmd_compile.is_cached()
    return False


def load_kernels(kind: str, notify: Callable[[str], None] | None = None) -> float:
    """Load the compiled kernels of ``kind`` (one of :data:`KERNEL_KINDS`) from numba's cache,
    or compile them (``notify`` is then told so, once, and told again when the compile is done);
    returns the seconds it took, 0.0 when this process has loaded them already."""
    if kind not in KERNEL_KINDS:
        raise InvalidInputError("kind", f"must be one of {', '.join(KERNEL_KINDS)}", got=kind)
    if kind in _loaded:
        return 0.0
    started = time.perf_counter()
    if kind in ("euler", "exact", "solve"):
        load_stepper_kernels(kind, notify)
    elif kind == "event-driven":
        _event_driven(notify)
    else:
        _particles()
    _loaded.add(kind)
    return time.perf_counter() - started
