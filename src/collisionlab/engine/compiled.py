"""The engine's kernels compiled by numba: the same source files as the Python forms, loaded a
second time under their own module names with every function put through ``numba.njit``.

Nothing is compiled until :func:`kernels` is first called; numba caches the machine code on disk
(``cache=True``), so the compile happens once per machine and later loads take well under a
second. :func:`is_cached` tells whether a run will find the cache (a world then says on stderr
that it compiles).

A kernel file may name helpers to inline into their callers (``INLINE``) and functions to
compile without numba's reference counts (``NO_REFCOUNT``: they allocate nothing). numba takes and
gives back a count on every array an inlined helper is passed, atomically, and its pruning leaves
them in loops; the exact stepper's phases run as such functions (bench/README.md measures it).
Every kernel releases the GIL while it runs (``nogil``): the output writers then format what the
last chunk of steps produced, in a thread of their own, while the next chunk runs.

numba keys each cached function on its own source file only, but the stepper's machine code
contains the geometry kernels it calls, and the options above (this file) change it too:
:func:`_forget_stale` drops a kernel file's cache when the file, a file it calls, or this one,
changed since it was written, so an edit there can never run stale code (and :func:`is_cached`
never finds a kernel numba would compile again).
"""

from __future__ import annotations

import importlib.util
import sys
import types
from pathlib import Path
from typing import Any

from ..numba_cache import cache_files, forget_stale, use_user_cache

__all__ = ["contact_kernels", "exact_kernels", "is_cached", "kernels"]

_HERE = Path(__file__).resolve().parent
_loaded: dict[str, types.ModuleType] = {}
_started: list[bool] = []  # whether _start has run in this process


def _compile_module(name: str, inject: dict[str, Any]) -> types.ModuleType:
    """Load ``name``.py again as ``collisionlab.engine._compiled_<name>`` and jit its functions.
    The module goes into ``sys.modules`` so that numba's cache can find it again."""
    use_user_cache()  # before numba is first imported: it reads NUMBA_CACHE_DIR then
    import numba

    qualified = f"{__package__}._compiled_{name}"
    spec = importlib.util.spec_from_file_location(qualified, _HERE / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    module.__dict__.update(inject)
    sys.modules[qualified] = module
    spec.loader.exec_module(module)
    inline = set(getattr(module, "INLINE", ()))
    no_refcount = set(getattr(module, "NO_REFCOUNT", ()))
    for attribute, value in list(vars(module).items()):
        if isinstance(value, types.FunctionType) and value.__module__ == qualified:
            # error_model="numpy": no Python exception check in every division (none can raise).
            options: dict[str, Any] = {"cache": True, "error_model": "numpy", "nogil": True}
            if attribute in inline:
                options["inline"] = "always"
            if attribute in no_refcount:
                options["_nrt"] = False  # allocates nothing: no reference counts either
            setattr(module, attribute, numba.njit(**options)(value))
    return module


#: Each kernel file and the kernel files it imports: its compiled copy is handed theirs as the
#: globals of :data:`_GLOBAL_NAMES` (the block at the top of each file that reads them).
_IMPORTS: dict[str, tuple[str, ...]] = {
    "geometry_kernels": (),
    "event_heap": (),
    # The Forward Euler stepper, one concept per file (step_kernels.py, the loop, lists them); the
    # other steppers call its lower files too.
    "non_literal": (),
    "pair_separation": ("geometry_kernels",),
    "broad_phase_grid": (),
    "broad_phase_pairs": ("pair_separation", "broad_phase_grid"),
    "contact_order": ("non_literal",),
    "touching_memory": (),
    "event_rows": ("non_literal",),
    "euler_impulses": ("geometry_kernels", "non_literal", "pair_separation", "event_rows"),
    "euler_push_apart": ("pair_separation",),
    "euler_clamps": ("pair_separation", "broad_phase_pairs"),
    "step_kernels": (
        "non_literal",
        "broad_phase_grid",
        "broad_phase_pairs",
        "contact_order",
        "touching_memory",
        "euler_impulses",
        "euler_push_apart",
        "euler_clamps",
    ),
    # The exact stepper, one concept per file (exact_kernels.py, the loop, lists them).
    "exact_flight": (),
    "exact_sweeps": (),
    "exact_impulses": ("geometry_kernels",),
    "exact_time_of_impact": ("geometry_kernels", "pair_separation", "exact_flight"),
    "exact_rest": ("geometry_kernels", "pair_separation", "exact_impulses"),
    "exact_settle": (
        "geometry_kernels",
        "pair_separation",
        "event_rows",
        "event_heap",
        "exact_flight",
        "exact_time_of_impact",
        "exact_impulses",
        "exact_rest",
    ),
    "exact_impacts": (
        "geometry_kernels",
        "pair_separation",
        "event_rows",
        "event_heap",
        "exact_flight",
        "exact_time_of_impact",
        "exact_impulses",
        "exact_rest",
        "exact_sweeps",
        "exact_settle",
    ),
    "exact_step_end": ("pair_separation", "touching_memory", "exact_sweeps"),
    "exact_kernels": (
        "non_literal",
        "pair_separation",
        "broad_phase_grid",
        "broad_phase_pairs",
        "contact_order",
        "touching_memory",
        "event_rows",
        "euler_push_apart",
        "euler_clamps",
        "exact_flight",
        "exact_rest",
        "exact_sweeps",
        "exact_settle",
        "exact_impacts",
        "exact_step_end",
    ),
    # The contact stepper, one concept per file (contact_kernels.py, the loop, lists them).
    "contact_flight": (),
    "contact_memory": ("non_literal",),
    "contact_qp": (),
    "contact_time_of_impact": ("geometry_kernels", "pair_separation", "contact_flight"),
    "contact_candidates": ("non_literal", "contact_time_of_impact"),
    "contact_islands": ("non_literal", "contact_time_of_impact", "contact_candidates"),
    "contact_impacts": (
        "geometry_kernels",
        "non_literal",
        "pair_separation",
        "event_rows",
        "event_heap",
        "contact_flight",
        "contact_time_of_impact",
        "contact_islands",
    ),
    "contact_solver": ("non_literal", "contact_time_of_impact", "contact_memory", "contact_qp"),
    "contact_push_apart": ("non_literal", "contact_time_of_impact", "contact_qp"),
    "contact_kernels": (
        "non_literal",
        "contact_candidates",
        "contact_impacts",
        "contact_islands",
        "contact_push_apart",
        "contact_qp",
        "contact_solver",
    ),
}

#: The global a compiled copy finds an imported kernel file's compiled copy under.
_GLOBAL_NAMES = {
    "geometry_kernels": "_GEOMETRY",
    "step_kernels": "_STEP",
    "non_literal": "_NON_LITERAL",
    "pair_separation": "_PAIR_SEPARATION",
    "broad_phase_grid": "_BROAD_PHASE_GRID",
    "broad_phase_pairs": "_BROAD_PHASE_PAIRS",
    "contact_order": "_CONTACT_ORDER",
    "touching_memory": "_TOUCHING_MEMORY",
    "event_rows": "_EVENT_ROWS",
    "euler_impulses": "_EULER_IMPULSES",
    "euler_push_apart": "_EULER_PUSH_APART",
    "euler_clamps": "_EULER_CLAMPS",
    "event_heap": "_HEAP",
    "exact_flight": "_EXACT_FLIGHT",
    "exact_sweeps": "_EXACT_SWEEPS",
    "exact_impulses": "_EXACT_IMPULSES",
    "exact_time_of_impact": "_EXACT_TIME_OF_IMPACT",
    "exact_rest": "_EXACT_REST",
    "exact_settle": "_EXACT_SETTLE",
    "exact_step_end": "_EXACT_STEP_END",
    "exact_impacts": "_EXACT_IMPACTS",
    "contact_flight": "_CONTACT_FLIGHT",
    "contact_memory": "_CONTACT_MEMORY",
    "contact_qp": "_CONTACT_QP",
    "contact_time_of_impact": "_CONTACT_TIME_OF_IMPACT",
    "contact_candidates": "_CONTACT_CANDIDATES",
    "contact_islands": "_CONTACT_ISLANDS",
    "contact_impacts": "_CONTACT_IMPACTS",
    "contact_solver": "_CONTACT_SOLVER",
    "contact_push_apart": "_CONTACT_PUSH_APART",
}


def _calls(stem: str) -> list[str]:
    """The kernel files whose code the machine code of ``stem``'s kernels contains: those it
    imports, and theirs, in the order first met.

    >>> _calls("exact_rest")
    ['geometry_kernels', 'pair_separation', 'exact_impulses']
    """
    found: list[str] = []
    for callee in _IMPORTS[stem]:
        for name in (*_calls(callee), callee):
            if name not in found:
                found.append(name)
    return found


def _forget_stale() -> None:
    """Remove a kernel file's cached code if the file, a file it calls (directly or through
    another), or this one (the options it is compiled with), is newer than it. (numba would
    compile a changed file's kernels again anyway; removing its files first keeps
    :func:`is_cached` true to what a call will do.)"""
    for stem in _IMPORTS:
        sources = [_HERE / f"{name}.py" for name in (stem, *_calls(stem))]
        sources += [_HERE.parent / "tolerances.py", Path(__file__)]
        forget_stale(_HERE, [stem], sources)


def _start() -> None:
    """Once per process, before any kernel file is loaded: numba's cache folder, and the stale
    cached code dropped."""
    if not _started:
        use_user_cache()
        _forget_stale()
        _started.append(True)


def _module(stem: str) -> types.ModuleType:
    """The compiled copy of the kernel file ``stem``, loaded with the compiled copies of the
    files it imports at its first call (loading compiles nothing: numba compiles a kernel, or
    loads it from its cache, at the kernel's first call)."""
    _start()
    if stem not in _loaded:
        inject = {_GLOBAL_NAMES[callee]: _module(callee) for callee in _IMPORTS[stem]}
        _loaded[stem] = _compile_module(stem, inject)
    return _loaded[stem]


def kernels() -> types.ModuleType:
    """The compiled :mod:`~collisionlab.engine.step_kernels` (and, inside it, geometry kernels)."""
    return _module("step_kernels")


def exact_kernels() -> types.ModuleType:
    """The compiled :mod:`~collisionlab.engine.exact_kernels` (calling the compiled step kernels
    and the compiled files of its phases)."""
    return _module("exact_kernels")


def contact_kernels() -> types.ModuleType:
    """The compiled :mod:`~collisionlab.engine.contact_kernels` (calling the compiled step kernels
    and the compiled files of its phases)."""
    return _module("contact_kernels")


def is_cached(stem: str, entry: str) -> bool:
    """Whether numba's on-disk cache seems to hold the kernel ``entry`` of the file ``stem``
    (``"step_kernels"``, ``"run_steps"``) already: its first call then loads it in well under a
    second instead of compiling it. A guess from the cache's index file of that function itself
    (the kernels it calls are compiled into its machine code), once stale cached code is dropped
    (:func:`_start`): a kernel file changed since is not cached, whatever its old files say."""
    _start()
    return any(f.name.startswith(f"{stem}.{entry}-") for f in cache_files(_HERE))
