"""The gas scenario shared by ``collisionlab gas`` and the benchmark.

N equal balls of radius ``r`` start on a square (cubic) lattice filling a box whose side ``L``
makes the area (volume) fraction ``phi``: ``N * pi r^2 = phi L^2`` in 2D, ``N * 4/3 pi r^3 =
phi L^3`` in 3D. Velocities are seeded Gaussian, each component of standard deviation 1, with
the mean removed so the box frame is the rest frame; ``dt`` makes the root-mean-square speed
cover ``step_fraction * r`` per step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from .. import limits
from ..errors import InvalidInputError
from ..model import BodyBlock, Box, Scenario, Settings
from ..validate import positive, whole_number
from ..vector import Vector3D
from .world import ParticleWorld

__all__ = ["SPEED_DISTRIBUTIONS", "GasScenario", "ball_volume", "gas_scenario"]

#: ``"gaussian"``: Maxwell-Boltzmann from the start; ``"equal"``: every body at the same speed
#: in a random direction, far from equilibrium (the collisions relax it to Maxwell-Boltzmann).
SPEED_DISTRIBUTIONS: tuple[str, ...] = ("gaussian", "equal")


def ball_volume(radius: float, dim: int) -> float:
    """Area of a disc (``dim = 2``) or volume of a ball (``dim = 3``).

    >>> round(ball_volume(1.0, 2), 6), round(ball_volume(1.0, 3), 6)
    (3.141593, 4.18879)
    """
    return math.pi * radius**2 if dim == 2 else 4.0 / 3.0 * math.pi * radius**3


@dataclass(frozen=True)
class GasScenario:
    """A ready-to-run gas: the box is ``[0, side]^dim``; arrays have one row per body."""

    positions: NDArray[np.float64]
    velocities: NDArray[np.float64]
    radius: float
    side: float
    dt: float
    seed: int

    @property
    def n(self) -> int:
        return int(self.positions.shape[0])

    @property
    def dim(self) -> int:
        return int(self.positions.shape[1])

    def scenario(self, steps: int, restitution: float = 1.0, gravity: float = 0.0) -> Scenario:
        """The gas as a scenario for the engine's world (Forward Euler, ``dt``): the balls as one
        block named ``ball`` (unit masses), in a box of walls ``[0, side]``; ``gravity`` pulls
        along -y. What ``collisionlab gas`` runs.

        >>> gas_scenario(100, 2, seed=1).scenario(10).box.sides == (gas_scenario(100, 2).side,) * 2
        True
        """
        shape: Literal["circle", "sphere"] = "circle" if self.dim == 2 else "sphere"
        block = BodyBlock("ball", shape, (self.radius,) * 3, self.positions, self.velocities)
        settings = Settings(dt=self.dt, steps=steps, restitution=restitution, gravity=Vector3D(0.0, -gravity, 0.0))
        box = Box((0.0,) * self.dim, (self.side,) * self.dim, "walls")
        return Scenario(settings, [block], title=f"gas of {self.n:,} {shape}s", box=box)

    def world(self, restitution: float = 1.0, gravity: float = 0.0, backend: str = "auto") -> ParticleWorld:
        """The scenario as a :class:`ParticleWorld` (unit masses; ``gravity`` pulls along -y)."""
        g = [0.0, -float(gravity), 0.0][: self.dim]
        box = ([0.0] * self.dim, [self.side] * self.dim)
        return ParticleWorld(
            self.positions,
            self.velocities,
            self.radius,
            1.0,
            box=box,
            restitution=restitution,
            gravity=g,
            backend=backend,
        )


def gas_scenario(
    n: int,
    dim: int = 2,
    seed: int = 0,
    *,
    radius: float = 1.0,
    fraction: float = 0.2,
    step_fraction: float = 0.1,
    speeds: str = "gaussian",
) -> GasScenario:
    """The benchmark's gas: see the module docstring.

    >>> gas = gas_scenario(1000, 2, seed=1)
    >>> round(gas.side, 3)                       # sqrt(1000 * pi / 0.2)
    125.331
    >>> bool(abs(np.sqrt((gas.velocities**2).sum(1).mean()) * gas.dt - 0.1) < 1e-12)
    True
    """
    n = limits.gas_balls(n, "n")
    dim = whole_number(dim, "dim")
    if dim not in (2, 3):
        raise InvalidInputError("dim", "must be 2 or 3", got=dim)
    seed = whole_number(seed, "seed", minimum=0)
    radius = positive(radius, "radius")
    fraction = positive(fraction, "fraction")
    step_fraction = positive(step_fraction, "step_fraction")
    if speeds not in SPEED_DISTRIBUTIONS:
        raise InvalidInputError("speeds", f"must be one of {', '.join(SPEED_DISTRIBUTIONS)}", got=speeds)
    side = (n * ball_volume(radius, dim) / fraction) ** (1.0 / dim)
    per_row = max(1, round(n ** (1.0 / dim)))
    while per_row**dim < n:
        per_row += 1
    spacing = side / per_row
    if spacing <= 2.0 * radius:
        raise InvalidInputError("fraction", "too high for the balls to start apart on a lattice", got=fraction)
    cells = np.indices((per_row,) * dim).reshape(dim, -1).T[:n]
    positions = np.ascontiguousarray((cells[:, ::-1] + 0.5) * spacing, dtype=np.float64)
    rng = np.random.default_rng(seed)
    velocities = rng.standard_normal((n, dim))
    if speeds == "equal":
        velocities *= math.sqrt(dim) / np.linalg.norm(velocities, axis=1, keepdims=True)
    if n > 1:
        velocities -= velocities.mean(axis=0)
    rms = float(np.sqrt(np.mean(np.sum(velocities**2, axis=1))))
    dt = step_fraction * radius / rms if rms > 0.0 else step_fraction * radius
    return GasScenario(positions, np.ascontiguousarray(velocities), radius, side, dt, seed)
