"""Turn a :class:`~collisionlab.record.RunRecord` into text: the lab's table of positions with
collision lines, CSV, JSON, the ``--explain`` working and the summary. Text only: no physics."""

from __future__ import annotations

import csv
import io
import json
import math
import tempfile
from collections.abc import Callable, Iterable, Sequence
from typing import IO, Any, TextIO

import numpy as np

from .. import text_kernels
from ..atomic import copy_file
from ..record import CollisionEvent, EventBlock, Frame, FrameBodies, RunObserver, RunRecord, SkippedContact
from ..textformat import format_float as _f
from ..vector import Vector3D

__all__ = [
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


def _block_texts(block: EventBlock, dims: int) -> list[tuple[int, str]]:
    """The text of :func:`_event_lines` (without ``--explain``) of every event of ``block``, one
    text (its lines, each ending in a newline) per step, the steps in order and each step's
    events in the block's order: the same text, written from the block's columns, with one ``%``
    a step (a heap of balls makes millions of events)."""
    n = len(block)
    if not n:
        return []
    steps, a, b = block.step, block.a, block.b
    order = np.argsort(steps, kind="stable") if np.any(np.diff(steps) < 0) else slice(None)
    steps, a, b = steps[order], a[order], b[order]
    ids, index = np.unique(np.concatenate((a, b)), return_inverse=True)
    names = np.array([block.static_names[-1 - i] if i < 0 else block.names[i] for i in ids.tolist()], dtype=object)
    name_a, name_b = names[index[:n]], names[index[n:]]
    static = a < 0
    # No signed zero: a velocity that .3f would write -0.000 (below half a thousandth, as a
    # double: 0.0005 is a little more than 5e-4) is written 0.000.
    after = np.column_stack((block.after_a[order, :dims], block.after_b[order, :dims]))
    after = np.where(np.abs(after) < 0.0005, 0.0, after).astype(object)
    after[static, :dims] = ""
    arguments = np.empty((n, 6 + 2 * dims), dtype=object)
    arguments[:, 0] = steps.astype(object)
    arguments[:, 1] = block.time[order].astype(object)
    arguments[:, 2] = np.where(static, name_b, name_a)  # "A and B collide", "B hits A"
    arguments[:, 3] = np.where(static, name_a, name_b)
    arguments[:, 4] = np.where(static, "", name_a)
    arguments[:, 5 : 5 + dims] = after[:, :dims]
    arguments[:, 5 + dims] = name_b
    arguments[:, 6 + dims :] = after[:, dims:]
    pair, obstacle = _block_templates(dims)
    templates = np.where(static, obstacle, pair).astype(object).tolist()
    values = arguments.ravel().tolist()
    width = arguments.shape[1]
    starts = [0, *(np.flatnonzero(np.diff(steps)) + 1).tolist()]
    out = []
    for start, stop in zip(starts, [*starts[1:], n], strict=True):
        text = "".join(templates[start:stop]) % tuple(values[start * width : stop * width])
        out.append((int(steps[start]), text))
    return out


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
    return lines


class TableWriter:
    """The lab's output, written as the run goes (a :class:`~collisionlab.record.RunObserver`):
    a row of positions per kept step, each collision announced after its step with the velocity
    after it, warnings, then the summary. ``quiet`` keeps only events and the summary. Events of
    the steps between two kept rows come before the later row, a row's own step's after it."""

    def __init__(self, out: TextIO, every: int = 1, quiet: bool = False, explain: bool = False) -> None:
        self._out, self._every, self._quiet, self._explain = out, every, quiet, explain
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
            for step, text in _block_texts(events, self._dims):
                by_step.setdefault(step, []).append(text)
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
        self._notify = notify  # hears that the JSON layout kernel compiles (once per machine)
        self._steps = 0
        self._frames = 0
        self._spools: dict[str, tuple[IO[str], list[int]]] = {}  # each with the pieces written to it

    def begin(self, record: RunRecord) -> None:
        self._steps = record.steps
        self._out.write("{\n" + "".join(f" {json.dumps(k)}: {_dumps(v)},\n" for k, v in record.header_dict().items()))
        self._out.write(' "frames": [')
        # Open across calls, closed by end(); a run that fails drops them (already unlinked).
        self._spools = {
            key: (tempfile.TemporaryFile("w+", encoding="utf-8"), [0])  # noqa: SIM115
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
                if self._notify is not None and not text_kernels.is_cached():
                    self._notify("compiling the JSON writer's kernel (once per machine)...")
                    self._notify = None
                chunks: Iterable[str] = items.json_chunks(",\n  ")
            else:
                chunks = ["".join(",\n  " + _dumps_item(item) for item in items)]
            for text in chunks:
                spool.write(text if written[0] else text[1:])
                written[0] += 1

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
    what takes time (the JSON writer's kernel compiling)."""
    if fmt == "csv":
        return CsvWriter(out, every)
    if fmt == "json":
        return JsonWriter(out, every, notify)
    return TableWriter(out, every, quiet, explain)


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
