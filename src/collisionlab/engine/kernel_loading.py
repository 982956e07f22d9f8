"""How a world reaches its compiled kernels: which compiled module each stepper calls, and what
surrounds a kernel's first call in a process (numba loads it from its cache, or compiles it:
announced once, under a lock). :func:`~collisionlab.engine.world.load_stepper_kernels` loads
one stepper's kernels ahead of a run by stepping a world.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any

from ..numba_cache import compile_lock, compiling_notice, gc_paused

__all__ = ["KernelCalls"]


class KernelCalls:
    """One world's compiled kernel modules and first calls. ``kind`` is the stepper's
    (``"euler"``, ``"exact"``, ``"solve"``, or ``"event-driven"``, whose loop is not here: it
    calls the step kernels only to find bodies near each other); ``notify`` hears that a
    compile starts, once."""

    def __init__(self, kind: str, notify: Callable[[str], None] | None) -> None:
        self.kind = kind
        self._notify = notify
        self._modules: dict[bool, ModuleType] = {}
        self._called: set[str] = set()  # compiled kernels called once already (numba has loaded them)
        #: Whether the compile notice was given (once per world).
        self.said_compiling = False

    def module(self, stepper: bool = True) -> ModuleType:
        """The compiled step kernels, or (``stepper``, in exact mode) the compiled exact or
        contact kernels."""
        from . import compiled

        stepper = stepper and self.kind in ("exact", "solve")
        if stepper not in self._modules:
            with gc_paused():  # numba's import, its registries
                if not stepper:
                    self._modules[stepper] = compiled.kernels()
                else:
                    solving = self.kind == "solve"
                    self._modules[stepper] = compiled.contact_kernels() if solving else compiled.exact_kernels()
        return self._modules[stepper]

    def first_call(self, kernels: ModuleType, entry: str) -> contextlib.AbstractContextManager[Any]:
        """What surrounds the first call of a compiled kernel module's ``entry``, when numba
        loads its code from the cache, or compiles it. A load runs with Python's collector
        paused (numba makes objects that live until exit: :func:`~collisionlab.numba_cache.gc_paused`).
        A compile is announced (once per world), and runs with the collector on (it makes garbage
        for minutes) and under a lock that makes another process wanting the same kernels wait
        and then load them rather than compile them too
        (:func:`~collisionlab.numba_cache.compile_lock`). Nothing for a Python form."""
        from . import compiled

        key = f"{kernels.__name__}.{entry}"
        if "._compiled_" not in key or key in self._called:
            return contextlib.nullcontext()
        self._called.add(key)
        stem = kernels.__name__.rpartition("._compiled_")[2]
        if compiled.is_cached(stem, entry):
            return gc_paused()
        if self._notify is not None and not self.said_compiling:
            self.said_compiling = True
            # The exact stepper's kernel takes longest to compile: the notice says what the run
            # will wait (on 2 cores, bench/README.md).
            exact = self.kind == "exact" and not compiled.is_cached("exact_kernels", "run_exact_steps")
            self._notify(compiling_notice("exact" if exact else "solve" if self.kind == "solve" else "euler"))
        return compile_lock(Path(kernels.__file__ or ".").parent, stem)
