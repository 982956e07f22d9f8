"""Turn a :class:`~collisionlab.record.RunRecord` into text: the lab's table of positions with
collision lines (written by :mod:`.event_text`), CSV, JSON and the summary, as the run goes
(writers, each a :class:`~collisionlab.record.RunObserver`) or from a finished record. Text
only: no physics."""

from __future__ import annotations

import csv
import io
import json
import tempfile
from collections.abc import Callable, Iterable, Sequence
from typing import IO, Any, TextIO

import numpy as np

from ..atomic import copy_file
from ..collision_events import EventBlock
from ..record import CollisionEvent, Frame, FrameBodies, RunObserver, RunRecord, SkippedContact
from ..textformat import format_float as _f
from ..vector import Vector3D
from .event_text import COMPILE_NOTICE, TextCompile, block_texts, event_lines
from .event_text import vector_text as _vec

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
        self._text = TextCompile(notify)  # says that the text kernel compiles (once per machine)
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
            for step, text in block_texts(events, self._dims, self._text.say):
                by_step.setdefault(step, []).append(text)
            self._text.done()
        else:
            for event in events:
                lines = event_lines(event, self._dims, self._explain)
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
        self._text = TextCompile(notify)  # says that the JSON layout kernel compiles (once per machine)
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
