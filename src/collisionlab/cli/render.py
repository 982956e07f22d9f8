"""Turn a :class:`~collisionlab.record.RunRecord` into text: the lab's table of positions with
collision lines, CSV, JSON, the ``--explain`` working and the summary. Text only: no physics."""

from __future__ import annotations

import csv
import io
import json
import math
from typing import Any

from ..record import CollisionEvent, Frame, RunRecord, SkippedContact
from ..textformat import format_float as _f
from ..vector import Vector3D

__all__ = ["render", "render_csv", "render_json", "render_table"]

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


def _skip_line(skip: SkippedContact) -> str:
    a, b = skip.bodies
    return f"contact {a} / {b} at step {skip.step} (t = {skip.time:.3f} s) skipped: {skip.reason}"


def _row(frame: Frame, dims: int) -> str:
    cells = [f"{frame.step:>6}", f"{frame.time:>{_WIDTH}.4f}"]
    for body in frame.bodies:
        cells += [_f(c, f">{_WIDTH}.4f") for c in body.position.as_tuple()[:dims]]
    return " ".join(cells)


def _header(frame: Frame, dims: int) -> str:
    cells = [f"{'step':>6}", f"{'t (s)':>{_WIDTH}}"]
    for body in frame.bodies:
        cells += [f"{(body.name + '.' + axis)[-_WIDTH:]:>{_WIDTH}}" for axis in "xyz"[:dims]]
    return " ".join(cells)


def summary_lines(record: RunRecord) -> list[str]:
    ledger = record.ledger
    count = len(record.events)
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


def render_table(record: RunRecord, every: int = 1, quiet: bool = False, explain: bool = False) -> str:
    """The lab's output: a row of positions per step, each collision announced after its step
    with the velocity after it, warnings, then the summary. ``quiet`` keeps only events and
    the summary."""
    dims = record.dims
    out: list[str] = [f"{record.title}  (dt = {record.dt:g} s, {record.steps} steps, mode {record.mode})"]
    out += [f"warning: {w}" for w in record.warnings]
    events_by_step: dict[int, list[str]] = {}
    for event in record.events:
        events_by_step.setdefault(event.step, []).extend(_event_lines(event, dims, explain))
    if explain:
        for skip in record.skipped:
            events_by_step.setdefault(skip.step, []).append(_skip_line(skip))
    if not quiet and record.frames:
        out.append(_header(record.frames[0], dims))
    last_step = -1
    for frame in record.frames:
        # Events of the steps between kept frames come first (in step order), then this row,
        # then this step's own events: the same text whether every step was kept or not.
        for step in sorted(s for s in events_by_step if last_step < s < frame.step):
            out += events_by_step[step]
        if not quiet and (frame.step % every == 0 or frame.step == record.steps):
            out.append(_row(frame, dims))
        out += events_by_step.get(frame.step, [])
        last_step = frame.step
    out += summary_lines(record)
    return "\n".join(out) + "\n"


def render_csv(record: RunRecord, every: int = 1) -> str:
    """One row per kept frame: step, time, then x, y, z and vx, vy, vz of every body."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    if record.frames:
        header = ["step", "time"]
        for body in record.frames[0].bodies:
            header += [f"{body.name}.{q}" for q in ("x", "y", "z", "vx", "vy", "vz")]
        writer.writerow(header)
    for frame in record.frames:
        if frame.step % every and frame.step != record.steps:
            continue
        row: list[object] = [frame.step, f"{frame.time:.15g}"]
        for body in frame.bodies:
            # 15 significant digits: every digit a double holds for sure (JSON keeps all 17).
            row += [f"{c:.15g}" for c in (*body.position.as_tuple(), *body.velocity.as_tuple())]
        writer.writerow(row)
    return buffer.getvalue()


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


def _json_lines(data: dict[str, Any]) -> str:
    """``data`` as JSON, one top-level key per line and each item of a list (a frame, an event)
    on a line of its own: readable and line-oriented, and written by the json module's C
    encoder (which ``indent`` turns off: a run's frames and events are most of the work).

    >>> print(_json_lines({"title": "t", "frames": [{"step": 0}, {"step": 1}], "events": []}))
    {
     "title": "t",
     "frames": [
      {"step": 0},
      {"step": 1}
     ],
     "events": []
    }
    """
    parts = []
    for key, value in data.items():
        if isinstance(value, list) and value:
            items = ",\n  ".join(json.dumps(item) for item in value)
            parts.append(f" {json.dumps(key)}: [\n  {items}\n ]")
        else:
            parts.append(f" {json.dumps(key)}: {json.dumps(value)}")
    return "{\n" + ",\n".join(parts) + "\n}"


def render_json(record: RunRecord, every: int = 1) -> str:
    data = _no_signed_zero(record.to_dict())
    data["frames"] = [f for f in data["frames"] if f["step"] % every == 0 or f["step"] == record.steps]
    return _json_lines(data) + "\n"


def render(record: RunRecord, fmt: str, every: int = 1, quiet: bool = False, explain: bool = False) -> str:
    if fmt == "csv":
        return render_csv(record, every)
    if fmt == "json":
        return render_json(record, every)
    return render_table(record, every, quiet, explain)
