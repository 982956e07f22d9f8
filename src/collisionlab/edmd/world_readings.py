"""What an :class:`~.world.EventDrivenWorld` reads back from its arrays without changing the run:
the time, each ball's position, velocity, radius and mass in the caller's order, the energies
(exactly rounded sums), the deepest overlap, the memory held and the loop's counts
(:class:`Tally`). A mixin: the world owns the arrays (:mod:`.layout`) and the loop.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..sums import exact_dot, exact_sum, squared_lengths
from . import layout as L
from .loop import max_overlap_now, synchronize

__all__ = ["Tally", "WorldReadings"]


@dataclass(frozen=True)
class Tally:
    """What the loop counted since the world was made."""

    time: float
    pair_collisions: int
    wall_collisions: int
    events: int
    list_rebuilds: int
    stale_events: int
    virial: float
    wall_momentum: tuple[float, ...]
    max_contact_overlap: float
    energy_lost: float
    #: Pair collisions by species, ``[a][b]`` (symmetric; a mixture only, else empty).
    species_collisions: tuple[tuple[int, ...], ...] = ()


class WorldReadings:
    """The readings of an event-driven world (a mixin of :class:`~.world.EventDrivenWorld`, which
    sets these attributes)."""

    n: int
    dim: int
    sides: NDArray[np.float64]
    periodic: bool
    gravity: float
    mass: float
    uniform_mass: bool
    F: NDArray[np.float64]
    IX: NDArray[np.int32]
    NB: NDArray[np.int32]
    P: NDArray[np.float64]
    Q: NDArray[np.int64]
    G: NDArray[np.float64]
    K: NDArray[np.int64]
    CI: NDArray[np.int32]
    heap: NDArray[np.int32]
    lists: NDArray[np.int32]
    order: NDArray[np.int64]
    S: NDArray[np.int32]
    KS: NDArray[np.int64]
    SE: NDArray[np.float64]

    @property
    def time(self) -> float:
        return float(self.G[L.G_NOW])

    def state(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Centres (inside the box also with periodic walls) and velocities at :attr:`time`, in
        the caller's order, each body's flight from its own time extended to it, without moving
        the bodies (what they do next does not depend on when they were looked at)."""
        d = self.dim
        ahead = self.time - self.F[:, L.T]
        x = self.F[:, L.X : L.X + d] + self.F[:, L.V : L.V + d] * ahead[:, None]
        v = self.F[:, L.V : L.V + d].copy()
        if self.gravity > 0.0:  # along -y: x += (v_y - g t / 2) t, v_y -= g t, as the loop moves them
            x[:, 1] -= 0.5 * self.gravity * ahead * ahead
            v[:, 1] -= self.gravity * ahead
        pos = np.empty((self.n, d))
        vel = np.empty((self.n, d))
        pos[self.order] = x
        vel[self.order] = v
        if self.periodic:
            pos -= np.floor(pos / self.sides) * self.sides
        return pos, vel

    @property
    def positions(self) -> NDArray[np.float64]:
        """Centres at :attr:`time` (a copy; inside the box also with periodic walls)."""
        synchronize(self.F, self.P, self.time)
        pos = np.empty((self.n, self.dim))
        pos[self.order] = self.F[:, L.X : L.X + self.dim]
        if self.periodic:
            pos -= np.floor(pos / self.sides) * self.sides
        return pos

    @property
    def velocities(self) -> NDArray[np.float64]:
        synchronize(self.F, self.P, self.time)
        vel = np.empty((self.n, self.dim))
        vel[self.order] = self.F[:, L.V : L.V + self.dim]
        return vel

    @property
    def radii(self) -> NDArray[np.float64]:
        """Each ball's radius, in the caller's order (a copy)."""
        radii = np.empty(self.n)
        radii[self.order] = self.F[:, L.RADIUS]
        return radii

    @property
    def masses(self) -> NDArray[np.float64]:
        """Each ball's mass, in the caller's order (a copy)."""
        masses = np.empty(self.n)
        masses[self.order] = self.F[:, L.MASS]
        return masses

    def species_mean_energy(self) -> NDArray[np.float64]:
        """Each species' kinetic energy averaged over the time run so far (a mixture; exact
        without gravity, where it changes only at collisions)."""
        t = self.time
        total = self.SE[:, 2] + self.SE[:, 0] * (t - self.SE[:, 1])
        return total / t if t > 0 else self.SE[:, 0].copy()

    def kinetic_energy(self) -> float:
        v = self.velocities
        if self.uniform_mass:
            return 0.5 * self.mass * exact_sum(squared_lengths(v))
        return 0.5 * exact_dot(self.masses, squared_lengths(v))

    def potential_energy(self) -> float:
        """``m g y`` summed (height measured from the floor of the box)."""
        if self.gravity == 0.0:
            return 0.0
        if self.uniform_mass:
            return self.mass * self.gravity * exact_sum(self.positions[:, 1])
        return self.gravity * exact_dot(self.masses, self.positions[:, 1])

    def max_overlap(self) -> float:
        """Deepest overlap now (pairs and walls; negative: the smallest gap), length units."""
        synchronize(self.F, self.P, self.time)
        return float(max_overlap_now(self.F, self.IX, self.NB, self.P, self.Q))

    @property
    def nbytes(self) -> int:
        arrays = (
            self.F,
            self.IX,
            self.NB,
            self.P,
            self.Q,
            self.G,
            self.K,
            self.CI,
            self.heap,
            self.lists,
            self.order,
            self.S,
            self.KS,
            self.SE,
        )
        return sum(a.nbytes for a in arrays)

    def tally(self) -> Tally:
        return Tally(
            time=self.time,
            pair_collisions=int(self.K[L.K_PAIRS]),
            wall_collisions=int(self.K[L.K_WALLS]),
            events=int(self.K[L.K_EVENTS]),
            list_rebuilds=int(self.K[L.K_NLIST]),
            stale_events=int(self.K[L.K_STALE]),
            virial=float(self.G[L.G_VIRIAL]),
            wall_momentum=tuple(float(x) for x in self.G[L.G_WALL : L.G_WALL + 2 * self.dim]),
            max_contact_overlap=float(self.G[L.G_MAX_OVERLAP]),
            energy_lost=float(self.G[L.G_LOST]),
            species_collisions=tuple(tuple(int(c) for c in row) for row in self.KS),
        )
