"""What a world reads of its state: positions and velocities in the order the bodies were given,
energies, momentum, frames. :class:`WorldReadings` is one of :class:`~collisionlab.engine.world.World`'s
bases; it holds no state of its own and steps nothing (that is :mod:`.world` and
:mod:`.world_runs`). Sums are exact (:mod:`collisionlab.sums`), so a reading does not depend on
the order the stepper keeps the bodies in.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..record import Frame, FrameBodies
from ..sums import exact_dot, row_dots, squared_lengths
from ..vector import Vector3D
from .state import BodyArrays

__all__ = ["WorldReadings"]


class WorldReadings:
    """The readings of a world's state (a base of :class:`~collisionlab.engine.world.World`, which
    sets the attributes below)."""

    _bodies: BodyArrays
    #: Whether the stepper keeps the state in its own order (``_bodies.ids`` says which body each row is).
    _storage_sorts: bool
    _finite_masses: np.ndarray[Any, np.dtype[np.float64]]
    _gravity: np.ndarray[Any, np.dtype[np.float64]]
    _names: list[str]
    step_index: int
    time: float

    def _given_order(self, stored: np.ndarray[Any, np.dtype[np.float64]]) -> np.ndarray[Any, np.dtype[np.float64]]:
        if not self._storage_sorts:
            return stored.copy()
        out = np.empty_like(stored)
        out[self._bodies.ids] = stored
        return out

    @property
    def position_array(self) -> np.ndarray[Any, np.dtype[np.float64]]:
        """Positions ``(n, 3)`` in the order the bodies were given (a copy)."""
        return self._given_order(self._bodies.pos)

    @property
    def velocity_array(self) -> np.ndarray[Any, np.dtype[np.float64]]:
        """Velocities ``(n, 3)`` in the order the bodies were given (a copy)."""
        return self._given_order(self._bodies.vel)

    @property
    def positions(self) -> list[Vector3D]:
        return [Vector3D(*row) for row in self.position_array.tolist()]

    @property
    def velocities(self) -> list[Vector3D]:
        return [Vector3D(*row) for row in self.velocity_array.tolist()]

    def _stored_masses(self) -> Any:
        """The masses in storage order, a kinematic body's (infinite) as 0: it adds nothing to the
        sums of energy and momentum."""
        masses = self._finite_masses
        return masses[self._bodies.ids] if self._storage_sorts else masses

    def kinetic_energy(self, masses: Any = None) -> float:
        m = self._stored_masses() if masses is None else masses
        return 0.5 * exact_dot(m, squared_lengths(self._bodies.vel))

    def potential_energy(self, masses: Any = None) -> float:
        """``-sum m g.x``: zero at the origin."""
        m = self._stored_masses() if masses is None else masses
        return -exact_dot(m, row_dots(self._bodies.pos, self._gravity))

    def energy(self) -> float:
        return self.kinetic_energy() + self.potential_energy()

    def momentum(self, masses: Any = None) -> Vector3D:
        m = self._stored_masses() if masses is None else masses
        v = self._bodies.vel
        return Vector3D(*(exact_dot(m, v[:, k]) for k in range(v.shape[1])))

    def frame(self) -> Frame:
        return self._frame(self.position_array, self.velocity_array)

    def _frame(self, position_array: Any, velocity_array: Any) -> Frame:
        # The arrays are the world's copies (position_array); body states are built only if read.
        return Frame(self.step_index, self.time, FrameBodies(self._names, position_array, velocity_array))
