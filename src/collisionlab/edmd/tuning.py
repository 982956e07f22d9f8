"""The event-driven world's tunables: the neighbour lists' reach, the calendar's blocks and
horizon, the cells' slots and the streamed blocks' size, each fitted or measured where its
comment says (bench/bench_edmd.py). Plain Python, read when a world is made: a change here
compiles nothing again. :func:`list_reach` and :func:`cell_counts` apply them to a world's
balls and box."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "BUFFER_EVENTS",
    "CELL_SLOTS",
    "EVENTS_PER_BLOCK",
    "HORIZON",
    "MIXED_REACH_2D",
    "SHELL",
    "SHELL_AT_QUARTER",
    "SHELL_EXPONENT",
    "SHELL_MAX",
    "SHELL_MIN",
    "cell_counts",
    "list_reach",
    "shell_for",
]

#: Neighbour-list reach in diameters (Smallenburg's ``1 + alpha``; he uses 1.5) in 2D and under
#: gravity (where the mean density says little about a pile's).
SHELL = 1.7
#: In 3D without gravity the reach follows the packing fraction: a wider shell means fewer list
#: rebuilds but more neighbours to test at every prediction, and the balance moves to narrower
#: shells as the fluid gets denser. ``SHELL_AT_QUARTER * (fraction / 0.25) ** -SHELL_EXPONENT``,
#: within ``[SHELL_MIN, SHELL_MAX]``, was fitted to the fastest shells of bench/bench_edmd.py.
#: ``SHELL_MAX`` keeps the reach within half of the smallest periodic box (4 diameters).
SHELL_AT_QUARTER = 2.0
SHELL_EXPONENT = 0.38
SHELL_MIN = 1.4
SHELL_MAX = 2.0
#: A gas of discs of several sizes (no gravity) lists neighbours at least this many mean
#: diameters beyond its largest contact distance (fitted in bench/bench_edmd.py --mixtures).
MIXED_REACH_2D = 1.2
#: Calendar: scheduled events per block of the near-future heap, and how many typical event
#: times the ring of lists covers before the overflow list (tuned in bench/bench_edmd.py).
EVENTS_PER_BLOCK = 8.0
HORIZON = 4.0
#: Slots of a cell's row (its count and up to 15 bodies, 256 bytes): doubled when one fills.
CELL_SLOTS = 16
#: Events held before a streamed block is handed to the sink.
BUFFER_EVENTS = 1 << 16


def shell_for(dim: int, fraction: float, gravity: float) -> float:
    """The neighbour-list reach in diameters for a box of packing ``fraction`` (see ``SHELL``).

    >>> shell_for(3, 0.25, 0.0), shell_for(2, 0.25, 0.0), shell_for(3, 0.05, 0.0)
    (2.0, 1.7, 2.0)
    """
    if dim != 3 or gravity > 0.0:
        return SHELL
    if fraction <= 0.0:
        return SHELL_MAX
    return min(SHELL_MAX, max(SHELL_MIN, SHELL_AT_QUARTER * float((fraction / 0.25) ** -SHELL_EXPONENT)))


def list_reach(
    radii: NDArray[np.float64], dim: int, box: NDArray[np.float64], gravity: float
) -> tuple[float, float, float]:
    """The neighbour lists of balls of ``radii`` in a box of sides ``box``: ``(shell, sigma, cut)``,
    the reach in diameters (:func:`shell_for`), the largest contact distance (the sum of the two
    largest radii; one ball: 2 r) and the distance within which a ball lists its neighbours.

    One kind of ball lists neighbours within ``shell * sigma``. A mixture lists them within
    ``shell`` times its mean diameter (by number: most pairs are of the typical size), and at
    least ``SHELL_MIN - 1`` mean diameters beyond its largest contact distance; each body's skin
    is then ``cut / 2 - r_i`` (see :func:`.schedule.predict_next`), the small balls' the larger
    (``shell * sigma`` would have the small balls list many neighbours they never meet:
    bench/bench_edmd.py --mixtures). Discs of a mixture without gravity rebuild their lists far
    more often than spheres, so they reach ``MIXED_REACH_2D`` mean diameters beyond at least,
    at most 2 sigma (half the narrowest periodic box; bench/LOG.md).

    >>> list_reach(np.full(10, 0.5), 3, np.array([10.0, 10.0, 10.0]), 0.0)  # fraction 0.005: SHELL_MAX
    (2.0, 1.0, 2.0)
    >>> # discs, radii 1, 0.5, 0.5: sigma 1 + 0.5, mean diameter 4/3; 1.7 x 4/3 = 2.27 and
    >>> # 1.5 + 0.4 x 4/3 = 2.03 give 2.27; the discs' 1.5 + 1.2 x 4/3 = 3.1, at most 2 x 1.5
    >>> list_reach(np.array([1.0, 0.5, 0.5]), 2, np.array([20.0, 20.0]), 0.0)
    (1.7, 1.5, 3.0)
    """
    n = len(radii)
    radius = float(radii.max())
    mixed = bool(radii.min() != radii.max())
    top = np.sort(radii)[-2:] if n > 1 else np.array([radius, radius])
    sigma = 2.0 * radius if not mixed else float(top[0] + top[1])
    if mixed:
        volume = float(np.sum(math.pi * radii**2 if dim == 2 else 4.0 / 3.0 * math.pi * radii**3))
    else:
        ball = math.pi * radius**2 if dim == 2 else 4.0 / 3.0 * math.pi * radius**3
        volume = n * ball
    shell = shell_for(dim, volume / float(np.prod(box)), gravity)
    if not mixed:
        return shell, sigma, shell * sigma
    mean_sigma = 2.0 * float(radii.mean())
    cut = max(shell * mean_sigma, sigma + (SHELL_MIN - 1.0) * mean_sigma)
    if dim == 2 and gravity == 0.0:
        cut = min(2.0 * sigma, max(cut, sigma + MIXED_REACH_2D * mean_sigma))
    return shell, sigma, cut


def cell_counts(box: NDArray[np.float64], cut: float, n: int) -> NDArray[np.int64]:
    """Cells per axis for ``n`` balls listing neighbours within ``cut`` in a box of sides
    ``box``: cells at least one reach wide, and no more than about one per 2 bodies (a sparse
    box): each cell's row holds room for ``CELL_SLOTS - 1`` bodies, 256 bytes, 128 bytes a body
    at most.

    >>> cell_counts(np.array([10.0, 10.0]), 1.7, 1000).tolist()  # 10 / 1.7 = 5.9: 5 a side
    [5, 5]
    >>> # 100 balls: at most 100 // 2 + 27 = 77 cells; 58 a side shrinks by 0.8 (46, 36, 28, 22,
    >>> # 17, 13, 10) to 8: 64 cells
    >>> cell_counts(np.array([100.0, 100.0]), 1.7, 100).tolist()
    [8, 8]
    """
    cells = np.maximum(1, np.floor(box / cut)).astype(np.int64)
    while int(np.prod(cells)) > n // 2 + 27 and np.any(cells > 1):
        cells = np.maximum(1, (cells * 0.8).astype(np.int64))
    return cells
