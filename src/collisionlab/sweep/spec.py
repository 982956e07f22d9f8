"""The ``[sweep]`` table of a sweep file: read, check, and expand into points.

A sweep file names one base (a scenario file, a built-in demo, or the gas shortcut's
parameters), the parameters to vary by their dotted path, how many replicas (seeds) each point
gets, and the metrics to keep::

    [sweep]
    title = "First collision step against dt"    # optional; default: the file's name
    scenario = "sphere-plane.toml"               # or demo = "sphere-plane", or a [sweep.gas] table
    replicas = 1                                 # rows per point (default 1)
    seed = 0                                     # the seeds are derived from it (default 0)
    metrics = ["first_collision_step", "collisions"]
    combine = "grid"                             # "grid" (every combination, default) or "zip"

    [sweep.parameters]
    "simulation.dt" = [0.01, 0.02, 0.05]                  # a list
    "simulation.restitution" = {start = 0.2, stop = 1, step = 0.2}   # a range, stop included
    "body.ball.velocity.y" = {start = -1, stop = -4, num = 4}        # num values, both ends

    [sweep.plot]                                 # optional: what --plot draws
    x = "simulation.dt"
    y = "first_collision_step"

Paths: ``simulation.KEY``, ``body.NAME.KEY`` and ``static.NAME.KEY`` (NAME is the body's name or
its index in the file, from 0), with an optional ``.x``/``.y``/``.z`` to vary one component of a
vector; ``gas.KEY`` for the gas. The gas is time-stepped (``collisionlab gas``) unless its table
says ``mode = "exact"`` (``collisionlab gas --mode exact``: event-driven, with its own keys, see
:data:`.points.EXACT_GAS_KEYS`); the mode itself cannot be varied. The exact gas may be a
mixture, its species given as ``[[sweep.gas.species]]`` tables (``name``, ``fraction``,
``radius``, optional ``mass``: ``--species NAME:FRACTION:RADIUS[:MASS]``), and
``gas.species.NAME.KEY`` varies one species' ``fraction``, ``radius`` or ``mass`` (the fractions
must still sum to 1: vary two of them together with ``combine = "zip"``). Every problem is a
:class:`SweepError` naming the file and the field, in one line.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import numbers
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..demos import demo_names, demo_text
from ..errors import CollisionLabError, InvalidInputError
from ..scenario_file import read_toml
from .paths import Parameter, SweepError, Value, apply_point, target
from .points import (
    EXACT_GAS_DEFAULTS,
    EXACT_GAS_KEYS,
    EXACT_GAS_METRICS,
    GAS_DEFAULTS,
    GAS_METRICS,
    GAS_MODES,
    SCENARIO_METRICS,
    Task,
    check_base,
)

__all__ = ["MAX_ROWS", "Parameter", "Point", "SweepError", "SweepSpec", "Value", "load_sweep", "parse_sweep"]

#: Rows (points times replicas) at most in one sweep: a typo in a range should not queue a billion tasks.
MAX_ROWS = 1_000_000

_SWEEP_KEYS = {"title", "scenario", "demo", "gas", "parameters", "replicas", "seed", "metrics", "combine", "plot"}
_RANGE_KEYS = {"start", "stop", "step", "num"}
#: Significant digits a range's values are rounded to, so that 0.1 + 2 * 0.1 is written 0.3.
_RANGE_DIGITS = 12


@dataclass(frozen=True)
class Point:
    """One combination of parameter values; ``index`` counts from 0 in the sweep's order."""

    index: int
    values: Mapping[str, Value]


@dataclass(frozen=True)
class SweepSpec:
    """A checked sweep: ``kind`` is ``"scenario"`` (``base`` is the scenario's TOML data) or
    ``"gas"`` (``base`` is the gas's parameters, defaults filled in)."""

    source: str
    title: str
    kind: str
    base: Mapping[str, Any]
    parameters: tuple[Parameter, ...]
    replicas: int = 1
    seed: int = 0
    metrics: tuple[str, ...] = ()
    combine: str = "grid"
    plot_x: str | None = None
    plot_y: str | None = None
    _points: tuple[Point, ...] = field(default=(), repr=False)

    def points(self) -> tuple[Point, ...]:
        return self._points

    def tasks(self) -> list[Task]:
        """One task per point and replica, in the table's order."""
        return [
            Task(
                point=point.index,
                replica=replica,
                seed=derived_seed(self.seed, point.values, replica),
                kind=self.kind,
                data=apply_point(self.base, self.parameters, point.values),
                metrics=self.metrics,
            )
            for point in self._points
            for replica in range(self.replicas)
        ]


def derived_seed(seed: int, values: Mapping[str, Value], replica: int) -> int:
    """The seed of one row: a hash of the sweep's seed, the point's values and the replica, so it
    depends on the point itself, never on the order the rows run in or on the worker.

    >>> derived_seed(0, {"gas.fraction": 0.1}, 0) == derived_seed(0, {"gas.fraction": 0.1}, 0)
    True
    >>> derived_seed(0, {"gas.fraction": 0.1}, 0) != derived_seed(0, {"gas.fraction": 0.1}, 1)
    True
    """
    text = json.dumps([seed, sorted(values.items()), replica], sort_keys=True)
    return int.from_bytes(hashlib.sha256(text.encode()).digest()[:4], "big") >> 1  # 0 <= seed < 2**31


# --- values -------------------------------------------------------------------------------------
def _number(source: str, value: object, field: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(float(value)):
        raise SweepError(source, field, "must be a finite number", got=value)
    return float(value)


def _tidy(value: float, whole: bool) -> float | int:
    """A range's value rounded to ``_RANGE_DIGITS`` significant digits (an int for whole ranges)."""
    return round(value) if whole else float(f"{value:.{_RANGE_DIGITS}g}")


def expand_range(source: str, table: Mapping[str, Any], field: str) -> tuple[float | int, ...]:
    """The values of ``{start, stop, step}`` (stop included when the steps land on it) or
    ``{start, stop, num}`` (``num`` values, both ends included).

    >>> expand_range("f", {"start": 0.1, "stop": 0.5, "step": 0.1}, "p")
    (0.1, 0.2, 0.3, 0.4, 0.5)
    >>> expand_range("f", {"start": 1, "stop": 10, "num": 4}, "p")
    (1, 4, 7, 10)
    """
    for key in table:
        if key not in _RANGE_KEYS:
            raise SweepError(
                source, f"{field}.{key}", "unknown key; a range is {start, stop, step} or {start, stop, num}"
            )
    if "start" not in table or "stop" not in table or ("step" in table) == ("num" in table):
        raise SweepError(source, field, "a range needs start, stop and one of step or num")
    start, stop = _number(source, table["start"], f"{field}.start"), _number(source, table["stop"], f"{field}.stop")
    given = [table["start"], table["stop"], table.get("step", 0)]
    if "num" in table:
        num = table["num"]
        if isinstance(num, bool) or not isinstance(num, int) or num < 1:
            raise SweepError(source, f"{field}.num", "must be a whole number >= 1", got=num)
        if num > MAX_ROWS:
            raise SweepError(source, f"{field}.num", f"must be at most {MAX_ROWS:,}", got=num)
        whole = all(isinstance(v, int) for v in given) and (num == 1 or (stop - start) % (num - 1) == 0)
        raw = [start] if num == 1 else [start + (stop - start) * i / (num - 1) for i in range(num)]
    else:
        step = _number(source, table["step"], f"{field}.step")
        if step == 0 or (stop - start) * step < 0:
            raise SweepError(source, f"{field}.step", "must be non-zero and go from start towards stop", got=step)
        count = math.floor((stop - start) / step) + 2  # one more than fits, dropped below unless it lands on stop
        if count > MAX_ROWS:
            raise SweepError(source, field, f"gives {count:,} values; at most {MAX_ROWS:,}")
        whole = all(isinstance(v, int) for v in given)
        tidied = [_tidy(start + step * i, whole) for i in range(count)]
        return tuple(v for v in tidied if (v - stop) * step <= 0)
    return tuple(_tidy(v, whole) for v in raw)


def _values(source: str, given: object, field: str) -> tuple[Value, ...]:
    if isinstance(given, Mapping):
        return expand_range(source, given, field)
    if not isinstance(given, list) or not given:
        raise SweepError(source, field, "must be a non-empty list of values or a range {start, stop, step|num}")
    for index, value in enumerate(given):
        if isinstance(value, float) and not math.isfinite(value):
            raise SweepError(source, f"{field}[{index}]", "must be finite", got=value)
        if isinstance(value, Mapping):
            raise SweepError(source, f"{field}[{index}]", "must be a number, a string, a boolean or a list", got=value)
    return tuple(given)


# --- the file -----------------------------------------------------------------------------------
def _base(source: str, sweep: Mapping[str, Any], folder: Path) -> tuple[str, dict[str, Any]]:
    given = [key for key in ("scenario", "demo", "gas") if key in sweep]
    if len(given) != 1:
        raise SweepError(
            source,
            "sweep",
            "needs exactly one base: scenario = FILE.toml, demo = NAME or a [sweep.gas] table",
            got=given or None,
        )
    if given[0] == "gas":
        table = sweep["gas"]
        if not isinstance(table, Mapping):
            raise SweepError(source, "sweep.gas", "must be a table of the gas's parameters")
        mode = table.get("mode", "stepped")
        if mode not in GAS_MODES:
            raise SweepError(source, "sweep.gas.mode", f"must be one of {', '.join(map(repr, GAS_MODES))}", got=mode)
        exact = mode == "exact"
        keys, defaults = (EXACT_GAS_KEYS, EXACT_GAS_DEFAULTS) if exact else (tuple(GAS_DEFAULTS), GAS_DEFAULTS)
        for key in table:
            if key not in keys:
                hint = " (each row's seed is derived from sweep.seed)" if key == "seed" else ""
                which = 'the exact gas (mode = "exact")' if exact else 'the stepped gas (mode = "stepped")'
                raise SweepError(
                    source, f"sweep.gas.{key}", f"unknown key for {which}; expected one of {', '.join(keys)}{hint}"
                )
        return "gas", {**defaults, **table}
    if given[0] == "demo":
        name = sweep["demo"]
        if name not in demo_names():
            raise SweepError(source, "sweep.demo", f"unknown demo; expected one of {', '.join(demo_names())}", got=name)
        return "scenario", tomllib.loads(demo_text(name))
    name = sweep["scenario"]
    if not isinstance(name, str):
        raise SweepError(source, "sweep.scenario", "must be the path of a scenario file", got=name)
    path = folder / name

    def invalid(_: str, __: str, problem: str) -> SweepError:  # read as a scenario file is (bounded, UTF-8)
        return SweepError(source, "sweep.scenario", f"{path} {problem}")

    try:
        return "scenario", read_toml(path, invalid, "scenario")
    except OSError as error:
        raise SweepError(source, "sweep.scenario", f"cannot read {path}: {error.strerror or error}") from None


def _whole(source: str, sweep: Mapping[str, Any], key: str, default: int, minimum: int) -> int:
    value = sweep.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise SweepError(source, f"sweep.{key}", f"must be a whole number >= {minimum}", got=value)
    return value


def _metrics(source: str, sweep: Mapping[str, Any], kind: str, exact: bool = False) -> tuple[str, ...]:
    known = (EXACT_GAS_METRICS if exact else GAS_METRICS) if kind == "gas" else SCENARIO_METRICS
    given = sweep.get("metrics")
    if given is None:
        raise SweepError(source, "sweep.metrics", f"is missing; a list of: {', '.join(known)}")
    if not isinstance(given, list) or not given or not all(isinstance(m, str) for m in given):
        raise SweepError(source, "sweep.metrics", f"must be a non-empty list of names: {', '.join(known)}", got=given)
    for index, name in enumerate(given):
        if name not in known:
            base = ('the exact gas (mode = "exact")' if exact else "the gas") if kind == "gas" else "a scenario"
            raise SweepError(
                source, f"sweep.metrics[{index}]", f"unknown for {base}; expected one of {', '.join(known)}", got=name
            )
    return tuple(dict.fromkeys(given))


def _expand(source: str, parameters: tuple[Parameter, ...], combine: str, replicas: int) -> tuple[Point, ...]:
    paths = [p.path for p in parameters]
    if combine == "zip":
        lengths = {len(p.values) for p in parameters}
        if len(lengths) > 1:
            raise SweepError(source, "sweep.combine", "zip needs every parameter to have as many values", got=combine)
        rows = list(zip(*(p.values for p in parameters), strict=True))
    else:
        total = math.prod(len(p.values) for p in parameters) * replicas
        if total > MAX_ROWS:
            raise SweepError(source, "sweep.parameters", f"the grid has {total:,} rows; at most {MAX_ROWS:,}")
        rows = list(itertools.product(*(p.values for p in parameters)))
    return tuple(Point(i, dict(zip(paths, row, strict=True))) for i, row in enumerate(rows))


def parse_sweep(data: Mapping[str, Any], source: str = "<sweep>", folder: Path = Path(".")) -> SweepSpec:
    """A :class:`SweepSpec` from a sweep file's parsed TOML (``folder``: where ``scenario`` is looked up)."""
    for key in data:
        if key != "sweep":
            raise SweepError(source, key, "unknown table; a sweep file has one [sweep] table")
    sweep = data.get("sweep")
    if not isinstance(sweep, Mapping):
        raise SweepError(source, "sweep", "is missing: the file needs a [sweep] table")
    for key in sweep:
        if key not in _SWEEP_KEYS:
            raise SweepError(source, f"sweep.{key}", f"unknown key; expected one of {', '.join(sorted(_SWEEP_KEYS))}")
    kind, base = _base(source, sweep, folder)
    try:
        check_base(kind, base)
    except InvalidInputError as error:
        raise SweepError(
            source, f"sweep.{'gas' if kind == 'gas' else 'scenario'}", f"the base is invalid: {error}"
        ) from None
    table = sweep.get("parameters")
    if not isinstance(table, Mapping) or not table:
        raise SweepError(source, "sweep.parameters", 'needs at least one parameter, as "PATH" = [values]')
    parameters = []
    for path, given in table.items():
        where = f"sweep.parameters.{path}"
        keys, component = target(source, kind, base, path, where)
        parameters.append(Parameter(path, _values(source, given, where), keys, component))
    combine = sweep.get("combine", "grid")
    if combine not in ("grid", "zip"):
        raise SweepError(source, "sweep.combine", "must be 'grid' or 'zip'", got=combine)
    replicas = _whole(source, sweep, "replicas", 1, 1)
    seed = _whole(source, sweep, "seed", 0, 0)
    metrics = _metrics(source, sweep, kind, exact=kind == "gas" and base["mode"] == "exact")
    plot = sweep.get("plot", {})
    if not isinstance(plot, Mapping) or any(k not in ("x", "y") for k in plot):
        raise SweepError(source, "sweep.plot", "must be a table with x (a parameter) and y (a metric)", got=plot)
    plot_x, plot_y = plot.get("x"), plot.get("y")
    if plot_x is not None and plot_x not in table:
        raise SweepError(source, "sweep.plot.x", f"must be a varied parameter: {', '.join(table)}", got=plot_x)
    if plot_y is not None and plot_y not in metrics:
        raise SweepError(source, "sweep.plot.y", f"must be one of the metrics: {', '.join(metrics)}", got=plot_y)
    title = sweep.get("title", Path(source).stem)
    if not isinstance(title, str):
        raise SweepError(source, "sweep.title", "must be a string", got=title)
    params = tuple(parameters)
    points = _expand(source, params, combine, replicas)
    return SweepSpec(source, title, kind, base, params, replicas, seed, metrics, combine, plot_x, plot_y, points)


def load_sweep(path: str | Path) -> SweepSpec:
    """Read and check a sweep file."""
    # As a scenario file is read: bounded (sweep /dev/zero grew for ever), UTF-8 (else a raw
    # UnicodeDecodeError), not nested too deeply (else a RecursionError); a missing file is exit 1.
    source = str(path)
    try:
        data = read_toml(path, SweepError, "sweep")
    except OSError as error:  # not bad data but a missing file: an "other failure" (exit status 1)
        raise CollisionLabError(f"{source}: cannot be read: {error.strerror or error}") from None
    return parse_sweep(data, source, Path(path).parent)
