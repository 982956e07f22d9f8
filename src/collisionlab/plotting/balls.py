"""The event-driven gas's picture (``collisionlab gas --mode exact --plot FILE``): the balls of
the last frame, drawn to scale in their box and coloured by species, beside each species' speeds
against the Maxwell-Boltzmann distribution at that species' own temperature (equipartition: the
same ``kT`` for every species, so ``kT/m`` differs by the mass). PNG, SVG or PDF as matplotlib
writes them; a GIF is the same picture as one frame, converted by Pillow (matplotlib's own
dependency). A 3D box is drawn in perspective, each ball a point of its size; more than
:data:`MOST_DRAWN` balls are drawn as a fixed random choice of that many (the title says so),
so that a million balls make a picture in seconds.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..atomic import atomic_path
from ..particles import speed_pdf
from ._data import check_path
from .static import body_color

__all__ = ["MOST_DRAWN", "check_balls_plot_path", "draw_balls", "save_balls_plot"]

#: The most balls drawn in the picture of the box (the speeds panel uses every ball).
MOST_DRAWN = 20_000

_SUFFIXES = (".png", ".svg", ".pdf", ".gif")
_FORM = "FILE.png (or .svg, .pdf, .gif) in an existing folder"


def check_balls_plot_path(path: str) -> Path:
    """``path`` if the picture can be written there, else ``InvalidInputError("--plot", ...)``."""
    return check_path(path, "--plot", _SUFFIXES, _FORM)


def save_balls_plot(
    path: str,
    positions: NDArray[np.float64],
    velocities: NDArray[np.float64],
    radii: NDArray[np.float64],
    kinds: NDArray[np.int64],
    names: tuple[str, ...],
    sides: tuple[float, ...],
    title: str,
) -> None:
    """Write the picture of balls at ``positions`` with ``velocities`` (``(n, dim)``), ``radii``
    and species ``kinds`` (indices into ``names``) in the box ``[0, sides]`` to ``path``, whole
    or not at all."""
    target = check_balls_plot_path(path)
    figure = draw_balls(positions, velocities, radii, kinds, names, sides, title)
    with atomic_path(target) as temporary:
        if target.suffix.lower() == ".gif":
            from PIL import Image

            png = io.BytesIO()
            figure.savefig(png, format="png")
            png.seek(0)
            with Image.open(png) as image:
                image.convert("RGB").convert("P", palette=Image.Palette.ADAPTIVE).save(temporary, format="GIF")
        else:
            figure.savefig(temporary, format=target.suffix.lower().lstrip("."))


def draw_balls(
    positions: NDArray[np.float64],
    velocities: NDArray[np.float64],
    radii: NDArray[np.float64],
    kinds: NDArray[np.int64],
    names: tuple[str, ...],
    sides: tuple[float, ...],
    title: str,
) -> Any:
    """The figure :func:`save_balls_plot` writes (a matplotlib ``Figure``): the box with its
    balls on the left (each ball the colour of its species, ``C0``, ``C1``, ... in the order of
    ``names``), the speeds on the right."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    dim = positions.shape[1]
    figure = Figure(figsize=(12, 5.5), dpi=100)
    FigureCanvasAgg(figure)
    shown = _drawn(len(positions))
    if dim == 3:
        box = figure.add_subplot(1, 2, 1, projection="3d")
        _draw_3d(box, positions[shown], radii[shown], kinds[shown], sides)
    else:
        box = figure.add_subplot(1, 2, 1)
        _draw_2d(box, positions[shown], radii[shown], kinds[shown], sides)
    drawn = "" if len(shown) == len(positions) else f" ({len(shown):,} of {len(positions):,} drawn)"
    box.set_title(f"the last frame{drawn}")
    _speeds(figure.add_subplot(1, 2, 2), velocities, kinds, names)
    handles = _legend(names, kinds, radii)
    box.legend(handles=handles, loc="upper right", fontsize=8, framealpha=0.85)
    figure.suptitle(title)
    figure.tight_layout()
    return figure


def _drawn(n: int) -> NDArray[np.int64]:
    """The balls drawn: all, or :data:`MOST_DRAWN` of them chosen at random (the same every time)."""
    if n <= MOST_DRAWN:
        return np.arange(n)
    return np.sort(np.random.default_rng(0).choice(n, MOST_DRAWN, replace=False))


def _draw_2d(axes: Any, positions: NDArray[np.float64], radii: NDArray[np.float64], kinds: NDArray[np.int64],
             sides: tuple[float, ...]) -> None:  # fmt: skip
    from matplotlib.collections import EllipseCollection
    from matplotlib.patches import Rectangle

    colours = [body_color(int(k)) for k in kinds]
    discs = EllipseCollection(
        2.0 * radii, 2.0 * radii, np.zeros(len(radii)), units="xy", offsets=positions,
        offset_transform=axes.transData, facecolors=colours, edgecolors="0.2", linewidths=0.3, alpha=0.85,
    )  # fmt: skip
    axes.add_collection(discs)
    axes.add_patch(Rectangle((0.0, 0.0), sides[0], sides[1], fill=False, edgecolor="0.3", lw=1.2))
    margin = 0.02 * max(sides[0], sides[1])
    axes.set_xlim(-margin, sides[0] + margin)
    axes.set_ylim(-margin, sides[1] + margin)
    axes.set_aspect("equal")
    axes.set_xlabel("x")
    axes.set_ylabel("y")


def _draw_3d(axes: Any, positions: NDArray[np.float64], radii: NDArray[np.float64], kinds: NDArray[np.int64],
             sides: tuple[float, ...]) -> None:  # fmt: skip
    colours = [body_color(int(k)) for k in kinds]
    # A ball of diameter 2r as a marker of 2r / side of the box's drawn width (about 200 points
    # across, in perspective): an area in points^2, a little small so that the inside shows.
    size = (2.0 * radii / max(sides) * 200.0) ** 2
    axes.scatter(positions[:, 0], positions[:, 1], positions[:, 2], s=size, c=colours, alpha=0.5, linewidths=0)
    for x in (0.0, sides[0]):
        for y in (0.0, sides[1]):
            axes.plot([x, x], [y, y], [0.0, sides[2]], color="0.3", lw=0.8)
    for x in (0.0, sides[0]):
        for z in (0.0, sides[2]):
            axes.plot([x, x], [0.0, sides[1]], [z, z], color="0.3", lw=0.8)
    for y in (0.0, sides[1]):
        for z in (0.0, sides[2]):
            axes.plot([0.0, sides[0]], [y, y], [z, z], color="0.3", lw=0.8)
    axes.set_xlim(0.0, sides[0])
    axes.set_ylim(0.0, sides[1])
    axes.set_zlim(0.0, sides[2])
    axes.set_box_aspect(sides[:3])
    axes.set_xlabel("x")
    axes.set_ylabel("y")
    axes.set_zlabel("z")


def _speeds(axes: Any, velocities: NDArray[np.float64], kinds: NDArray[np.int64], names: tuple[str, ...]) -> None:
    """Each species' speeds (a histogram) and Maxwell-Boltzmann at its own ``kT/m``."""
    dim = velocities.shape[1]
    speeds = np.sqrt(np.sum(velocities**2, axis=1))
    top = float(speeds.max()) if len(speeds) else 1.0
    bins = np.linspace(0.0, top if top > 0.0 else 1.0, 50)
    curve = np.linspace(0.0, bins[-1], 300)
    for k, name in enumerate(names):
        mine = kinds == k
        if not mine.any():
            continue
        variance = float(np.mean(np.sum(velocities[mine] ** 2, axis=1)) / dim)
        colour = body_color(k)
        axes.hist(speeds[mine], bins=bins, density=True, alpha=0.45, color=colour, label=f"{name}: speeds")
        if variance > 0.0:
            axes.plot(curve, speed_pdf(curve, dim, variance), color=colour, lw=2,
                      label=f"{name}: Maxwell-Boltzmann, kT/m = {variance:.3g}")  # fmt: skip
    axes.set_xlabel("speed")
    axes.set_ylabel("probability density")
    axes.set_title("speeds at the end")
    axes.legend(fontsize=8)


def _legend(names: tuple[str, ...], kinds: NDArray[np.int64], radii: NDArray[np.float64]) -> list[Any]:
    """A patch per species: its name, how many balls, their radius."""
    from matplotlib.patches import Patch

    handles = []
    for k, name in enumerate(names):
        mine = kinds == k
        count = int(mine.sum())
        radius = float(radii[mine][0]) if count else 0.0
        label = f"{name}: {count:,} balls, r = {radius:g}"
        handles.append(Patch(facecolor=body_color(k), edgecolor="0.2", label=label))
    return handles
