"""The engine's kernels compiled by numba: the same source files as the Python forms, loaded a
second time under their own module names with every function compiled as every kernel of the
package is (:func:`collisionlab.numba_cache.kernel`, the one set of numba's options). The second
load is how a compiled kernel calls the compiled copies of its helpers while the Python form
keeps calling plain functions; numba's other way, an overload of each Python function
(``register_jitable``), compiled exact mode's kind 2.3 times as long and cached nothing apart
(bench/LOG.md, "one loader without loading a file twice"). Which files a kernel file calls is
read from its own import block, not kept in a list.

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
contains the geometry kernels it calls, and the options (this file, and numba_cache.py's
:func:`~collisionlab.numba_cache.kernel`) change it too: :func:`_forget_stale` drops a kernel
file's cache when the file, a file it calls, or one of those, changed since it was written, so an
edit there can never run stale code (and :func:`is_cached` never finds a kernel numba would
compile again).
"""

from __future__ import annotations

import functools
import importlib.util
import re
import sys
import types
from pathlib import Path
from typing import Any

from ..numba_cache import forget_stale, holds, kernel, use_user_cache

__all__ = ["contact_kernels", "exact_kernels", "is_cached", "kernels"]

_HERE = Path(__file__).resolve().parent
_loaded: dict[str, types.ModuleType] = {}
_started: list[bool] = []  # whether _start has run in this process


def _compile_module(name: str, inject: dict[str, Any]) -> types.ModuleType:
    """Load ``name``.py again as ``collisionlab.engine._compiled_<name>`` and jit its functions.
    The module goes into ``sys.modules`` so that numba's cache can find it again."""
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
            setattr(module, attribute, kernel(value, inline=attribute in inline, refcount=attribute not in no_refcount))
    return module


#: The kernel files a run starts from: each stepper's loop. The rest are found from them.
_ROOTS = ("step_kernels", "exact_kernels", "contact_kernels")
#: A kernel file names the kernel files it calls twice, in the block at its top: the global its
#: compiled copy is handed (``gk: Any = globals()["_GEOMETRY"]``) and the import of its Python
#: form (``from . import geometry_kernels as gk``), paired by the name they bind.
_HANDED = re.compile(r'^    (\w+): Any = globals\(\)\["(_[A-Z_]+)"\]$', re.MULTILINE)
_IMPORTED = re.compile(r"^    from \. import (\w+) as (\w+)$", re.MULTILINE)


@functools.cache
def _imports(stem: str) -> dict[str, str]:
    """The kernel files ``stem``.py calls, each with the global its compiled copy finds it
    under, read from the file itself (so no list of them is kept by hand here).

    >>> _imports("exact_rest")
    {'exact_impulses': '_EXACT_IMPULSES', 'geometry_kernels': '_GEOMETRY', 'pair_separation': '_PAIR_SEPARATION'}
    """
    text = (_HERE / f"{stem}.py").read_text(encoding="utf-8")
    handed = dict(_HANDED.findall(text))
    imported = {alias: module for module, alias in _IMPORTED.findall(text)}
    if set(handed) != set(imported):
        raise RuntimeError(f"{stem}.py: the compiled copy's globals {sorted(handed)} and the imports "
                           f"{sorted(imported)} of its Python form name different kernel files")  # fmt: skip
    return {imported[alias]: handed[alias] for alias in sorted(imported, key=imported.__getitem__)}


@functools.cache
def _kernel_files() -> tuple[str, ...]:
    """Every kernel file: the roots and what they call, directly or through another.

    >>> {"geometry_kernels", "exact_rest", "contact_solver"} <= set(_kernel_files())
    True
    """
    found: list[str] = []
    waiting = list(_ROOTS)
    while waiting:
        stem = waiting.pop()
        if stem not in found:
            found.append(stem)
            waiting.extend(_imports(stem))
    return tuple(sorted(found))


def _calls(stem: str) -> list[str]:
    """The kernel files whose code the machine code of ``stem``'s kernels contains: those it
    imports, and theirs.

    >>> _calls("exact_rest")
    ['contact_law', 'exact_impulses', 'geometry_kernels', 'pair_separation']
    """
    found: set[str] = set()
    for callee in _imports(stem):
        found.update((*_calls(callee), callee))
    return sorted(found)


def _forget_stale() -> None:
    """Remove a kernel file's cached code if the file, a file it calls (directly or through
    another), or this one (the options it is compiled with), is newer than it. (numba would
    compile a changed file's kernels again anyway; removing its files first keeps
    :func:`is_cached` true to what a call will do.)"""
    for stem in _kernel_files():
        sources = [_HERE / f"{name}.py" for name in (stem, *_calls(stem))]
        sources += [_HERE.parent / "tolerances.py", _HERE.parent / "numba_cache.py", Path(__file__)]
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
        inject = {name: _module(callee) for callee, name in _imports(stem).items()}
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
    return holds(_HERE, stem, entry)
