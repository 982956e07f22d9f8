"""Text laid out by compiled code: the JSON lines of a block of collision events
(:meth:`EventBlock.json_chunks <collisionlab.record.EventBlock.json_chunks>`), copied byte by
byte from the text of their numbers (orjson's) and of their names (the json module's) along a
program made from the line's template, with no loop over the events in Python; and the table's
collision lines, whose numbers it writes itself as ``"%.3f" % x`` would (:data:`FIXED3`).

:func:`lay_out` is plain Python (and runs as such, slowly, in a test); :func:`compiled` is the
same function compiled by numba on first use and cached on disk, as the engine's kernels are.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .numba_cache import forget_stale, holds, kernel, use_user_cache

__all__ = [
    "FIXED3",
    "FIXED3_LIMIT",
    "FLAG",
    "LITERAL",
    "NAME_A",
    "NAME_B",
    "NUMBER",
    "OBSTACLES_ONLY",
    "PAIRS_ONLY",
    "STEP",
    "compiled",
    "is_cached",
    "lay_out",
]

#: The operations of a program, one row each: ``(operation, argument, flag, only)``.
#: LITERAL writes literal ``argument``; NUMBER the next number of the text (read even when left
#: out); NAME_A and NAME_B the event's names; STEP its step; FLAG literal ``argument`` or, when
#: the event's ``flag`` is set, literal ``argument + 1``; FIXED3 the event's value in column
#: ``argument`` as ``"%.3f"`` writes it. ``only`` is 0 (every event), :data:`PAIRS_ONLY` (left
#: out of an event against an obstacle: flag 0) or :data:`OBSTACLES_ONLY`.
LITERAL, NUMBER, NAME_A, NAME_B, STEP, FLAG, FIXED3 = range(7)
PAIRS_ONLY, OBSTACLES_ONLY = 1, 2

#: FIXED3 writes values below this in magnitude (2**53: 1000 times the value's 53-bit
#: significand is then an exact int64); the caller formats larger ones another way.
FIXED3_LIMIT = 9007199254740992.0
_TWO_53 = 9007199254740992.0


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
    values: NDArray[np.float64],
    starts: NDArray[np.int64],
) -> int:
    """Write each event's text into ``out`` by ``program`` (rows as :data:`LITERAL` and the
    others say); return the number of bytes written, and the offset in ``out`` where event
    ``e``'s text starts in ``starts[e]`` (``starts[n]``: the end).

    ``numbers`` is a JSON array of every event's numbers in the order the program reads them
    (``[1.5,-2.0,...]``: each ends at a comma or at the closing bracket). Event ``e``'s names
    are ``names[name_bounds[i]:name_bounds[i + 1]]`` for ``i = name_a[e]`` and ``name_b[e]``,
    its flags ``flags[e]`` (flag 0: against an obstacle), its step ``steps[e]``. Literal ``k``
    is ``literals[literal_bounds[k]:literal_bounds[k + 1]]``. ``values[e, k]`` are event ``e``'s
    values for FIXED3, each finite one below :data:`FIXED3_LIMIT` in magnitude. ``out`` must be
    large enough. ``numbers``, ``names`` and ``literals`` are read-only arrays (``np.frombuffer``
    of bytes) in every caller: numba compiles a function once per type of its arguments, and a
    writable array is another type.

    FIXED3 rounds the value's exact binary fraction to three decimals, half to even, as Python's
    ``%`` does: with ``|x| = m 2**e`` (``m`` its 53-bit significand, ``e <= 0`` below the limit),
    ``1000 |x| = 1000 m / 2**-e`` exactly, an integer division with its remainder.

    >>> import numpy as np
    >>> def run(*xs):
    ...     program = np.array([[FIXED3, k, 0, 0] for k in range(len(xs))], np.int64)
    ...     out, starts, empty = np.zeros(200, np.uint8), np.zeros(2, np.int64), np.zeros(1, np.int64)
    ...     n = lay_out(np.zeros(1, np.uint8), empty, empty, empty, np.zeros((1, 1), bool), out[:0],
    ...                 empty, program, out[:0], empty, out, np.array([xs]), starts)
    ...     return out[:n].tobytes().decode()
    >>> run(0.0625, 0.0005, -0.0004, 2.5e-4, 1e15, float("-inf"), float("nan"))
    '0.0620.001-0.0000.0001000000000000000.000-infnan'
    >>> "".join("%.3f" % x for x in (0.0625, 0.0005, -0.0004, 2.5e-4, 1e15, float("-inf"), float("nan")))
    '0.0620.001-0.0000.0001000000000000000.000-infnan'
    """
    written = 0
    read = 1  # after the array's "["
    for e in range(steps.shape[0]):
        starts[e] = written
        obstacle = flags[e, 0]
        for row in range(program.shape[0]):
            operation, argument = program[row, 0], program[row, 1]
            only = program[row, 3]
            leave_out = (only == PAIRS_ONLY and obstacle) or (only == OBSTACLES_ONLY and not obstacle)
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
            if operation in (STEP, FIXED3):
                fraction = -1  # thousandths to write after the point; none for a step
                if operation == STEP:
                    value = steps[e]
                    if value < 0:
                        out[written] = 45  # "-"
                        written += 1
                        value = -value
                else:
                    x = values[e, argument]
                    if x != x:
                        out[written], out[written + 1], out[written + 2] = 110, 97, 110  # "nan"
                        written += 3
                        continue
                    if math.copysign(1.0, x) < 0.0:  # -0.0 too, as "%.3f" writes it
                        out[written] = 45
                        written += 1
                        x = -x
                    if x == math.inf:
                        out[written], out[written + 1], out[written + 2] = 105, 110, 102  # "inf"
                        written += 3
                        continue
                    significand, exponent = math.frexp(x)  # x = significand 2**exponent, 1/2 <= it < 1
                    scaled = np.int64(significand * _TWO_53) * 1000  # < 2**63
                    shift = 53 - exponent  # 1000 x = scaled / 2**shift; shift >= 0 below the limit
                    if shift == 0:
                        thousandths = scaled
                    elif shift >= 64:
                        thousandths = np.int64(0)  # below one half
                    elif shift == 63:
                        thousandths = np.int64(1) if scaled > np.int64(1) << 62 else np.int64(0)
                    else:
                        thousandths = scaled >> shift
                        remainder = scaled & ((np.int64(1) << shift) - 1)
                        half = np.int64(1) << (shift - 1)
                        if remainder > half or (remainder == half and thousandths & 1):
                            thousandths += 1  # half to even
                    value, fraction = int(thousandths // 1000), int(thousandths % 1000)
                digits, rest = 1, value
                while rest >= 10:
                    rest //= 10
                    digits += 1
                for i in range(digits - 1, -1, -1):
                    out[written + i] = 48 + value % 10  # "0" + the digit
                    value //= 10
                written += digits
                if fraction >= 0:
                    out[written] = 46  # "."
                    for i in range(3, 0, -1):
                        out[written + i] = 48 + fraction % 10
                        fraction //= 10
                    written += 4
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
    starts[steps.shape[0]] = written
    return written


_compiled: list[Callable[..., int]] = []
_started: list[bool] = []  # whether _start has run in this process


def _start() -> None:
    """Once per process, before the cache is first asked: numba's cache folder, and this file's
    cached code dropped when it, or the compile's options
    (:func:`~collisionlab.numba_cache.kernel`), changed since it was written."""
    if not _started:
        use_user_cache()
        here = Path(__file__)
        forget_stale(here.parent, ["text_kernels"], [here, here.parent / "numba_cache.py"])
        _started.append(True)


def is_cached() -> bool:
    """Whether numba's on-disk cache seems to hold :func:`lay_out` already (a guess from its
    index file, as :func:`collisionlab.engine.compiled.is_cached`): else the first use compiles
    it, for a few seconds, and a program says so."""
    _start()
    return holds(Path(__file__).parent, "text_kernels", "lay_out")


def compiled() -> Callable[..., int]:
    """:func:`lay_out` compiled by numba as every kernel of the package is (on first use; cached
    on disk, in the user's cache folder; the GIL released: the writers' thread, see
    cli.background)."""
    if not _compiled:
        _start()
        jitted: Any = kernel(lay_out)
        _compiled.append(jitted)
    return _compiled[0]
