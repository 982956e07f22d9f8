"""Spreading balls apart: the start of a mixture too dense for a lattice.

A lattice whose sites are one largest diameter apart holds a mixture only up to a packing
fraction well below its fluid's range (a binary of radii 1 and 0.5, half of each by number, 3D:
0.42, where the fluid goes on past 0.5). Denser mixtures start from that lattice laid in the
box they must fill (its sites closer than the largest balls' diameter) and pushed apart: every
pair of balls ``i, j`` closer than ``(r_i + r_j)(1 + gap / 2)`` is moved apart along the line of
centres to ``(r_i + r_j)(1 + gap)``, each by half the way (the other half of the gap keeps a pair
just parted from being moved again by its rounding), one pair after the other (a projection, as
in position-based dynamics; Gauss-Seidel order, by the balls' numbers), until a sweep over every
pair moves nothing. That sweep proves the result: its pairs were found from the positions it
ends with. Walls keep each centre ``r_i (1 + gap / 2)`` from them (a centre nearer is put at
``r_i (1 + gap)``). The moves are deterministic (the same balls, box and order give the same
bits). The start is a packing, not an equilibrium: the run's first collisions take it there, as
they do the lattice.

It owns :func:`spread_apart`; it imports only the package's compile options and must not import
the world, the loop or the engine.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .compile import jit, jit_inline

__all__ = ["SPREAD_SWEEPS", "spread_apart"]

#: The most sweeps a start spreads its balls for before it is refused as too dense (a binary of
#: radii 1 and 0.5 at fraction 0.5 needs a few dozen; near jamming they grow without end).
SPREAD_SWEEPS = 2000


@jit
def spread_apart(x: Any, radii: Any, side: float, periodic: bool, gap: float, sweeps: int) -> int:
    """Move the centres ``x`` (``(n, dim)``, in ``[0, side]^dim``, changed in place) until no two
    balls are closer than ``(r_i + r_j)(1 + gap / 2)`` and (walls) no centre nearer a wall than
    ``r_i (1 + gap / 2)``; periodic centres are put back into ``[0, side)``. Returns the number of
    sweeps that moved something (0: nothing was too close), or -1 when ``sweeps`` were not enough.
    Coincident centres part along the first axis (the package's fallback normal).

    Two discs of radius 1 at distance 1 part by half a diameter each, to 2 (1 + gap):

    >>> import numpy as np
    >>> x = np.array([[4.5, 5.0], [5.5, 5.0]])
    >>> spread_apart(x, np.array([1.0, 1.0]), 10.0, True, 0.0, 100), x.tolist()
    (1, [[4.0, 5.0], [6.0, 5.0]])
    """
    n = x.shape[0]
    dim = x.shape[1]
    reach = 2.0 * radii.max() * (1.0 + gap)
    nc = max(1, int(side / reach))  # cells at least one largest pair distance wide
    if periodic and nc < 3:
        nc = 1  # fewer than 3 would visit a neighbour cell twice: one cell, every pair
    h = side / nc
    cells = nc**dim
    head = np.empty(cells, np.int64)
    after = np.empty(n, np.int64)
    home = np.empty((n, 3), np.int64)
    reach_out = 1 if nc > 1 else 0
    for sweep in range(sweeps + 1):
        head[:] = -1
        for i in range(n):
            cell = 0
            stride = 1
            for k in range(3):
                home[i, k] = 0
            for k in range(dim):
                if periodic:
                    xi = x[i, k] % side
                    x[i, k] = xi if xi < side else 0.0
                a = min(nc - 1, max(0, int(x[i, k] / h)))
                home[i, k] = a
                cell += a * stride
                stride *= nc
            after[i] = head[cell]
            head[cell] = i
        moved = False
        for i in range(n):
            for ox in range(-reach_out, reach_out + 1):
                for oy in range(-reach_out, reach_out + 1):
                    for oz in range(-reach_out if dim == 3 else 0, (reach_out if dim == 3 else 0) + 1):
                        cell = 0
                        stride = 1
                        outside = False
                        for k in range(dim):
                            a = home[i, k] + (ox if k == 0 else oy if k == 1 else oz)
                            if periodic:
                                a %= nc
                            elif a < 0 or a >= nc:
                                outside = True
                            cell += a * stride
                            stride *= nc
                        if outside:
                            continue
                        j = head[cell]
                        while j >= 0:
                            if j > i and _part(x, radii, i, j, side, periodic, gap):
                                moved = True
                            j = after[j]
            if not periodic:
                for k in range(dim):
                    near = radii[i] * (1.0 + 0.5 * gap)
                    if x[i, k] < near or x[i, k] > side - near:
                        low = radii[i] * (1.0 + gap)
                        x[i, k] = min(max(x[i, k], low), side - low)
                        moved = True
        if not moved:
            return sweep
    return -1


@jit_inline
def _part(x: Any, radii: Any, i: int, j: int, side: float, periodic: bool, gap: float) -> bool:
    """Move balls ``i`` and ``j`` apart to ``(r_i + r_j)(1 + gap)``, half the way each, if they
    are closer than ``(r_i + r_j)(1 + gap / 2)``; whether they were."""
    dim = x.shape[1]
    sigma = radii[i] + radii[j]
    near = sigma * (1.0 + 0.5 * gap)
    need = sigma * (1.0 + gap)
    d2 = 0.0
    for k in range(dim):
        d = x[j, k] - x[i, k]
        if periodic:
            d -= side * math.floor(d / side + 0.5)
        d2 += d * d
    if d2 >= near * near:
        return False
    dist = math.sqrt(d2)
    push = 0.5 * (need - dist)
    for k in range(dim):
        d = x[j, k] - x[i, k]
        if periodic:
            d -= side * math.floor(d / side + 0.5)
        u = d / dist if dist > 0.0 else (1.0 if k == 0 else 0.0)
        x[i, k] -= push * u
        x[j, k] += push * u
    return True
