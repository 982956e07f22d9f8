"""The collision lines of the lab's table: one event's lines (with ``--explain``'s working), and
the lines of a whole block of events at once, written from the block's columns by compiled code
(:mod:`collisionlab.text_kernels`) or with one ``%`` a step, the same text either way. Text only:
no physics; the writers (:mod:`.render`) put these lines between the rows of positions."""

from __future__ import annotations

import functools
import math
import sys
import time
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from .. import text_kernels
from ..collision_events import EventBlock
from ..numba_cache import compiled_notice, compiling_notice
from ..record import CollisionEvent
from ..textformat import format_float as _f
from ..vector import Vector3D

__all__ = ["COMPILE_NOTICE", "TextCompile", "block_texts", "event_lines", "vector_text"]


def vector_text(v: Vector3D, dims: int = 3, digits: int = 3) -> str:
    return "(" + ", ".join(_f(c, f".{digits}f") for c in v.as_tuple()[:dims]) + ")"


def _number(x: float) -> str:
    return "inf" if math.isinf(x) else _f(x, ".4g")


def event_lines(event: CollisionEvent, dims: int, explain: bool) -> list[str]:
    a, b = event.bodies
    verb = f"{b} hits {a}" if event.static else f"{a} and {b} collide"
    lines = [f"collision at step {event.step} (t = {event.time:.3f} s): {verb}"]
    after = ", ".join(f"{name} = {vector_text(v, dims)}" for name, v in event.velocities_after.items())
    label = "velocity after" if len(event.velocities_after) == 1 else "velocities after"
    if explain:
        m_a, m_b = event.masses
        inv_a = "0" if math.isinf(m_a) else f"1/{_number(m_a)}"
        v_n = _f(event.approach_speed, ".4f")
        lines += [
            f"    normal n = {vector_text(event.normal, dims)} (from {a} to {b}), "
            f"contact point {vector_text(event.point, dims)}",
            f"    v_n = (v_{b} - v_{a}) . n = {v_n} m/s (negative: approaching)",
            (
                f"    e = {event.restitution:g}"
                + (" (approach slower than the rest threshold: no bounce)" if event.below_rest_threshold else "")
            ),
            (
                f"    j = -(1 + e) v_n / (1/m_{a} + 1/m_{b}) = -(1 + {event.restitution:g})({v_n})"
                f" / ({inv_a} + 1/{_number(m_b)}) = {_f(event.impulse, '.4f')} N s"
            ),
        ]
        for name, before in event.velocities_before.items():
            sign = "-" if name == a else "+"
            mass = m_a if name == a else m_b
            lines.append(
                f"    v_{name} {sign}= (j / {_number(mass)}) n: {vector_text(before, dims)} -> "
                f"{vector_text(event.velocities_after[name], dims)}"
            )
        lines.append(f"    kinetic energy {event.kinetic_energy_before:.4f} J -> {event.kinetic_energy_after:.4f} J")
    lines.append(f"  {label}: {after} m/s")
    return lines


def _block_templates(dims: int) -> tuple[str, str]:
    """The ``%`` templates of :func:`event_lines`'s text (without ``--explain``) of an event
    between two bodies and of a body against an obstacle, for :func:`block_texts`'s arguments:
    step, time, the two names as the first line gives them, then A's name and velocity (empty
    against an obstacle) and B's."""
    vector = "(" + ", ".join(["%.3f"] * dims) + ")"
    head = "collision at step %d (t = %.3f s): "
    return (
        head + f"%s and %s collide\n  velocities after: %s = {vector}, %s = {vector} m/s\n",
        head + f"%s hits %s\n  velocity after: {'%s' * (1 + dims)}%s = {vector} m/s\n",
    )


@functools.cache
def _table_program(dims: int) -> tuple[NDArray[np.int64], NDArray[np.uint8], NDArray[np.int64]]:
    """:func:`_block_templates`'s two texts as one program of :func:`text_kernels.lay_out
    <collisionlab.text_kernels.lay_out>` (its rows, literals and their bounds), reading the
    values time, A's velocity after, B's velocity after."""
    rows: list[tuple[int, int, int, int]] = []
    literals: list[bytes] = []
    only = 0

    def put(*items: str | tuple[int, int]) -> None:
        for item in items:
            if isinstance(item, str):
                literals.append(item.encode())
                rows.append((text_kernels.LITERAL, len(literals) - 1, 0, only))
            else:
                rows.append((item[0], item[1], 0, only))

    def vector(first: int) -> list[str | tuple[int, int]]:
        items: list[str | tuple[int, int]] = [" = ("]
        for k in range(dims):
            items += [", "] if k else []
            items.append((text_kernels.FIXED3, first + k))
        return items

    a, b = (text_kernels.NAME_A, 0), (text_kernels.NAME_B, 0)
    put("collision at step ", (text_kernels.STEP, 0), " (t = ", (text_kernels.FIXED3, 0), " s): ")
    only = text_kernels.PAIRS_ONLY
    put(a, " and ", b, " collide\n  velocities after: ", a, *vector(1), "), ", b, *vector(1 + dims), ") m/s\n")
    only = text_kernels.OBSTACLES_ONLY
    put(b, " hits ", a, "\n  velocity after: ", b, *vector(1 + dims), ") m/s\n")
    bounds = np.cumsum([0, *map(len, literals)], dtype=np.int64)
    return np.array(rows, dtype=np.int64), np.frombuffer(b"".join(literals), np.uint8), bounds


#: Blocks of at least this many events are laid out by compiled code when numba is loaded
#: already (by the engine's compiled kernels); smaller ones, and every block of a run that never
#: loads numba (the lab's cases), by ``%``, which costs no compiler start-up (~0.7 s).
_COMPILED_EVENTS = 512


#: What a writer says (through its ``notify``) before the text kernel compiles.
COMPILE_NOTICE = compiling_notice("text")


def block_texts(block: EventBlock, dims: int, compiling: Callable[[], None] | None = None) -> list[tuple[int, str]]:
    """The text of :func:`event_lines` (without ``--explain``) of every event of ``block``, one
    text (its lines, each ending in a newline) per step, the steps in order and each step's
    events in the block's order, written from the block's columns with no loop over the events
    in Python (a heap of balls makes millions): by compiled code (:func:`_laid_out_texts`) or
    with one ``%`` a step (:func:`_formatted_texts`), the same text either way. ``compiling`` is
    called before the compiled code is used."""
    n = len(block)
    if not n:
        return []
    steps = block.step
    order = np.argsort(steps, kind="stable") if np.any(np.diff(steps) < 0) else np.arange(n)
    steps = steps[order]
    ids, index = np.unique(np.concatenate((block.a[order], block.b[order])), return_inverse=True)
    names = [block.static_names[-1 - i] if i < 0 else block.names[i] for i in ids.tolist()]
    # No signed zero: a velocity that .3f would write -0.000 (below half a thousandth, as a
    # double: 0.0005 is a little more than 5e-4) is written 0.000.
    after = np.column_stack((block.after_a[order, :dims], block.after_b[order, :dims]))
    after = np.where(np.abs(after) < 0.0005, 0.0, after)
    values = np.column_stack((block.time[order], after))
    static = block.a[order] < 0
    finite = values[np.isfinite(values)]
    if n >= _COMPILED_EVENTS and "numba" in sys.modules and not np.any(np.abs(finite) >= text_kernels.FIXED3_LIMIT):
        if compiling is not None:
            compiling()
        texts, starts = _laid_out_texts(steps, index, names, static, values, dims)
    else:
        texts, starts = _formatted_texts(steps, index, names, static, values, dims)
    return [(int(steps[start]), text) for start, text in zip(starts, texts, strict=True)]


def _step_starts(steps: NDArray[np.int64]) -> list[int]:
    """Where each step's events begin in the sorted ``steps``."""
    return [0, *(np.flatnonzero(np.diff(steps)) + 1).tolist()]


def _laid_out_texts(
    steps: NDArray[np.int64], index: NDArray[np.int64], names: list[str], static: NDArray[np.bool_],
    values: NDArray[np.float64], dims: int, size: int = 16384,
) -> tuple[list[str], list[int]]:  # fmt: skip
    """:func:`block_texts` by :func:`text_kernels.lay_out <collisionlab.text_kernels.lay_out>`,
    ``size`` events at a time: each step's text and its first event."""
    n = len(steps)
    program, literals, literal_bounds = _table_program(dims)
    encoded = [name.encode() for name in names]
    name_bytes = np.frombuffer(b"".join(encoded), np.uint8)
    name_bounds = np.cumsum([0, *map(len, encoded)], dtype=np.int64)
    name_a, name_b = index[:n].astype(np.int64), index[n:].astype(np.int64)
    flags = static[:, None]
    steps = np.ascontiguousarray(steps, dtype=np.int64)
    values = np.ascontiguousarray(values)
    longest = int(np.diff(name_bounds).max())
    # Bytes an event writes at most: every literal, four names, a step, and each value as
    # "-" + 16 digits + "." + 3 digits (below FIXED3_LIMIT) or "-inf".
    bound = int(literal_bounds[-1]) + 4 * longest + 21 + 21 * values.shape[1]
    lay_out = text_kernels.compiled()
    no_numbers = np.frombuffer(b"", np.uint8)  # read-only, as every caller's (text_kernels.lay_out)
    pieces = []
    offsets = np.empty(n + 1, np.int64)  # where each event's text starts in the whole text
    done = 0
    for start in range(0, n, size):
        rows = slice(start, start + size)
        count = len(steps[rows])
        out = np.empty(count * bound, np.uint8)
        written = lay_out(
            no_numbers, steps[rows], name_a[rows], name_b[rows], flags[rows], name_bytes, name_bounds,
            program, literals, literal_bounds, out, values[rows], offsets[start : start + count + 1],
        )  # fmt: skip
        offsets[start : start + count + 1] += done
        pieces.append(out[:written].tobytes())
        done += written
    whole = b"".join(pieces)
    firsts = _step_starts(steps)
    texts = [
        whole[offsets[first] : offsets[stop]].decode() for first, stop in zip(firsts, [*firsts[1:], n], strict=True)
    ]
    return texts, firsts


def _formatted_texts(
    steps: NDArray[np.int64], index: NDArray[np.int64], names: list[str], static: NDArray[np.bool_],
    values: NDArray[np.float64], dims: int,
) -> tuple[list[str], list[int]]:  # fmt: skip
    """:func:`block_texts` with one ``%`` a step: each step's text and its first event."""
    n = len(steps)
    name_array = np.array(names, dtype=object)
    name_a, name_b = name_array[index[:n]], name_array[index[n:]]
    after = values[:, 1:].astype(object)
    after[static, :dims] = ""
    arguments = np.empty((n, 6 + 2 * dims), dtype=object)
    arguments[:, 0] = steps.astype(object)
    arguments[:, 1] = values[:, 0].astype(object)
    arguments[:, 2] = np.where(static, name_b, name_a)  # "A and B collide", "B hits A"
    arguments[:, 3] = np.where(static, name_a, name_b)
    arguments[:, 4] = np.where(static, "", name_a)
    arguments[:, 5 : 5 + dims] = after[:, :dims]
    arguments[:, 5 + dims] = name_b
    arguments[:, 6 + dims :] = after[:, dims:]
    pair, obstacle = _block_templates(dims)
    templates = np.where(static, obstacle, pair).astype(object).tolist()
    values_list = arguments.ravel().tolist()
    width = arguments.shape[1]
    firsts = _step_starts(steps)
    texts = [
        "".join(templates[start:stop]) % tuple(values_list[start * width : stop * width])
        for start, stop in zip(firsts, [*firsts[1:], n], strict=True)
    ]
    return texts, firsts


class TextCompile:
    """What a writer says of the text kernel's compile (through ``notify``): that it compiles,
    once, before its first use when numba's cache does not hold it (:meth:`say`), and that it
    is done, with the seconds it took, once the cache holds it (:meth:`done`, called after each
    use: a block too small for the compiled kernel leaves it uncompiled, and nothing is said)."""

    def __init__(self, notify: Callable[[str], None] | None) -> None:
        self._notify = notify
        self._began: float | None = None

    def say(self) -> None:
        if self._notify is not None and self._began is None and not text_kernels.is_cached():
            self._notify(COMPILE_NOTICE)
            self._began = time.perf_counter()
        elif self._began is None:
            self._notify = None  # loaded from the cache (or nobody listens): nothing to say, ever

    def done(self) -> None:
        if self._notify is not None and self._began is not None and text_kernels.is_cached():
            self._notify(compiled_notice("text", time.perf_counter() - self._began))
            self._notify = None
