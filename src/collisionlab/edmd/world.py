"""``EventDrivenWorld``: hard discs or spheres run exactly, event by event (the Python side).

It owns the arrays (see :mod:`.layout`), checks its input, and calls the compiled loop
(:func:`.loop.run_events`) once per span of time; only when events are being streamed, or a
neighbour list must be widened, does control come back to Python in between. What it reads
back (time, positions, energies, the tally) is :mod:`.world_readings`'s.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidInputError
from ..validate import non_negative, positive
from . import layout as L
from .arrays import ALIGNED, STATE_ARRAYS, aligned_zeros, morton_order
from .loop import BUFFER_FULL, CELL_FULL, EVENT_LIMIT, LIST_FULL, run_events, start, synchronize
from .tuning import BUFFER_EVENTS, CELL_SLOTS, EVENTS_PER_BLOCK, HORIZON, cell_counts, list_reach
from .world_readings import Tally, WorldReadings

__all__ = ["EventDrivenWorld", "EventSink", "Tally"]

#: Receives a block of events, one row each: time, body a, body b (or ``-1 - wall``), impulse,
#: and with ``run(..., working=True)`` the rest of the columns :mod:`.layout` documents.
EventSink = Callable[[NDArray[np.float64]], None]


class EventDrivenWorld(WorldReadings):
    """N hard balls (discs in 2D, spheres in 3D) in the box ``[0, sides]``, periodic or walled,
    under optional gravity ``g`` along ``-y`` (walls only), with restitution ``e`` and the TC
    model's ``tc`` (Luding and McNamara 1998; see :mod:`.loop`).

    ``radius`` and ``mass`` are one number for equal balls, or one per ball (a mixture: the same
    arrays and the same loop, each pair meeting at ``r_i + r_j``). ``species``, one small
    integer per ball, labels the kinds whose pair collisions are counted apart
    (:attr:`Tally.species_collisions`); by default each distinct (radius, mass) is a kind.

    >>> w = EventDrivenWorld([[2.0, 5.0], [6.0, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], sides=[10.0, 10.0],
    ...                      periodic=False)
    >>> w.run(1.5)                                   # they meet at t = 1, when the gap of 2 is closed
    >>> w.velocities.tolist(), w.tally().pair_collisions
    ([[-1.0, 0.0], [1.0, 0.0]], 1)
    """

    def __init__(
        self,
        positions: object,
        velocities: object,
        sides: object,
        *,
        radius: ArrayLike = 1.0,
        mass: ArrayLike = 1.0,
        species: object = None,
        restitution: float = 1.0,
        gravity: float = 0.0,
        tc: float = 0.0,
        periodic: bool = True,
    ) -> None:
        # No copies: a million balls' inputs are 48 MB; they are read, then copied into F.
        pos = np.asarray(positions, dtype=np.float64)
        vel = np.asarray(velocities, dtype=np.float64)
        if pos.ndim != 2 or pos.shape[1] not in (2, 3) or pos.shape[0] < 1:
            raise InvalidInputError("positions", "must be N rows of 2 or 3 numbers", got=pos.shape)
        if vel.shape != pos.shape:
            raise InvalidInputError("velocities", f"must have the shape of positions {pos.shape}", got=vel.shape)
        n, dim = pos.shape
        box = np.array(sides, dtype=np.float64).reshape(-1)
        if box.shape != (dim,) or not np.all(np.isfinite(box)) or np.any(box <= 0):
            raise InvalidInputError("sides", f"must be {dim} numbers > 0", got=box.tolist())
        if not (np.all(np.isfinite(pos)) and np.all(np.isfinite(vel))):
            raise InvalidInputError("positions", "positions and velocities must be finite")
        radii = self._per_ball(radius, "radius", n)
        masses = self._per_ball(mass, "mass", n)
        kinds = self._species(species, radii, masses, n)
        #: The largest radius (the one of every ball when they are equal), and the mass of
        #: every ball when they are equal (else the largest: see :attr:`masses`).
        self.radius = float(radii.max())
        self.mass = float(masses.max())
        self.mixed = bool(radii.min() != radii.max())
        self.uniform_mass = bool(masses.min() == masses.max())
        self.restitution = non_negative(restitution, "restitution")
        self.gravity = non_negative(gravity, "gravity")
        self.tc = non_negative(tc, "tc")
        self.periodic = bool(periodic)
        if self.gravity > 0 and self.periodic:
            raise InvalidInputError("gravity", "needs walls (a periodic box has no floor)")
        if self.gravity > 0 and self.tc <= 0:
            raise InvalidInputError("tc", "must be > 0 under gravity (the shortest flight off the floor)")
        self.shell, sigma, cut = list_reach(radii, dim, box, self.gravity)
        if self.periodic and np.any(box < 4.0 * sigma):
            raise InvalidInputError("sides", "a periodic box must be at least 4 diameters wide", got=box.tolist())
        if self.periodic:
            pos = pos - np.floor(pos / box) * box
        elif np.any(pos < radii[:, None]) or np.any(pos > box - radii[:, None]):
            raise InvalidInputError("positions", "every ball must lie inside the walls")
        self.n = n
        self.dim = dim
        self.sides = box
        self.F = aligned_zeros((n, L.NF))
        # Bodies are stored in Morton (Z-curve) order of their starting cells, so that neighbours
        # sit near each other in memory (a million bodies do not fit in any cache); ``order[k]`` is
        # the caller's index of stored body k. The key depends on positions only, never on the
        # caller's numbering, so a permutation of the input is stored the same way.
        self.order = morton_order(pos, cut)
        self.F[:, L.X : L.X + dim] = pos[self.order]
        self.F[:, L.V : L.V + dim] = vel[self.order]
        self.F[:, L.TLAST] = -math.inf
        self.F[:, L.RADIUS] = radii[self.order]
        self.F[:, L.MASS] = masses[self.order]
        count = int(kinds.max()) + 1
        # Counted by species when there are several or they were named (else the totals tell).
        counted = count > 1 or species is not None
        self.S = kinds[self.order].astype(np.int32) if counted else np.zeros(0, dtype=np.int32)
        self.KS = np.zeros((count, count) if counted else (0, 0), dtype=np.int64)
        self.species_count = count
        self.SE = np.zeros((count, 3) if counted else (0, 3))
        if counted:  # each species' kinetic energy at the start (its integral starts at time 0)
            energy = 0.5 * masses * np.einsum("ij,ij->i", vel, vel)
            self.SE[:, 0] = np.bincount(kinds, weights=energy, minlength=count)
        del pos, vel  # (a wrapped copy of) the inputs, now in F: not held through the start
        self.IX = aligned_zeros((n, L.NI), np.int32)
        # a mixture: each body's radius after the parameters, in storage order (layout.P_RADII)
        self.P = np.zeros(L.NP + (n if self.mixed else 0))
        self.Q = np.zeros(L.NQ, dtype=np.int64)
        self.G = np.zeros(L.NG)
        self.K = np.zeros(L.NK, dtype=np.int64)
        self.P[L.P_L : L.P_L + 3] = 1.0
        self.P[L.P_L : L.P_L + dim] = box
        self.P[L.P_RADIUS] = self.radius
        self.P[L.P_MIXED] = 1.0 if self.mixed else 0.0
        if self.mixed:
            self.P[L.P_RADII :] = self.F[:, L.RADIUS]
        self.P[L.P_E] = self.restitution
        self.P[L.P_TC] = self.tc
        self.P[L.P_G] = self.gravity
        self.P[L.P_CUT] = cut
        # the cells' float32 centres are off by at most 2^-24 of the box side per axis
        self.P[L.P_REACH] = cut + 8.0 * float(np.finfo(np.float32).eps) * float(box.max())
        self.P[L.P_SKIN] = 0.5 * (cut - sigma)  # no pair off the lists comes within sigma
        self.Q[L.Q_DIM] = dim
        self.Q[L.Q_PERIODIC] = int(self.periodic)
        self.Q[L.Q_NC : L.Q_NC + 3] = 1
        cells = cell_counts(box, cut, n)
        self.Q[L.Q_NC : L.Q_NC + dim] = cells
        self.P[L.P_INV_H : L.P_INV_H + dim] = cells / box
        self._cells(int(np.prod(cells)), CELL_SLOTS)
        self.heap = aligned_zeros((n,), np.int32)
        neighbours = 16 if dim == 2 else 32
        self.NB = aligned_zeros((n, neighbours), np.int32)
        self.P[L.P_BLOCK] = 1.0
        self.Q[L.Q_NB] = 1
        self.lists = np.full(2, -1, dtype=np.int32)
        self._start()
        self._tune_calendar()
        if self.max_overlap() > 0.0:
            raise InvalidInputError("positions", "balls must not overlap at the start")
        self.G[L.G_MAX_OVERLAP] = 0.0

    def state_arrays(self) -> dict[str, NDArray[Any]]:
        """The world's whole state, as it is stored (each body at its own time, the calendar
        as scheduled): the arrays named in :data:`STATE_ARRAYS`, not copied. A world made from
        them (:meth:`from_state_arrays`) runs on exactly as this one would, to the last bit."""
        return {name: getattr(self, name) for name in STATE_ARRAYS}

    @classmethod
    def from_state_arrays(cls, arrays: dict[str, NDArray[Any]], shell: float) -> EventDrivenWorld:
        """A world holding a copy of ``arrays`` (:meth:`state_arrays`; checked by their reader,
        :mod:`.checkpoint`), nothing predicted or rebuilt: its future is the saved world's.
        ``shell`` is the saved world's :attr:`shell` (it decided the lists' reach, ``P_CUT``)."""
        world = cls.__new__(cls)
        for name in STATE_ARRAYS:
            source = arrays[name]
            if name in ALIGNED:
                copy = aligned_zeros(source.shape, source.dtype.type)
                copy[...] = source
            else:
                copy = np.array(source, dtype=source.dtype, copy=True)
            setattr(world, name, copy)
        world.CF = world.CI.view(np.float32)
        F, P, Q = world.F, world.P, world.Q
        world.n, world.dim = int(F.shape[0]), int(Q[L.Q_DIM])
        world.sides = P[L.P_L : L.P_L + world.dim].copy()
        world.radius = float(P[L.P_RADIUS])
        world.mass = float(F[:, L.MASS].max())
        world.mixed = bool(P[L.P_MIXED] != 0.0)
        world.uniform_mass = bool(F[:, L.MASS].min() == F[:, L.MASS].max())
        world.restitution, world.tc, world.gravity = float(P[L.P_E]), float(P[L.P_TC]), float(P[L.P_G])
        world.periodic = bool(Q[L.Q_PERIODIC])
        world.shell = float(shell)
        world.species_count = max(1, int(world.KS.shape[0]))
        return world

    @staticmethod
    def _per_ball(value: ArrayLike, name: str, n: int) -> NDArray[np.float64]:
        """``value`` (one number, or one per ball) as ``n`` finite numbers > 0."""
        if np.ndim(value) == 0:
            return np.full(n, positive(value, name))
        array = np.asarray(value, dtype=np.float64)
        if array.shape != (n,):
            raise InvalidInputError(name, f"must be one number or {n} (one per ball)", got=array.shape)
        if not (np.all(np.isfinite(array)) and np.all(array > 0.0)):
            raise InvalidInputError(name, "every value must be finite and > 0")
        return array

    @staticmethod
    def _species(species: object, radii: NDArray[np.float64], masses: NDArray[np.float64], n: int) -> NDArray[Any]:
        """Each ball's kind, ``0 .. k - 1``: ``species`` as given, or one per (radius, mass)."""
        if species is None:
            pairs = np.stack([radii, masses], axis=1)
            return np.unique(pairs, axis=0, return_inverse=True)[1].reshape(-1).astype(np.int64)
        kinds = np.asarray(species)
        if kinds.shape != (n,) or kinds.dtype.kind not in "iu" or (n > 0 and int(kinds.min()) < 0):
            raise InvalidInputError("species", f"must be {n} integers >= 0 (one per ball)", got=kinds.shape)
        return kinds.astype(np.int64)

    def _cells(self, count: int, slots: int) -> None:
        """Room for ``count`` cells of ``slots - 1`` bodies (see :mod:`.cells`)."""
        # rows on cache lines: a cell's count and first 3 bodies in one
        self.CI = aligned_zeros((count, slots, 4), np.int32)
        self.CF = self.CI.view(np.float32)

    def _widen(self, status: int) -> None:
        """Twice the room in every neighbour list (``LIST_FULL``) or every cell (``CELL_FULL``)."""
        if status == LIST_FULL:
            self.NB = aligned_zeros((self.n, 2 * self.NB.shape[1]), np.int32)
        elif status == CELL_FULL:
            self._cells(self.CI.shape[0], 2 * self.CI.shape[1])

    def _start(self) -> None:
        while True:
            status = start(
                self.heap, self.lists, self.CI, self.CF, self.F, self.IX, self.NB, self.P, self.Q, self.K, self.time
            )
            if status == 0:
                return
            self._widen(status)

    def _tune_calendar(self) -> None:
        """Blocks of about ``EVENTS_PER_BLOCK`` events, a ring covering ``HORIZON`` typical
        times between a body's events (Smallenburg's advice: tens to hundreds per block)."""
        ahead = self.F[:, L.EVT] - self.time
        ahead = ahead[np.isfinite(ahead) & (ahead > 0)]
        typical = float(np.median(ahead)) if ahead.size else 1.0
        block = EVENTS_PER_BLOCK * typical / self.n
        self.P[L.P_BLOCK] = block
        self.Q[L.Q_NB] = max(1, math.ceil(HORIZON * typical / block))
        self.lists = np.full(int(self.Q[L.Q_NB]) + 1, -1, dtype=np.int32)
        self._start()

    def run(
        self,
        until: float,
        sink: EventSink | None = None,
        max_events: int | None = None,
        working: bool = False,
        bring: bool = True,
        between: Callable[[], None] | None = None,
        every: int = BUFFER_EVENTS,
    ) -> None:
        """Handle every event up to time ``until`` (or stop after ``max_events``), then (when
        ``bring``) bring every body to that time. ``sink`` receives the events in blocks as they
        happen, with each one's working (normal, point, normal speed, e, velocities) when
        ``working``. Without ``bring`` the bodies stay at the times of their last events, so a
        run split into many calls is the same, to the last bit, as one call (:meth:`state`
        reads where they are without moving them). ``between``, when given, is called at least
        every ``every`` events, with control back in Python: it may look at the state, or raise
        to stop the run; the run is the same to the last bit however often it is called."""
        limit = np.iinfo(np.int64).max if max_events is None else int(max_events)
        columns = L.EVENT_FULL if working else L.EVENT_BRIEF
        buffer = np.zeros((BUFFER_EVENTS if sink is not None else 0, columns))
        while True:
            before = int(self.K[L.K_EVENTS])
            chunk = limit if between is None else min(limit, max(1, int(every)))
            status = run_events(
                self.heap, self.lists, self.CI, self.CF, self.F, self.IX, self.NB, self.P, self.Q, self.G, self.K,
                self.S, self.KS, self.SE, buffer, float(until), chunk,
            )  # fmt: skip
            limit -= int(self.K[L.K_EVENTS]) - before
            if sink is not None and self.K[L.K_BUFFERED] > 0:
                block = buffer[: int(self.K[L.K_BUFFERED])]
                a = block[:, 1].astype(np.int64)
                b = block[:, 2].astype(np.int64)
                block[:, 1] = self.order[a]
                block[:, 2] = np.where(b >= 0, self.order[np.maximum(b, 0)], b)
                sink(block)
                self.K[L.K_BUFFERED] = 0
            # after the sink: no event is lost if it raises
            if between is not None and status not in (LIST_FULL, CELL_FULL):
                between()
            if status == BUFFER_FULL or (status == EVENT_LIMIT and limit > 0):  # (a chunk for between)
                continue
            if status in (LIST_FULL, CELL_FULL):
                self._widen(status)
                self._start()
                continue
            break  # DONE or EVENT_LIMIT
        if bring:
            synchronize(self.F, self.P, self.time)
