"""The static picture of a run (``--plot FILE.png``), drawn with matplotlib's Agg canvas.

Left: the trajectories of every moving body, each body's shape outlined at its start (dashed)
and end (solid), the static obstacles (a line across the view, a plane as a square patch,
boxes as boxes) and every collision marked where it happened, labelled with its step. 2D runs
are drawn in the x-y plane with equal axes; 3D runs in true 3D axes with y up (the lab's
floors are ``y = 0``). Right: kinetic, potential and total energy over time above the momentum
components, with each collision's time as a faint vertical line and the run's energy ledger.

Thinning: at most :data:`MAX_POINTS` frames are drawn per trajectory and energy curve, evenly
spaced, plus the frames on both sides of every collision (so a bounce keeps its corner). Every
collision gets a marker (an even choice of 1,000 when there are more); at most
:data:`~._data.MAX_LABELLED_EVENTS` get a "step N" label, skipping any that would sit on top of
one already labelled.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Circle as CirclePatch
from matplotlib.patches import Patch, Rectangle
from mpl_toolkits.mplot3d.art3d import Poly3DCollection
from numpy.typing import NDArray

from ..atomic import atomic_path
from ..model import Scenario
from ..shapes import AABB, Circle, Line, Plane, Sphere
from ..tolerances import PICTURE_MIN_SPAN
from ._data import (
    Array,
    Bounds,
    RunArrays,
    box_edges,
    check_path,
    line_segment,
    plane_patch,
    sphere_mesh,
    thin_indices,
    uncrowded,
)
from ._run import DrawnRun

__all__ = ["DEFAULT_SIZE", "MAX_POINTS", "draw_figure", "save_plot"]

#: Width and height (pixels) of a plot when no size is asked for.
DEFAULT_SIZE = (1200, 800)
#: At most this many frames (plus those around collisions) per trajectory and energy curve.
MAX_POINTS = 2000
_DPI = 100
OBSTACLE_COLOR = "0.45"
EVENT_COLOR = "crimson"


def body_color(index: int) -> str:
    """The colour of body ``index`` in every picture (matplotlib's tab10 cycle)."""
    return f"C{index % 10}"


def m3(points: Array) -> tuple[Array, Array, Array]:
    """Data coordinates (..., 3) as matplotlib 3D axes coordinates: y is drawn up."""
    return points[..., 0], points[..., 2], points[..., 1]


def setup_view(ax: Any, bounds: Bounds, dims: int) -> None:
    """Equal axes around ``bounds`` with labelled units: x-y for 2D, a cube (y up) for 3D."""
    if dims == 2:
        # Widen the shorter data range to the axes' own shape, so equal axes fill the panel.
        box = ax.get_position()
        fig_w, fig_h = ax.figure.get_size_inches()
        screen_ratio = (box.height * fig_h) / (box.width * fig_w)  # a panel has a size
        (x0, y0), (x1, y1) = bounds.low[:2], bounds.high[:2]
        cx, cy, w, h = (x0 + x1) / 2, (y0 + y1) / 2, max(x1 - x0, PICTURE_MIN_SPAN), max(y1 - y0, PICTURE_MIN_SPAN)
        if h / w < screen_ratio:
            h = w * screen_ratio
        else:
            w = h / screen_ratio
        ax.set_xlim(cx - w / 2, cx + w / 2)
        ax.set_ylim(cy - h / 2, cy + h / 2)
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.grid(True, alpha=0.3)
        return
    cube = bounds.cube()
    ax.set_xlim(cube.low[0], cube.high[0])
    ax.set_ylim(cube.low[2], cube.high[2])
    ax.set_zlim(cube.low[1], cube.high[1])
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    ax.set_zlabel("y (m)")
    ax.view_init(elev=22, azim=-60)


def draw_obstacles(ax: Any, scenario: Scenario, bounds: Bounds, dims: int) -> list[Any]:
    """Every static obstacle, labelled with its name; returns legend handles."""
    handles: list[Any] = []
    for obstacle in scenario.obstacles:
        shape = obstacle.shape
        label = f"{obstacle.name} (static {type(shape).__name__.lower()})"
        if isinstance(shape, Line):
            a, b = line_segment(shape, bounds)
            if dims == 2:
                ax.axline(a[:2], b[:2], color=OBSTACLE_COLOR, lw=2.5)
            else:
                ax.plot(*m3(np.array([a, b])), color=OBSTACLE_COLOR, lw=2.5)
            handles.append(Line2D([], [], color=OBSTACLE_COLOR, lw=2.5, label=label))
        elif isinstance(shape, Plane):
            corners = plane_patch(shape, bounds)
            poly = Poly3DCollection([list(zip(*m3(corners), strict=True))], alpha=0.25)
            poly.set_facecolor(OBSTACLE_COLOR)
            poly.set_edgecolor("0.3")
            ax.add_collection3d(poly)
            handles.append(Patch(facecolor=OBSTACLE_COLOR, alpha=0.4, edgecolor="0.3", label=label))
        else:
            low, high = np.array(shape.min_corner.as_tuple()), np.array(shape.max_corner.as_tuple())
            if dims == 2:
                ax.add_patch(
                    Rectangle(
                        (low[0], low[1]), high[0] - low[0], high[1] - low[1],
                        facecolor=OBSTACLE_COLOR, alpha=0.35, edgecolor="0.25", hatch="//",
                    )
                )  # fmt: skip
            else:
                for p, q in box_edges(low, high):
                    ax.plot(*m3(np.array([p, q])), color="0.25", lw=1.5)
            handles.append(Patch(facecolor=OBSTACLE_COLOR, alpha=0.35, edgecolor="0.25", label=label))
    return handles


def draw_shape(ax: Any, shape: Circle | Sphere | AABB, center: Array, dims: int, **style: Any) -> list[Any]:
    """A body's real shape at ``center``: a circle or rectangle patch in 2D, a wireframe sphere
    or box in 3D. ``style`` takes ``color``, ``alpha``, ``ls``, ``lw``, ``fill``. Returns the artists."""
    color = style.get("color", "k")
    alpha = style.get("alpha", 1.0)
    ls = style.get("ls", "-")
    lw = style.get("lw", 1.2)
    fill = style.get("fill", False)
    if dims == 2:
        if isinstance(shape, AABB):
            half = np.array(shape.half_size.as_tuple())
            patch: Any = Rectangle(
                (center[0] - half[0], center[1] - half[1]), 2 * half[0], 2 * half[1],
                edgecolor=color, facecolor=color if fill else "none", alpha=alpha, ls=ls, lw=lw,
            )  # fmt: skip
        else:
            patch = CirclePatch(
                (center[0], center[1]), shape.radius,
                edgecolor=color, facecolor=color if fill else "none", alpha=alpha, ls=ls, lw=lw,
            )  # fmt: skip
        ax.add_patch(patch)
        return [patch]
    if isinstance(shape, AABB):
        half = np.array(shape.half_size.as_tuple())
        return [
            ax.plot(*m3(np.array([p, q])), color=color, alpha=alpha, ls=ls, lw=lw)[0]
            for p, q in box_edges(center - half, center + half)
        ]
    x, y, z = sphere_mesh(center, shape.radius, 14, 8)
    if fill:
        return [ax.plot_surface(x, z, y, color=color, alpha=alpha, shade=True, linewidth=0)]
    return [ax.plot_wireframe(x, z, y, color=color, alpha=alpha, lw=lw * 0.5, ls=ls)]


def _draw_trajectories(ax: Any, run: RunArrays, keep: NDArray[np.int64], dims: int) -> list[Any]:
    handles: list[Any] = []
    shapes = {b.name: b.shape for b in run.scenario.bodies}
    for i, name in enumerate(run.names):
        color = body_color(i)
        path = run.positions[keep, i, :]
        if dims == 2:
            (line,) = ax.plot(path[:, 0], path[:, 1], color=color, lw=1.6, label=f"{name} path")
            ax.plot(path[0, 0], path[0, 1], "o", color=color, ms=4)
            ax.plot(path[-1, 0], path[-1, 1], "s", color=color, ms=4)
        else:
            (line,) = ax.plot(*m3(path), color=color, lw=1.6, label=f"{name} path")
            ax.plot(*m3(path[:1]), "o", color=color, ms=4)
            ax.plot(*m3(path[-1:]), "s", color=color, ms=4)
        shape = shapes[name]
        draw_shape(ax, shape, run.positions[0, i], dims, color=color, alpha=0.5, ls="--", lw=1.0)
        draw_shape(ax, shape, run.positions[-1, i], dims, color=color, alpha=0.9, lw=1.4)
        handles.append(line)
    handles.append(Line2D([], [], color="0.3", ls="--", lw=1, label="shape at start (o)"))
    handles.append(Line2D([], [], color="0.3", lw=1.4, label="shape at end (\u25a0)"))
    return handles


def _draw_events(ax: Any, run: RunArrays, dims: int) -> list[Any]:
    events = run.shown_events()
    if not events:
        return []
    points = np.array([e.point.as_tuple() for e in events])
    if dims == 2:
        ax.scatter(points[:, 0], points[:, 1], marker="X", s=70, color=EVENT_COLOR, edgecolor="k", lw=0.5, zorder=5)
    else:
        ax.scatter(*m3(points), marker="X", s=70, color=EVENT_COLOR, edgecolor="k", lw=0.5, depthshade=False)
    crowd = (0.06 if dims == 2 else 0.15) * run.bounds().span  # no label this close to another one
    keep = uncrowded(points, crowd)
    for event, p, shown in zip(events, points, keep, strict=True):
        if not shown:
            continue
        text = f"step {event.step}"
        if dims == 2:
            ax.annotate(
                text, (p[0], p[1]), xytext=(6, 6), textcoords="offset points", fontsize=8, color=EVENT_COLOR,
                bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": EVENT_COLOR, "alpha": 0.8}, zorder=6,
            )  # fmt: skip
        else:
            ax.text(*m3(p), f"  {text}", fontsize=8, color=EVENT_COLOR)
    label = f"collision ({len(run.record.events)}), labelled by step"
    if sum(keep) < len(run.record.events):
        label += f" ({sum(keep)} labelled)"
    return [Line2D([], [], marker="X", ls="", color=EVENT_COLOR, markeredgecolor="k", ms=8, label=label)]


def _event_lines(ax: Axes, run: RunArrays) -> None:
    for event in run.shown_events():
        ax.axvline(event.time, color=EVENT_COLOR, alpha=0.25, lw=0.8)


def _draw_energy(ax: Axes, run: RunArrays, keep: NDArray[np.int64]) -> None:
    t = run.times[keep]
    ke = run.kinetic_energy()[keep]
    pe = run.potential_energy()[keep]
    _event_lines(ax, run)
    ax.plot(t, ke, color="C0", lw=1.6, label="kinetic")
    if np.any(pe != 0.0):
        ax.plot(t, pe, color="C2", lw=1.2, label="potential (-m g\u00b7x)")
        ax.plot(t, ke + pe, color="k", lw=1.4, ls="--", label="total")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("energy (J)")
    ax.set_title("Energy", fontsize=11)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    ledger = run.record.ledger
    text = (
        f"ledger: E {ledger.energy_start:.4g} \u2192 {ledger.energy_end:.4g} J\n"
        f"collisions {ledger.collisions:+.3g}, integrator {ledger.integrator:+.3g},\n"
        f"push-apart {ledger.push_apart:+.3g}, residual {ledger.residual:+.2g} J"
    )
    ax.text(
        0.02, 0.04, text, transform=ax.transAxes, fontsize=7.5, va="bottom", family="monospace",
        bbox={"boxstyle": "round", "fc": "white", "ec": "0.7", "alpha": 0.85},
    )  # fmt: skip


def _draw_momentum(ax: Axes, run: RunArrays, keep: NDArray[np.int64], dims: int) -> None:
    t = run.times[keep]
    p = run.momentum()[keep]
    _event_lines(ax, run)
    for k, axis in enumerate("xyz"[:dims]):
        ax.plot(t, p[:, k], lw=1.4, color=f"C{k + 3}", label=f"p{axis}")
    ax.plot(t, np.linalg.norm(p, axis=1), color="k", lw=1.2, ls=":", label="|p|")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("momentum (kg\u00b7m/s)")
    ax.set_title("Momentum", fontsize=11)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best", ncols=2)


def draw_figure(record: DrawnRun, scenario: Scenario, size: tuple[int, int] = DEFAULT_SIZE) -> Figure:
    """The whole picture of a run as a matplotlib :class:`Figure` of ``size`` pixels (at 100 dpi),
    on its own Agg canvas (no pyplot, no display)."""
    run = RunArrays.build(record, scenario)
    dims = record.dims
    keep = thin_indices(len(run.times), MAX_POINTS, run.event_frames())
    fig = Figure(figsize=(size[0] / _DPI, size[1] / _DPI), dpi=_DPI)
    FigureCanvasAgg(fig)
    grid = fig.add_gridspec(2, 2, width_ratios=(1.35, 1.0), hspace=0.42, wspace=0.22,
                            left=0.06, right=0.97, top=0.88, bottom=0.09)  # fmt: skip
    if dims == 2:
        ax: Any = fig.add_subplot(grid[:, 0])
    else:
        ax = fig.add_subplot(grid[:, 0], projection="3d")
    bounds = run.bounds()
    handles = _draw_trajectories(ax, run, keep, dims)
    handles += draw_obstacles(ax, scenario, bounds, dims)
    handles += _draw_events(ax, run, dims)
    setup_view(ax, bounds, dims)
    ax.set_title("Trajectories" + (" (x-y plane)" if dims == 2 else " (3D, y up)"), fontsize=11)
    ax.legend(handles=handles, fontsize=8, loc="upper left", framealpha=0.85)
    _draw_energy(fig.add_subplot(grid[0, 1]), run, keep)
    _draw_momentum(fig.add_subplot(grid[1, 1]), run, keep, dims)
    end = run.times[-1]
    fig.suptitle(record.title, fontsize=15, fontweight="bold", y=0.975)
    fig.text(
        0.5, 0.925,
        f"{record.mode} mode, dt = {record.dt:g} s, {record.steps} steps ({end:g} s), e = {record.restitution:g}, "
        f"{len(record.events)} collision{'s' if len(record.events) != 1 else ''}",
        ha="center", fontsize=10, color="0.3",
    )  # fmt: skip
    return fig


def check_plot_path(path: str) -> Path:
    """``path`` if a plot can be written there, else ``InvalidInputError("--plot", ...)``."""
    return check_path(path, "--plot", (".png", ".svg", ".pdf"), "FILE.png (or .svg, .pdf) in an existing folder")


def save_plot(record: DrawnRun, scenario: Scenario, path: str, *, size: tuple[int, int] | None = None) -> None:
    """Save the picture of a run (see the module's docstring) to ``path``: ``.png`` (or ``.svg``,
    ``.pdf``), ``size`` = (width, height) pixels, default :data:`DEFAULT_SIZE`. The file is
    written whole or not at all. A bad path raises ``InvalidInputError("--plot", ...)``."""
    target = check_plot_path(path)
    width, height = _check_size(size or DEFAULT_SIZE, "--plot")
    fig = draw_figure(record, scenario, (width, height))
    with atomic_path(target) as tmp:
        fig.savefig(tmp, format=target.suffix.lower().lstrip("."), dpi=_DPI)


def _check_size(size: tuple[int, int], option: str) -> tuple[int, int]:
    from ..errors import InvalidInputError

    width, height = size
    if int(width) != width or int(height) != height or not (100 <= width <= 10000 and 100 <= height <= 10000):
        raise InvalidInputError(option, "size must be two whole numbers of pixels from 100 to 10000", got=size)
    return int(width), int(height)
