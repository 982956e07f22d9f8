"""The gas's picture: the distribution of speeds against the Maxwell-Boltzmann curve.

Kinetic theory out of collisions: balls that start at one speed (or any distribution) relax,
through elastic collisions alone, to the Maxwell-Boltzmann distribution at the temperature set
by their kinetic energy (``kT/m`` = the variance of one velocity component).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..atomic import atomic_path
from ..particles import component_variance, speed_pdf
from .static import check_plot_path

__all__ = ["save_speed_plot"]


def save_speed_plot(
    path: str, start: np.ndarray[Any, Any], end: np.ndarray[Any, Any], restitution: float, steps: int
) -> None:
    """Histograms of the speeds at the start and at the end, and Maxwell-Boltzmann at the end's
    temperature; written atomically (never half-written). ``start`` and ``end`` are the
    velocities ``(n, dim)`` at the start and at the end, ``steps`` apart."""
    check_plot_path(path)
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    dim = int(end.shape[1])
    speeds_end = np.sqrt(np.sum(end**2, axis=1))
    speeds_start = np.sqrt(np.sum(start**2, axis=1))
    top = float(max(speeds_end.max(), speeds_start.max()))
    bins = np.linspace(0.0, top, 60).tolist()
    curve_v = np.linspace(0.0, top, 400)
    variance = component_variance(end)
    figure = Figure(figsize=(8, 5), dpi=100)
    FigureCanvasAgg(figure)
    axes = figure.add_subplot()
    axes.hist(speeds_start, bins=bins, density=True, histtype="step", color="0.6", label="speeds at the start")
    axes.hist(
        speeds_end,
        bins=bins,
        density=True,
        alpha=0.6,
        color="tab:blue",
        label=f"speeds after {steps} steps",
    )
    axes.plot(
        curve_v,
        speed_pdf(curve_v, dim, variance),
        color="tab:red",
        lw=2,
        label=f"Maxwell-Boltzmann, kT/m = {variance:.3g}",
    )
    # An equal-speed start is a spike that would flatten everything else: clip it, say so.
    ceiling = 1.5 * float(
        max(np.histogram(speeds_end, bins=bins, density=True)[0].max(), speed_pdf(curve_v, dim, variance).max())
    )
    if np.histogram(speeds_start, bins=bins, density=True)[0].max() > ceiling:
        axes.set_ylim(0.0, ceiling)
        axes.annotate(
            "start: off scale",
            xy=(float(np.median(speeds_start)), ceiling),
            xytext=(6, -14),
            textcoords="offset points",
            ha="left",
            color="0.4",
        )
    axes.set_xlabel("speed (radii per time unit)")
    axes.set_ylabel("probability density")
    shape = "discs" if dim == 2 else "spheres"
    axes.set_title(f"{len(end):,} {shape} in {dim}D, e = {restitution:g}")
    axes.legend()
    with atomic_path(path) as temporary:
        figure.savefig(temporary, format="png")
