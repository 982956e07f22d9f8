"""Starting states: bodies on a lattice at a given packing fraction, seeded Gaussian velocities.

The box side ``L`` makes the packing fraction ``phi``: ``N pi r^2 = phi L^2`` (2D),
``N 4/3 pi r^3 = phi L^3`` (3D). Sites are those of a grid of ``2k`` points per axis whose
coordinate indices sum to an even number: face-centred cubic in 3D (as the reference code
starts), a square lattice turned 45 degrees in 2D; ``k`` is the smallest with enough sites,
and ``N`` of them are drawn at random (seeded) when there are more. With periodic walls the
grid spans the box evenly; with hard walls it spans the room the centres have, ``[r, L - r]``.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidInputError
from ..particles.scenarios import ball_volume

__all__ = ["box_side", "gaussian_velocities", "lattice", "lattice_sites"]


def box_side(n: int, dim: int, fraction: float, radius: float) -> float:
    """The side of the square (cubic) box holding ``n`` balls at packing ``fraction``.

    >>> round(box_side(4000, 3, 0.25, 0.5), 6)   # the reference's 4,000 spheres, sigma = 1: (4000 pi/6 / 0.25)^(1/3)
    20.309826
    """
    return float((n * ball_volume(radius, dim) / fraction) ** (1.0 / dim))


def lattice(n: int, dim: int, fraction: float, radius: float, periodic: bool, seed: int) -> NDArray[np.float64]:
    """``n`` non-overlapping centres in ``[0, L]^dim`` (``L = box_side(...)``), shape ``(n, dim)``.

    Raises :class:`InvalidInputError` (field ``fraction``) when the lattice would overlap.
    """
    side = box_side(n, dim, fraction, radius)
    coords, spacing = lattice_sites(n, dim, side, radius, periodic, seed)
    nearest = spacing * math.sqrt(2.0)
    if nearest <= 2.0 * radius or (periodic and side < 8.0 * radius):
        raise InvalidInputError(
            "fraction",
            f"too dense to start {n:,} balls on a lattice in {'a periodic box' if periodic else 'walls'}"
            + (" (a periodic box must be at least 4 diameters wide: more balls)" if periodic else ""),
            got=fraction,
        )
    return coords


def lattice_sites(
    n: int, dim: int, side: float, radius: float, periodic: bool, seed: int
) -> tuple[NDArray[np.float64], float]:
    """``n`` sites of the lattice (see the module's docstring) in the box ``[0, side]^dim``, for
    centres of balls of ``radius`` (the room they have within walls), and the grid's spacing.
    Nothing is checked: the sites may be closer than a diameter."""
    k = 1
    while (2 * k) ** dim // 2 < n:
        k += 1
    m = 2 * k
    grid = np.indices((m,) * dim).reshape(dim, -1).T
    sites = grid[grid.sum(axis=1) % 2 == 0]
    if periodic:
        spacing = side / m
        coords = (sites + 0.5) * spacing
    else:
        spacing = (side - 2.0 * radius) / (m - 1) if m > 1 else side
        coords = np.minimum(radius + sites * spacing, side - radius)  # the last site exactly, not past it
    if len(coords) > n:
        chosen = np.sort(np.random.default_rng(seed).choice(len(coords), size=n, replace=False))
        coords = coords[chosen]
    return np.ascontiguousarray(coords, dtype=np.float64), float(spacing)


def gaussian_velocities(n: int, dim: int, kt: float, mass: float, seed: int) -> NDArray[np.float64]:
    """Seeded Gaussian velocities with zero total momentum, scaled so that the kinetic energy is
    exactly ``dim N kT / 2`` (equipartition).

    >>> v = gaussian_velocities(1000, 3, 2.0, 1.0, 0)
    >>> round(float(0.5 * (v ** 2).sum() / (1.5 * 1000)), 12), bool(abs(v.sum(axis=0)).max() < 1e-9)
    (2.0, True)
    """
    rng = np.random.default_rng(seed)
    v = rng.normal(0.0, 1.0, size=(n, dim))
    if n > 1:
        v -= v.mean(axis=0)
    energy = 0.5 * mass * float((v * v).sum())
    if energy > 0.0:
        v *= math.sqrt(0.5 * dim * n * kt / energy)
    return v
