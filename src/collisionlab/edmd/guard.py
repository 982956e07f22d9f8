"""What an event-driven run looks at between chunks of its compiled loop: two conditions under
which it cannot go on, each ended with :class:`~collisionlab.errors.OutOfRangeError` instead of
an overflow or a loop that spins for ever.

* **Speeds beyond the run's range** (``limits.MAX_RUN_SPEED``): with e > 1 every collision adds
  energy, and a gas's collision rate grows with its speed, so the speeds can overflow within one
  step. A collision multiplies a speed by at most ``2 + e <= 12``: looking every
  :data:`GROWING_CHUNK_EVENTS` events keeps the speeds below ``1e12 * 12^32 ~ 1e47`` in between.
* **Time that no longer advances**: :data:`STALL_EVENTS` events at one instant (balls so fast
  that they cross their neighbour-list shell within the resolution of the time, or an inelastic
  collapse when ``tc = 0``).

Both read the state as stored (each ball at its own time), so a run is the same to the last bit
however often it is looked at.
"""

from __future__ import annotations

import numpy as np

from .. import limits
from ..errors import OutOfRangeError
from . import layout as L
from .world import EventDrivenWorld

__all__ = ["CHUNK_EVENTS", "GROWING_CHUNK_EVENTS", "STALL_EVENTS", "RunGuard"]

#: Events between two looks when e <= 1: a fraction of a second at the 0.3-0.9 M collisions per
#: second of bench/README.md, a negligible cost.
CHUNK_EVENTS = 1 << 16
#: Events between two looks when e > 1 (see the module's note).
GROWING_CHUNK_EVENTS = 32
#: Events at one instant after which a run is stopped: its time no longer advances.
STALL_EVENTS = CHUNK_EVENTS


class RunGuard:
    """Pass as ``EventDrivenWorld.run(..., between=guard, every=guard.every)``; keeps what it
    saw across calls (a stall may span the end of a step)."""

    def __init__(self, world: EventDrivenWorld) -> None:
        self.world = world
        self.growing = world.restitution > 1.0
        self.every = GROWING_CHUNK_EVENTS if self.growing else CHUNK_EVENTS
        self.time, self.events = world.time, int(world.K[L.K_EVENTS])

    def __call__(self) -> None:
        world = self.world
        if self.growing and not self._fastest() <= limits.MAX_RUN_SPEED:  # (NaN too)
            raise OutOfRangeError(
                f"at t = {world.time:.6g} s: speeds grew beyond {limits.MAX_RUN_SPEED:g} m/s (restitution "
                f"{world.restitution:g} > 1 adds energy at every collision): too large to simulate"
            )
        events = int(world.K[L.K_EVENTS])
        if world.time > self.time:
            self.time, self.events = world.time, events
        elif events - self.events >= STALL_EVENTS:
            raise OutOfRangeError(
                f"at t = {world.time:.6g} s: time stopped advancing ({events - self.events:,} events at one "
                f"instant; speeds up to {self._fastest():.3g} m/s: too fast for the resolution of the time, or an "
                "inelastic collapse with tc = 0): too large to simulate"
            )

    def _fastest(self) -> float:
        """The largest speed component (a million balls: a few ms, so only when needed)."""
        world = self.world
        return float(np.abs(world.F[:, L.V : L.V + world.dim]).max()) if world.n else 0.0
