"""Text laid out by compiled code: the JSON lines of a block of collision events
(:meth:`EventBlock.json_chunks <collisionlab.record.EventBlock.json_chunks>`), copied byte by
byte from the text of their numbers (orjson's) and of their names (the json module's) along a
program made from the line's template, with no loop over the events in Python.

:func:`lay_out` is plain Python (and runs as such, slowly, in a test); :func:`compiled` is the
same function compiled by numba on first use and cached on disk, as the engine's kernels are.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .numba_cache import cache_files, use_user_cache

__all__ = ["FLAG", "LITERAL", "NAME_A", "NAME_B", "NUMBER", "STEP", "compiled", "is_cached", "lay_out"]

#: The operations of a program, one row each: ``(operation, argument, flag, pair_only)``.
#: LITERAL writes literal ``argument``; NUMBER the next number of the text (read even when left
#: out); NAME_A and NAME_B the event's names; STEP its step; FLAG literal ``argument`` or, when
#: the event's ``flag`` is set, literal ``argument + 1``. A row with ``pair_only`` set is left
#: out of an event against an obstacle (flag 0).
LITERAL, NUMBER, NAME_A, NAME_B, STEP, FLAG = range(6)


def lay_out(
    numbers: NDArray[np.uint8],
    steps: NDArray[np.int64],
    name_a: NDArray[np.int64],
    name_b: NDArray[np.int64],
    flags: NDArray[np.bool_],
    names: NDArray[np.uint8],
    name_bounds: NDArray[np.int64],
    program: NDArray[np.int64],
    literals: NDArray[np.uint8],
    literal_bounds: NDArray[np.int64],
    out: NDArray[np.uint8],
) -> int:
    """Write each event's text into ``out`` by ``program`` (rows as :data:`LITERAL` and the
    others say); return the number of bytes written.

    ``numbers`` is a JSON array of every event's numbers in the order the program reads them
    (``[1.5,-2.0,...]``: each ends at a comma or at the closing bracket). Event ``e``'s names
    are ``names[name_bounds[i]:name_bounds[i + 1]]`` for ``i = name_a[e]`` and ``name_b[e]``,
    its flags ``flags[e]`` (flag 0: against an obstacle), its step ``steps[e]``. Literal ``k``
    is ``literals[literal_bounds[k]:literal_bounds[k + 1]]``. ``out`` must be large enough.
    """
    written = 0
    read = 1  # after the array's "["
    for e in range(steps.shape[0]):
        obstacle = flags[e, 0]
        for row in range(program.shape[0]):
            operation, argument = program[row, 0], program[row, 1]
            leave_out = program[row, 3] != 0 and obstacle
            if operation == NUMBER:
                end = read
                while numbers[end] != 44 and numbers[end] != 93:  # "," or "]"
                    end += 1
                if not leave_out:
                    for i in range(read, end):
                        out[written] = numbers[i]
                        written += 1
                read = end + 1
                continue
            if leave_out:
                continue
            if operation == STEP:
                value = steps[e]
                if value < 0:
                    out[written] = 45  # "-"
                    written += 1
                    value = -value
                digits, rest = 1, value
                while rest >= 10:
                    rest //= 10
                    digits += 1
                for i in range(digits - 1, -1, -1):
                    out[written + i] = 48 + value % 10  # "0" + the digit
                    value //= 10
                written += digits
                continue
            source = literals
            if operation in (LITERAL, FLAG):
                k = argument + 1 if operation == FLAG and flags[e, program[row, 2]] else argument
                start, stop = literal_bounds[k], literal_bounds[k + 1]
            else:
                source = names
                i = name_a[e] if operation == NAME_A else name_b[e]
                start, stop = name_bounds[i], name_bounds[i + 1]
            for i in range(start, stop):
                out[written] = source[i]
                written += 1
    return written


_compiled: list[Callable[..., int]] = []


def is_cached() -> bool:
    """Whether numba's on-disk cache seems to hold :func:`lay_out` already (a guess from its
    index file, as :func:`collisionlab.engine.compiled.is_cached`): else the first use compiles
    it, for a few seconds, and a program says so."""
    use_user_cache()
    return any(f.name.startswith("text_kernels.lay_out-") for f in cache_files(Path(__file__).parent))


def compiled() -> Callable[..., int]:
    """:func:`lay_out` compiled by numba (on first use; cached on disk, in the user's cache
    folder, as the engine's kernels)."""
    if not _compiled:
        use_user_cache()  # before numba is first imported: it reads NUMBA_CACHE_DIR then
        import numba

        jitted: Any = numba.njit(cache=True)(lay_out)
        _compiled.append(jitted)
    return _compiled[0]
