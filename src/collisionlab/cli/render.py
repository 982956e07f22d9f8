"""Turn a :class:`~collisionlab.record.RunRecord` into text: the lab's table of positions with
collision lines, CSV, JSON, the ``--explain`` working and the summary. Text only: no physics."""

from __future__ import annotations

import csv
import functools
import io
import json
import math
import sys
import tempfile
import time
from collections.abc import Callable, Iterable, Sequence
from typing import IO, Any, TextIO

import numpy as np
from numpy.typing import NDArray

from .. import text_kernels
from ..atomic import copy_file
from ..collision_events import EventBlock
from ..numba_cache import compiled_notice, compiling_notice
from ..record import CollisionEvent, Frame, FrameBodies, RunObserver, RunRecord, SkippedContact
from ..textformat import format_float as _f
from ..vector import Vector3D

__all__ = [
    "COMPILE_NOTICE",
    "CsvWriter",
    "JsonWriter",
    "TableWriter",
    "render",
    "render_csv",
    "render_json",
    "render_table",
    "writer_for",
]

_WIDTH = 11


def _vec(v: Vector3D, dims: int = 3, digits: int = 3) -> str:
    return "(" + ", ".join(_f(c, f".{digits}f") for c in v.as_tuple()[:dims]) + ")"


def _number(x: float) -> str:
    return "inf" if math.isinf(x) else _f(x, ".4g")


def _event_lines(event: CollisionEvent, dims: int, explain: bool) -> list[str]:
    a, b = event.bodies
    verb = f"{b} hits {a}" if event.static else f"{a} and {b} collide"
    lines = [f"collision at step {event.step} (t = {event.time:.3f} s): {verb}"]
    after = ", ".join(f"{name} = {_vec(v, dims)}" for name, v in event.velocities_after.items())
    label = "velocity after" if len(event.velocities_after) == 1 else "velocities after"
    if explain:
        m_a, m_b = event.masses
        inv_a = "0" if math.isinf(m_a) else f"1/{_number(m_a)}"
        v_n = _f(event.approach_speed, ".4f")
        lines += [
            f"    normal n = {_vec(event.normal, dims)} (from {a} to {b}), contact point {_vec(event.point, dims)}",
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
                f"    v_{name} {sign}= (j / {_number(mass)}) n: {_vec(before, dims)} -> "
                f"{_vec(event.velocities_after[name], dims)}"
            )
        lines.append(f"    kinetic energy {event.kinetic_energy_before:.4f} J -> {event.kinetic_energy_after:.4f} J")
    lines.append(f"  {label}: {after} m/s")
    return lines


def _block_templates(dims: int) -> tuple[str, str]:
    """The ``%`` templates of :func:`_event_lines`'s text (without ``--explain``) of an event
    between two bodies and of a body against an obstacle, for :func:`_block_texts`'s arguments:
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


def _block_texts(block: EventBlock, dims: int, compiling: Callable[[], None] | None = None) -> list[tuple[int, str]]:
    """The text of :func:`_event_lines` (without ``--explain``) of every event of ``block``, one
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
    """:func:`_block_texts` by :func:`text_kernels.lay_out <collisionlab.text_kernels.lay_out>`,
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
    """:func:`_block_texts` with one ``%`` a step: each step's text and its first event."""
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


def _skip_line(skip: SkippedContact) -> str:
    a, b = skip.bodies
    return f"contact {a} / {b} at step {skip.step} (t = {skip.time:.3f} s) skipped: {skip.reason}"


def _row(frame: Frame, dims: int) -> str:
    cells = [f"{frame.step:>6}", f"{frame.time:>{_WIDTH}.4f}"]
    bodies = frame.bodies
    if isinstance(bodies, FrameBodies):  # a world's frame: from its arrays
        cells += [_f(c, f">{_WIDTH}.4f") for c in bodies.positions[:, :dims].ravel().tolist()]
    else:
        for body in bodies:
            cells += [_f(c, f">{_WIDTH}.4f") for c in body.position.as_tuple()[:dims]]
    return " ".join(cells)


def _header(frame: Frame, dims: int) -> str:
    cells = [f"{'step':>6}", f"{'t (s)':>{_WIDTH}}"]
    for body in frame.bodies:
        cells += [f"{(body.name + '.' + axis)[-_WIDTH:]:>{_WIDTH}}" for axis in "xyz"[:dims]]
    return " ".join(cells)


def summary_lines(record: RunRecord) -> list[str]:
    ledger = record.ledger
    count = record.collision_total
    duration = record.frames[-1].time if record.frames else 0.0
    lines = [
        f"summary: {count} collision{'s' if count != 1 else ''} in {record.steps} steps "
        f"({duration:.3f} s, mode {record.mode})",
        f"  momentum        start {_vec(ledger.momentum_start)} kg m/s   end {_vec(ledger.momentum_end)} kg m/s",
        f"  kinetic energy  start {ledger.kinetic_start:.6g} J   end {ledger.kinetic_end:.6g} J",
    ]
    if record.gravity != Vector3D(0, 0, 0):
        lines.append(
            f"  potential       start {_f(ledger.potential_start, '.6g')} J   end {_f(ledger.potential_end, '.6g')} J"
        )
    change, theory = _f(ledger.energy_end - ledger.energy_start, "+.6g"), _f(ledger.collisions_predicted, "+.6g")
    lines.append(
        f"  energy change {change} J: collisions {_f(ledger.collisions, '+.6g')} "
        f"(theory (1-e^2)/2 mu v_n^2: {theory}), "
        f"integrator {_f(ledger.integrator, '+.6g')}, push-apart {_f(ledger.push_apart, '+.6g')}, "
        f"rounding {_f(ledger.residual, '+.2g')}"
    )
    if ledger.max_penetration > 0.0:
        lines.append(f"  deepest overlap undone by push-apart: {ledger.max_penetration:.3g} m")
    # An event-driven mixture: each kind of ball (a [[gas]] table), its kT from its kinetic energy
    # averaged over the run (under gravity, the end's: it changes in flight too).
    when = "averaged over the run" if record.gravity == Vector3D(0, 0, 0) else "at the end"
    for kind in record.species or ():
        balls = f"{kind['count']} ball{'s' if kind['count'] != 1 else ''}"
        lines.append(
            f"  species {kind['name']}: {balls}, radius {kind['radius']:g} m, mass {kind['mass']:g} kg, "
            f"kT {kind['kT']:.6g} J (2 <E_kin> / (d N), {when})"
        )
    return lines


class _TextCompile:
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


class TableWriter:
    """The lab's output, written as the run goes (a :class:`~collisionlab.record.RunObserver`):
    a row of positions per kept step, each collision announced after its step with the velocity
    after it, warnings, then the summary. ``quiet`` keeps only events and the summary. Events of
    the steps between two kept rows come before the later row, a row's own step's after it."""

    def __init__(
        self,
        out: TextIO,
        every: int = 1,
        quiet: bool = False,
        explain: bool = False,
        notify: Callable[[str], None] | None = None,
    ) -> None:
        self._out, self._every, self._quiet, self._explain = out, every, quiet, explain
        self._text = _TextCompile(notify)  # says that the text kernel compiles (once per machine)
        self._dims = 3
        self._steps = 0
        self._pending: list[tuple[int, str]] = []  # (step, its lines) not yet written
        self._header = False

    def begin(self, record: RunRecord) -> None:
        self._dims, self._steps = record.dims, record.steps
        self._out.write(f"{record.title}  (dt = {record.dt:g} s, {record.steps} steps, mode {record.mode})\n")
        for text in record.warnings:
            self.warning(text)

    def _flush(self, below: int) -> None:
        kept = []
        for step, text in self._pending:
            if step < below:
                self._out.write(text)
            else:
                kept.append((step, text))
        self._pending = kept

    def frame(self, frame: Frame) -> None:
        self._flush(frame.step)
        if not self._quiet:
            if not self._header:
                self._out.write(_header(frame, self._dims) + "\n")
                self._header = True
            if frame.step % self._every == 0 or frame.step == self._steps:
                self._out.write(_row(frame, self._dims) + "\n")
        self._flush(frame.step + 1)

    def events(self, events: Sequence[CollisionEvent], skipped: Sequence[SkippedContact], reached: int) -> None:
        by_step: dict[int, list[str]] = {}
        if isinstance(events, EventBlock) and not self._explain:  # a world's events: from their columns
            for step, text in _block_texts(events, self._dims, self._text.say):
                by_step.setdefault(step, []).append(text)
            self._text.done()
        else:
            for event in events:
                lines = _event_lines(event, self._dims, self._explain)
                by_step.setdefault(event.step, []).extend(line + "\n" for line in lines)
        if self._explain:
            for skip in skipped:
                by_step.setdefault(skip.step, []).append(_skip_line(skip) + "\n")
        self._pending += sorted(((step, "".join(texts)) for step, texts in by_step.items()), key=lambda item: item[0])
        self._flush(reached)

    def warning(self, text: str) -> None:
        self._out.write(f"warning: {text}\n")

    def end(self, record: RunRecord) -> None:
        self._flush(record.steps + 1)
        self._out.writelines(line + "\n" for line in summary_lines(record))


class CsvWriter:
    """One row per kept frame: step, time, then x, y, z and vx, vy, vz of every body."""

    def __init__(self, out: TextIO, every: int = 1) -> None:
        self._writer = csv.writer(out, lineterminator="\n")
        self._every = every
        self._steps = 0
        self._header = False

    def begin(self, record: RunRecord) -> None:
        self._steps = record.steps

    def frame(self, frame: Frame) -> None:
        if not self._header:
            header = ["step", "time"]
            for body in frame.bodies:
                header += [f"{body.name}.{q}" for q in ("x", "y", "z", "vx", "vy", "vz")]
            self._writer.writerow(header)
            self._header = True
        if frame.step % self._every and frame.step != self._steps:
            return
        row: list[object] = [frame.step, f"{frame.time:.15g}"]
        # 15 significant digits: every digit a double holds for sure (JSON keeps all 17).
        bodies = frame.bodies
        if isinstance(bodies, FrameBodies):  # a world's frame: from its arrays (+ 0.0: no signed zero)
            row += [f"{c:.15g}" for c in (np.hstack((bodies.positions, bodies.velocities)) + 0.0).ravel().tolist()]
        else:
            for body in bodies:
                row += [f"{c:.15g}" for c in (*body.position.as_tuple(), *body.velocity.as_tuple())]
        self._writer.writerow(row)

    def events(self, events: Sequence[CollisionEvent], skipped: Sequence[SkippedContact], reached: int) -> None:
        pass

    def warning(self, text: str) -> None:
        pass

    def end(self, record: RunRecord) -> None:
        pass


def _no_signed_zero(value: Any) -> Any:
    """``value`` with every ``-0.0`` inside it replaced by ``0.0`` (a signed zero reads as a
    different number to a person and to some parsers)."""
    if isinstance(value, float):
        return value + 0.0
    if isinstance(value, dict):
        return {k: _no_signed_zero(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_no_signed_zero(v) for v in value]
    return value


def _dumps(value: Any) -> str:
    return json.dumps(_no_signed_zero(value))


def _dumps_item(item: Frame | CollisionEvent | SkippedContact) -> str:
    """A frame, event or skipped contact: their ``to_dict`` already writes no signed zero."""
    return json.dumps(item.to_dict())


class JsonWriter:
    """One JSON object per run, written as it goes: one top-level key per line and each frame,
    event and skipped contact on a line of its own (readable, line-oriented, and written by the
    json module's C encoder, which ``indent`` would turn off; a world's events by
    :meth:`EventBlock.json_chunks <collisionlab.record.EventBlock.json_chunks>`). Frames go
    straight out; events and skipped contacts, which the object lists after the frames, wait in
    temporary files (disk, not memory), already with the commas between them, and are copied in
    whole at the end (:func:`~collisionlab.atomic.copy_file`). The object ends with ``}`` (no newline)."""

    def __init__(self, out: TextIO, every: int = 1, notify: Callable[[str], None] | None = None) -> None:
        self._out, self._every = out, every
        self._text = _TextCompile(notify)  # says that the JSON layout kernel compiles (once per machine)
        self._steps = 0
        self._frames = 0
        self._spools: dict[str, tuple[IO[bytes], list[int]]] = {}  # each with the pieces written to it

    def begin(self, record: RunRecord) -> None:
        self._steps = record.steps
        self._out.write("{\n" + "".join(f" {json.dumps(k)}: {_dumps(v)},\n" for k, v in record.header_dict().items()))
        self._out.write(' "frames": [')
        # Open across calls, closed by end(); a run that fails drops them (already unlinked).
        self._spools = {
            key: (tempfile.TemporaryFile("w+b"), [0])  # noqa: SIM115 (UTF-8: the pieces come as bytes)
            for key in ("events", "skipped")
        }

    def frame(self, frame: Frame) -> None:
        if frame.step % self._every and frame.step != self._steps:
            return
        self._out.write(("\n  " if self._frames == 0 else ",\n  ") + _dumps_item(frame))
        self._frames += 1

    def events(self, events: Sequence[CollisionEvent], skipped: Sequence[SkippedContact], reached: int) -> None:
        for key, items in (("events", events), ("skipped", skipped)):
            if not items:
                continue
            spool, written = self._spools[key]
            # Each item after ",\n  ", the first of all after "\n  " (the list's first line).
            if isinstance(items, EventBlock):  # a world's events: written from their columns
                self._text.say()
                chunks: Iterable[bytes | memoryview] = items.json_chunks(",\n  ")
            else:
                chunks = ["".join(",\n  " + _dumps_item(item) for item in items).encode()]
            for text in chunks:
                spool.write(text if written[0] else text[1:])
                written[0] += 1
            self._text.done()

    def warning(self, text: str) -> None:
        pass  # the record's warnings are written at the end

    def end(self, record: RunRecord) -> None:
        self._out.write("\n ]" if self._frames else "]")
        for key, (spool, written) in self._spools.items():
            self._out.write(f",\n {json.dumps(key)}: [")
            if written[0]:
                copy_file(spool, self._out)  # not read into memory: the spool may be larger
                self._out.write("\n ]")
            else:
                self._out.write("]")
            spool.close()
        self._out.write("".join(f",\n {json.dumps(k)}: {_dumps(v)}" for k, v in record.footer_dict().items()))
        self._out.write("\n}")


def writer_for(
    fmt: str,
    out: TextIO,
    every: int = 1,
    quiet: bool = False,
    explain: bool = False,
    notify: Callable[[str], None] | None = None,
) -> RunObserver:
    """The writer of ``fmt`` (``table``, ``csv`` or ``json``) into ``out``; ``notify`` hears
    what takes time (the writers' text kernel compiling)."""
    if fmt == "csv":
        return CsvWriter(out, every)
    if fmt == "json":
        return JsonWriter(out, every, notify)
    return TableWriter(out, every, quiet, explain, notify)


def _replayed(record: RunRecord, writer: Callable[[TextIO], RunObserver]) -> str:
    """The text ``writer`` writes of the whole ``record``."""
    buffer = io.StringIO()
    record.replay(writer(buffer))
    return buffer.getvalue()


def render_table(record: RunRecord, every: int = 1, quiet: bool = False, explain: bool = False) -> str:
    """The lab's output of a whole record (:class:`TableWriter`)."""
    return _replayed(record, lambda out: TableWriter(out, every, quiet, explain))


def render_csv(record: RunRecord, every: int = 1) -> str:
    """The CSV of a whole record (:class:`CsvWriter`)."""
    return _replayed(record, lambda out: CsvWriter(out, every))


def render_json(record: RunRecord, every: int = 1) -> str:
    """The JSON of a whole record (:class:`JsonWriter`), with a final newline."""
    return _replayed(record, lambda out: JsonWriter(out, every)) + "\n"


def render(record: RunRecord, fmt: str, every: int = 1, quiet: bool = False, explain: bool = False) -> str:
    if fmt == "csv":
        return render_csv(record, every)
    if fmt == "json":
        return render_json(record, every)
    return render_table(record, every, quiet, explain)
