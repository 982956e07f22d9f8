"""Many bodies from one table: a scenario file's ``[[gas]]`` places ``count`` bodies without
overlap in a region, with seeded velocities, so a gas is just a scenario.

Keys (README, "Scenario files"): ``name`` (the bodies are ``name0``, ``name1``, ...), ``shape``
(``circle``, ``sphere`` or ``aabb``), ``radius`` or ``size``, ``region`` (two opposite corners),
``count`` or ``fraction`` (of the region's area or volume the bodies fill), ``mass``, ``kT``
(velocities drawn from Maxwell-Boltzmann: each component Gaussian with variance ``kT / m``) or
``velocity`` (all the same), ``restitution`` and ``seed``.

Placement: the sites of a square (cubic) lattice whose spacing is the body's width plus a gap of
1% of it, fitted inside the region, taken in a seeded random order; a count the lattice cannot
hold is refused, naming the field. So no two bodies of one table ever overlap.

>>> spec = GasSpec("g", "circle", (0.5, 0.5, 0.5), ((0, 0, 0), (10, 10, 0)), 3, 2.0, 1.0, None, None, 7)
>>> bodies = place_gas(spec)
>>> [b.name for b in bodies], bodies[0].shape.radius, bodies[0].mass
(['g0', 'g1', 'g2'], 0.5, 2.0)
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np

from .body_block import BodyBlock
from .errors import InvalidInputError
from .gas_spec import GasSpec  # its own file, so that body_block can name it without importing this one

__all__ = ["GasSpec", "gas_count", "place_gas"]

#: The gap between neighbouring lattice sites, as a fraction of the body's width (dimensionless):
#: enough that rounding never makes two placed bodies touch.
_SITE_GAP = 0.01


def _sites_per_axis(spec: GasSpec) -> list[int]:
    low, high = spec.region
    counts = []
    for k in range(spec.dims):
        width = 2.0 * spec.half[k]
        spacing = width * (1.0 + _SITE_GAP)
        room = high[k] - low[k] - width
        counts.append(0 if room < 0.0 else int(room // spacing) + 1)
    return counts


def gas_count(shape: str, half: tuple[float, float, float], region_size: tuple[float, ...], fraction: float) -> int:
    """How many bodies fill ``fraction`` of the region's area (2D) or volume (3D).

    >>> gas_count("circle", (1.0, 1.0, 1.0), (10.0, 10.0), 0.314159)   # 0.314159 * 100 / pi
    10
    """
    dims = len(region_size)
    room = math.prod(region_size)
    if shape == "aabb":
        body = math.prod(2.0 * h for h in half[:dims])
    elif dims == 2:
        body = math.pi * half[0] ** 2
    else:
        body = 4.0 / 3.0 * math.pi * half[0] ** 3
    return round(fraction * room / body)


def place_gas(spec: GasSpec, field: str = "gas") -> BodyBlock:
    """The table's bodies, placed on the lattice's sites in a seeded random order: one block of
    arrays (no :class:`~collisionlab.model.Body` is built until one is read)."""
    counts = _sites_per_axis(spec)
    capacity = math.prod(counts)
    if spec.count > capacity:
        raise InvalidInputError(
            f"{field}.count",
            f"the region holds at most {capacity} such bodies without overlap; enlarge region or lower count",
            got=spec.count,
        )
    rng = np.random.default_rng(spec.seed)
    chosen = np.sort(rng.permutation(capacity)[: spec.count]) if spec.count < capacity else np.arange(capacity)
    low, high = spec.region
    dims = spec.dims
    # Each axis's sites, centred in the region so the leftover room is split evenly.
    axes = []
    for k in range(dims):
        width = 2.0 * spec.half[k]
        spacing = width * (1.0 + _SITE_GAP)
        used = (counts[k] - 1) * spacing + width
        start = low[k] + (high[k] - low[k] - used) / 2.0 + spec.half[k]
        axes.append(start + spacing * np.arange(counts[k]))
    index = np.unravel_index(chosen, counts)
    centres = np.zeros((spec.count, 3))
    for k in range(dims):
        centres[:, k] = axes[k][index[k]]
    if spec.kT is not None:
        velocities = np.zeros((spec.count, 3))
        velocities[:, :dims] = rng.normal(0.0, math.sqrt(spec.kT / spec.mass), (spec.count, dims))
    else:
        velocities = np.tile(np.array(spec.velocity or (0.0, 0.0, 0.0)), (spec.count, 1))
    shape: Literal["circle", "sphere", "aabb"] = spec.shape  # type: ignore[assignment]
    return BodyBlock(spec.name, shape, spec.half, centres, velocities, spec.mass, spec.restitution, spec)
