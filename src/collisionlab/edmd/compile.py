"""How the event-driven kernels are compiled: numba, once per machine (``cache=True``), with the
options every kernel of the package gets (:func:`collisionlab.numba_cache.kernel`, the one place
they are set); the decorators here say which way each function is compiled (inlined, called
without reference counts) and add the loop's own intrinsics.

``error_model="numpy"`` lets a division by zero give inf instead of raising (the predictions
divide by speeds that may be zero, and an infinite time is the right answer: never).
Contractions of ``a * b + c`` into fused multiply-adds stay off, so that results do not depend
on the instruction set of the machine that compiled them.

numba recompiles a cached function when *its own* file changes, not when a function it inlines
from another file does: so the package's cached code is dropped, before anything compiles,
when any of its files, the engine's geometry kernels (the contact law and the time of impact of
two balls, inlined here), the tolerances or the compile's options is newer than it.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar, cast

from ..numba_cache import compiled_once, forget_stale, holds, kernel, use_user_cache

use_user_cache()  # before numba is first imported: its cache goes to the user's cache folder
_HERE = Path(__file__).resolve().parent
#: A file that compiles functions with this file's decorators, and the imports of a file of the
#: package or of an engine's kernel file (numba compiles what it calls, or its constants, into it).
_DECORATED = re.compile(r"^from \.compile import ", re.MULTILINE)
_IMPORTS = re.compile(r"^from \.(\w+) import |^from \.\.engine import (\w+) as ", re.MULTILINE)


def _compiled_files() -> tuple[list[str], list[Path]]:
    """The package's files whose functions numba compiles (those that import this file's
    decorators, and this one: :func:`flag`), and every file their machine code may hold: they,
    the files of the package and the engine's kernel files they import, the tolerances and the
    compile's options (numba_cache.py's :func:`~collisionlab.numba_cache.kernel`). Read from the
    files themselves, so that no list is kept by hand.

    >>> stems, sources = _compiled_files()
    >>> {"compile", "loop", "predict", "spread", "structure"} <= set(stems), "observables" in stems
    (True, False)
    >>> sorted(p.name for p in sources if p.parent.name != "edmd")
    ['contact_law.py', 'geometry_kernels.py', 'numba_cache.py', 'tolerances.py']
    """
    stems = ["compile"] + [p.stem for p in sorted(_HERE.glob("*.py")) if _DECORATED.search(p.read_text("utf-8"))]
    sources = {_HERE.parent / "tolerances.py", _HERE.parent / "numba_cache.py"}
    for stem in stems:
        sources.add(_HERE / f"{stem}.py")
        for own, engine in _IMPORTS.findall((_HERE / f"{stem}.py").read_text("utf-8")):
            sources.add(_HERE / f"{own}.py" if own else _HERE.parent / "engine" / f"{engine}.py")
    return stems, sorted(sources)


forget_stale(_HERE, *_compiled_files())

from llvmlite import ir  # type: ignore[import-untyped]  # noqa: E402
from numba.core import cgutils as _cgutils  # noqa: E402
from numba.core import types  # noqa: E402
from numba.core.extending import intrinsic  # noqa: E402

__all__ = ["borrowed", "flag", "is_cached", "jit", "jit_call", "jit_inline", "prefetch"]


_F = TypeVar("_F", bound=Callable[..., Any])
_A = TypeVar("_A")


def jit(function: _F) -> _F:
    """Compile ``function`` with numba as every kernel of the package is
    (:func:`~collisionlab.numba_cache.kernel`: nopython, cached on disk)."""
    return cast(_F, kernel(function))


def jit_inline(function: _F) -> _F:
    """As :func:`jit`, and inlined into its callers by numba itself: the event loop's steps (a
    collision, a prediction, the calendar's next event) take a dozen arrays each, and a real call
    would pass every array's descriptor and adjust its reference count, which cost more than the
    work. numba types an inlined function again at every call site, so this is kept to the few
    that make the loop; the rest are :func:`jit_call` (bench/LOG.md, "Compiling the event-driven
    kernels", measures the compile's time and memory both ways, and the loop's speed)."""
    return cast(_F, kernel(function, inline=True))


def jit_call(function: _F) -> _F:
    """As :func:`jit`, for a helper that is called, not inlined by numba (LLVM still inlines it
    where it is small), and allocates nothing: compiled without reference counts, so a call
    passes its arrays as they are (none of numba's ``NRT_incref`` / ``NRT_decref``).

    It is compiled for one set of argument types whatever its callers pass
    (:func:`~collisionlab.numba_cache.compiled_once`)."""
    return cast(_F, compiled_once(kernel(function, refcount=False)))


@jit_call
def flag(value: bool) -> bool:
    """``value`` as an ordinary bool, not the constant ``True`` or ``False``: numba types a constant
    argument as itself (``Literal[bool](True)``) and would compile the kernel it is passed to once
    for each constant.

    >>> flag(True)
    True
    """
    return bool(value)


def is_cached() -> bool:
    """Whether numba's cache seems to hold the event loop already (a guess from its index file:
    a run then loads it in well under a second instead of compiling it)."""
    return holds(_HERE, "loop", "run_events")


#: numba's code-generation helpers, untyped.
cgutils: Any = _cgutils


@intrinsic
def _prefetch(typingctx: Any, array: Any, row: Any, column: Any) -> Any:
    """``prefetch(A, i, k)``: ask the processor to bring the cache line holding ``A[i, k]`` (a 2D
    array) into its caches, and go on without waiting (LLVM's ``llvm.prefetch``, a read kept in
    every level). Nothing is read or checked: an index out of range is harmless, and where the
    machine has no prefetch instruction LLVM leaves the call out. The event loop uses it to start
    fetching the rows of the next bodies it will touch while it works on the present ones."""
    if not (isinstance(array, types.Array) and array.ndim == 2):
        return None
    if not (isinstance(row, types.Integer) and isinstance(column, types.Integer)):
        return None

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        array_type = signature.args[0]
        arr = context.make_array(array_type)(context, builder, args[0])
        index = [context.cast(builder, args[1], signature.args[1], types.intp),
                 context.cast(builder, args[2], signature.args[2], types.intp)]  # fmt: skip
        pointer = cgutils.get_item_pointer(context, builder, array_type, arr, index, wraparound=False)
        byte = ir.IntType(8).as_pointer()
        i32 = ir.IntType(32)
        function = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(ir.VoidType(), [byte, i32, i32, i32]), "llvm.prefetch.p0"
        )
        # read (0), keep in every cache level (3), data (1)
        builder.call(function, [builder.bitcast(pointer, byte), i32(0), i32(3), i32(1)])
        return context.get_dummy_value()

    return types.void(array, row, column), codegen


#: ``prefetch(A, i, k)``, callable from compiled code (see ``_prefetch``).
prefetch = cast(Callable[[Any, int, int], None], _prefetch)


@intrinsic
def _borrowed(typingctx: Any, array: Any) -> Any:
    """``borrowed(A)``: the array ``A`` itself (the same data, shape and strides) without its
    reference count: no meminfo, no parent object.

    numba counts the references to every array it holds, and it holds a new one whenever a value
    is bound to a name, also inside a function it inlines (``jit_inline``): the event loop's
    helpers take a dozen arrays each, and the counts it could not prove redundant were hundreds
    of ``NRT_incref`` / ``NRT_decref`` calls in the loop, each an atomic read-modify-write (the
    decrement behind a fence). A profile of a million bodies found 14 % of the time in them, and
    an atomic operation also waits for the loads before it: the cache misses that the loop's
    prefetches had set running side by side. With no meminfo each count is a test of a null
    pointer. Only for arrays the caller keeps alive for the whole call (the arguments of a
    kernel called from Python), and never to be returned or stored."""
    if not isinstance(array, types.Array):
        return None

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        arr = context.make_array(signature.args[0])(context, builder, args[0])
        arr.meminfo = cgutils.get_null_value(arr.meminfo.type)
        arr.parent = cgutils.get_null_value(arr.parent.type)
        return arr._getvalue()

    return array(array), codegen


#: ``borrowed(A)``, callable from compiled code (see ``_borrowed``).
borrowed = cast(Callable[[_A], _A], _borrowed)
