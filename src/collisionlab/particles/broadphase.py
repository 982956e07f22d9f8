"""Broad phase of the particle world, as stateless queries: every overlapping pair of balls.

A uniform grid of cells at least one diameter (of the largest ball) wide, bodies sorted into it
by cell, and each cell checked against itself and half of its neighbours (4 of 8 in 2D, 13 of 26
in 3D) so that every unordered pair of cells is visited once (Ericson, *Real-Time Collision
Detection*, 7.1-7.1.3). A ball can only touch balls in its own or an adjacent cell, so the
search is complete; with a bounded number of bodies per cell it costs O(N).

Chosen over sort-and-sweep by measurement and by its scaling: sweeping along one axis of a square
box of N balls at a fixed area fraction keeps O(sqrt N) candidates per ball in the sweep window,
O(N^1.5) in all (the figures are in ``bench/README.md``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..engine import pair_separation
from ..engine.stepper import CELLS_PER_BODY, max_cells, stencil
from ..errors import InvalidInputError
from .backend import engine_kernels, pick_backend

__all__ = ["CELLS_PER_BODY", "brute_force_pairs", "grid_pairs", "half_stencil", "max_cells"]

# The grid's geometry is the engine's (one stepper, one grid).
half_stencil = stencil


def _as_balls(positions: object, radii: object) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    pos = np.ascontiguousarray(positions, dtype=np.float64)
    if pos.ndim != 2 or pos.shape[1] not in (2, 3) or pos.shape[0] == 0:
        raise InvalidInputError("positions", "must be an array of shape (n, 2) or (n, 3), n >= 1", got=pos.shape)
    if not np.all(np.isfinite(pos)):
        raise InvalidInputError("positions", "must be finite numbers")
    rad = np.ascontiguousarray(np.broadcast_to(np.asarray(radii, dtype=np.float64), pos.shape[:1]))
    if not np.all(np.isfinite(rad)) or not np.all(rad > 0.0):
        raise InvalidInputError("radii", "must be finite numbers > 0")
    return pos, rad


def _sorted_pairs(pairs: NDArray[np.int64]) -> NDArray[np.int64]:
    pairs = pairs.reshape(-1, 2)
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


def grid_pairs(positions: object, radii: object, *, backend: str = "auto") -> NDArray[np.int64]:
    """Every pair ``(i, j)``, ``i < j``, of balls with ``|x_j - x_i| <= r_i + r_j`` (touching
    counts), found by the grid; rows sorted. ``radii`` is one number or one per ball.

    >>> grid_pairs([[0, 0], [2, 0], [5, 0], [6.5, 0]], 1.0).tolist()
    [[0, 1], [2, 3]]
    """
    pos, rad = _as_balls(positions, radii)
    n, dim = pos.shape
    kind = np.full(n, pair_separation.BALL_2D if dim == 2 else pair_separation.BALL_3D, np.int64)
    pos3 = np.zeros((n, 3))
    pos3[:, :dim] = pos
    ext = np.repeat(rad[:, None], 3, axis=1)
    no_statics = np.zeros((0, 3))
    kernels = engine_kernels(pick_backend(backend))
    pairs, _ = kernels.find_near(
        kind,
        pos3,
        ext,
        np.arange(n, dtype=np.int64),
        np.zeros(0, np.int64),
        no_statics,
        no_statics,
        half_stencil(dim),
        dim,
        2.0 * float(rad.max()),
        max_cells(n),
        0.0,
    )
    pairs = np.sort(np.asarray(pairs, np.int64), axis=1)
    return _sorted_pairs(np.asarray(pairs, np.int64))


def brute_force_pairs(positions: object, radii: object) -> NDArray[np.int64]:
    """The same pairs by checking all ``N (N - 1) / 2`` of them: the reference for tests.

    >>> brute_force_pairs([[0, 0, 0], [0, 0, 2], [0, 0, 4.1]], 1.0).tolist()
    [[0, 1]]
    """
    pos, rad = _as_balls(positions, radii)
    found = []
    for i in range(pos.shape[0] - 1):
        delta = pos[i + 1 :] - pos[i]
        d2 = delta[:, 0] * delta[:, 0]
        for k in range(1, pos.shape[1]):
            d2 = d2 + delta[:, k] * delta[:, k]
        hit = np.flatnonzero(np.sqrt(d2) <= rad[i] + rad[i + 1 :]) + i + 1
        found.append(np.stack([np.full(hit.shape[0], i), hit], axis=1))
    if not found:
        return np.empty((0, 2), np.int64)
    return _sorted_pairs(np.concatenate(found).astype(np.int64))
