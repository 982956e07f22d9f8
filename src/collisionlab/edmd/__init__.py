"""Event-driven molecular dynamics of hard discs and spheres: exact, and fast.

Bodies fly on exact straight lines (parabolas under gravity) between collisions; the next
collision of every body is predicted and only collisions (and neighbour-list updates) are
handled, in time order, by one compiled loop. The design follows F. Smallenburg, "Efficient
event-driven simulations of hard spheres", Eur. Phys. J. E 45, 22 (2022): cell lists feeding
neighbour lists, one scheduled event per body, a calendar of a small heap for the near future
plus linear lists, and lazy invalidation by per-body collision counters.
"""

from __future__ import annotations

from .start import box_side, gaussian_velocities, lattice
from .theory import carnahan_starling, contact_value, enskog_collision_rate, henderson, ideal_compressibility
from .world import EventDrivenWorld, EventSink, Tally

__all__ = [
    "EventDrivenWorld",
    "EventSink",
    "Tally",
    "box_side",
    "carnahan_starling",
    "contact_value",
    "enskog_collision_rate",
    "gaussian_velocities",
    "henderson",
    "ideal_compressibility",
    "lattice",
]
