"""The sweep's picture: a metric against a swept parameter, with the spread over replicas.

Each point's replicas are drawn as small dots and their mean with an error bar of one standard
deviation (none with one replica). With several parameters, each combination of the others is
its own series. A value the runs did not give (no collision at all: the ball tunnelled through)
is marked along the bottom. For the compressibility of the gas against ``gas.fraction``, the
hard-ball equation of state (:mod:`.theory`: Carnahan-Starling in 3D, Henderson in 2D) is drawn
beside the points; against another parameter of the exact gas, the rows' own
``compressibility_theory`` (a mixture's: BMCSL in 3D) when the sweep keeps that metric.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from ..atomic import atomic_path
from ..errors import InvalidInputError
from .spec import SweepSpec
from .store import Column
from .theory import hard_ball_compressibility

__all__ = ["MAX_SERIES", "plot_axes", "save_sweep_plot"]

#: Series (combinations of the other parameters) drawn at most; the rest are left out, and said so.
MAX_SERIES = 8
_NUMERIC = ("int", "float", "bool")


def plot_axes(spec: SweepSpec, columns: Sequence[Column]) -> tuple[str, str]:
    """The parameter on x and the metric column on y: the sweep file's ``[sweep.plot]``, else the
    first numeric parameter and the first numeric metric column."""
    kinds = dict(columns)
    x = spec.plot_x or next((p.path for p in spec.parameters if kinds[p.path] in _NUMERIC), None)
    if x is None or kinds[x] not in _NUMERIC:
        raise InvalidInputError("--plot", "needs a parameter with numeric values to put on the x axis")
    metric_names = [name for name, _ in columns[columns.index(("error", "str")) + 1 :]]
    if spec.plot_y is not None:
        y = next(name for name in metric_names if name == spec.plot_y or name.startswith(spec.plot_y + "_"))
    else:
        y = next((name for name in metric_names if kinds[name] in _NUMERIC), metric_names[0])
    return x, y


def _series(rows: Sequence[Mapping[str, Any]], x: str, others: Sequence[str]) -> dict[tuple[Any, ...], list[Any]]:
    groups: dict[tuple[Any, ...], list[Any]] = {}
    for row in rows:
        groups.setdefault(tuple(row[o] for o in others), []).append(row)
    return groups


def save_sweep_plot(path: str, spec: SweepSpec, columns: Sequence[Column], rows: Sequence[Mapping[str, Any]]) -> str:
    """Draw the picture of ``rows`` (the table's rows) and write it to ``path`` atomically; returns a
    note on what was left out (or "")."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from ..plotting.static import check_plot_path

    target = check_plot_path(path)
    x, y = plot_axes(spec, columns)
    others = [p.path for p in spec.parameters if p.path != x]
    figure = Figure(figsize=(8, 5), dpi=100)
    FigureCanvasAgg(figure)
    axes = figure.add_subplot()
    groups = _series(rows, x, others)
    note = f"{len(groups) - MAX_SERIES} series of {len(groups)} not drawn" if len(groups) > MAX_SERIES else ""
    missing: list[tuple[list[float], str, str]] = []
    for number, (label_values, members) in enumerate(list(groups.items())[:MAX_SERIES]):
        by_x: dict[float, list[float]] = {}
        missing_x: list[float] = []
        for row in members:
            value = row[y]
            if row["error"]:
                continue
            if value is None or (isinstance(value, float) and math.isnan(value)):
                missing_x.append(float(row[x]))
                continue
            by_x.setdefault(float(row[x]), []).append(float(value))
        xs = sorted(by_x)
        color = f"C{number}"
        label = ", ".join(f"{o} = {v}" for o, v in zip(others, label_values, strict=True)) or "sweep"
        means = [sum(by_x[v]) / len(by_x[v]) for v in xs]
        spreads = [_deviation(by_x[v]) for v in xs]
        for v in xs:
            axes.plot([v] * len(by_x[v]), by_x[v], ".", color=color, alpha=0.3, markersize=4)
        axes.errorbar(xs, means, yerr=spreads, fmt="o-", color=color, capsize=3, label=f"{label} (mean ± sd)")
        if missing_x:
            missing.append((missing_x, color, label))
    bottom = axes.get_ylim()[0]
    for missing_x, color, label in missing:
        axes.plot(missing_x, [bottom] * len(missing_x), "x", color=color, markersize=9, label=f"{label}: no {y}")
    if spec.kind == "gas" and y == "compressibility" and x == "gas.fraction":
        dim = int(spec.base["dim"])
        xs_all = sorted({float(row[x]) for row in rows})
        if xs_all:
            grid = [xs_all[0] + (xs_all[-1] - xs_all[0]) * i / 200 for i in range(201)]
            name = "Carnahan-Starling" if dim == 3 else "Henderson (2D Carnahan-Starling)"
            axes.plot(grid, [hard_ball_compressibility(p, dim) for p in grid], "k--", label=name)
    elif spec.kind == "gas" and y == "compressibility":
        _theory_beside(axes, spec, rows, x)
    axes.set_xlabel(x)
    axes.set_ylabel(y)
    axes.set_title(spec.title)
    axes.grid(alpha=0.3)
    axes.legend(fontsize="small")
    figure.tight_layout()
    with atomic_path(target) as temporary:
        figure.savefig(temporary, format=target.suffix.lower().lstrip("."))
    return note


def _theory_beside(axes: Any, spec: SweepSpec, rows: Sequence[Mapping[str, Any]], x: str) -> None:
    """The rows' ``compressibility_theory`` (the exact gas's metric) against ``x``, as a dashed
    line: BMCSL (or its 2D counterpart) for a mixture, against e.g. a species' radius."""
    by_x: dict[float, float] = {}
    for row in rows:
        value = row.get("compressibility_theory")
        if not row["error"] and value is not None and not (isinstance(value, float) and math.isnan(value)):
            by_x[float(row[x])] = float(value)
    if not by_x:
        return
    dim = int(spec.base["dim"])
    if spec.base.get("species"):
        name = "BMCSL (mixture)" if dim == 3 else "Santos-Yuste-López de Haro (2D mixture)"
    else:
        name = "Carnahan-Starling" if dim == 3 else "Henderson (2D Carnahan-Starling)"
    xs = sorted(by_x)
    axes.plot(xs, [by_x[v] for v in xs], "k--", label=name)


def _deviation(values: Sequence[float]) -> float:
    """The sample standard deviation (0 for one value).

    >>> _deviation([1.0, 3.0])   # mean 2, squares 1 + 1, over n - 1 = 1
    1.4142135623730951
    """
    if len(values) < 2:
        return 0.0
    mean = sum(values) / len(values)
    return math.sqrt(sum((v - mean) ** 2 for v in values) / (len(values) - 1))
