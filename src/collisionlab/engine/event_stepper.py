"""The event-driven stepper: hard balls in a box, run event by event on a world's state.

A scenario of balls in a :class:`~collisionlab.model.Box` (walls or periodic) with
``mode = "exact"`` (:attr:`~collisionlab.model.Scenario.event_driven`) steps here, on
:class:`~collisionlab.edmd.EventDrivenWorld`: neighbour lists fed by cell lists, one
scheduled event per ball in a calendar, lazy invalidation (F. Smallenburg, Eur. Phys. J. E 45, 22
(2022)). There is no time step inside: :meth:`EventDrivenStepper.advance` handles every event
up to the end of the steps asked for, in time order, then brings every ball to that moment, so
the world's frames are exact at their times. The time of impact of two balls and the contact
law are the engine's (:mod:`collisionlab.engine.geometry_kernels`); inelastic collapse is
stopped by the TC model (a collision of a ball that collided less than ``tc`` ago is elastic:
:mod:`collisionlab.edmd.loop`).

Events come out as the Forward Euler stepper's rows (``event_rows.EVENT_COLUMNS``), oriented
as the engine orients pairs (the body given first is A; a wall is A, its normal pointing at the
ball), so the world records and streams them as any other. The ledger: the collisions' change of
kinetic energy as measured, beside theory's ``(1 - e^2)/2 mu v_n^2``; no integrator error (exact
flight) and no push-apart.

A mixture (balls of several radii or masses, or several ``[[gas]]`` tables: the scenario's
:meth:`~collisionlab.model.Scenario.ball_species`) runs on the same world, each ball with its
own radius and mass, its collisions and kinetic energy counted by kind;
:meth:`EventDrivenStepper.species_report` gives each kind's count, radius, mass and ``kT``.
Balls of one kind are given as one radius and one mass, as they always were.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidInputError
from ..model import BallSpecies, Box
from ..numba_cache import compiling_notice
from . import event_rows, step_kernels
from .params import WorldParams
from .state import BodyArrays, StaticArrays

__all__ = ["EventDrivenStepper", "default_tc"]

FloatArray = NDArray[np.float64]


def default_tc(radius: float, velocities: FloatArray, gravity: float, restitution: float, fraction: float) -> float:
    """The TC model's time when a scenario gives none: 0 for elastic balls without gravity (no
    collapse can happen); else ``fraction`` of the time a typical ball takes to cross its radius,
    ``radius / u`` with ``u`` the larger of the root-mean-square speed and ``sqrt(g r)``.

    >>> default_tc(1.0, np.zeros((4, 3)), 0.0, 1.0, 0.01), default_tc(0.5, np.zeros((4, 3)), 2.0, 1.0, 0.01)
    (0.0, 0.005)
    """
    if restitution >= 1.0 and gravity == 0.0:
        return 0.0
    rms = math.sqrt(float(np.mean(np.einsum("ij,ij->i", velocities, velocities)))) if len(velocities) else 0.0
    speed = max(rms, math.sqrt(gravity * radius))
    return fraction * radius / speed if speed > 0.0 else 0.0


class EventDrivenStepper:
    """Advances ``bodies`` (balls) in ``box`` event by event; ``statics`` are the box's walls as
    the world lists them (for the overlap check at the start). The ledger of every call since it
    was made is :attr:`ledger` (``step_kernels.LEDGER_SIZE``). ``species``: a mixture's kinds
    of ball and each ball's kind (:meth:`~collisionlab.model.Scenario.ball_species`), each ball
    then of its kind's radius and mass; ``None``: balls all of the first one's radius and mass."""

    def __init__(
        self,
        bodies: BodyArrays,
        statics: StaticArrays,
        dims: int,
        gravity: FloatArray,
        params: WorldParams,
        box: Box,
        restitution: float,
        tc: float | None,
        record_events: bool = True,
        notify: Callable[[str], None] | None = None,
        species: tuple[tuple[BallSpecies, ...], NDArray[np.int64]] | None = None,
    ) -> None:
        from ..edmd import EventDrivenWorld
        from ..edmd.compile import is_cached
        from ..edmd.guard import RunGuard

        self.bodies, self.statics, self.dims, self.params = bodies, statics, dims, params
        self.record_events = record_events
        self._origin = np.array(box.low.as_tuple()[:dims])
        self._periodic = box.boundary == "periodic"
        self._box = box
        #: A mixture's kinds of ball (empty: balls of one kind) and each ball's kind.
        self.species: tuple[BallSpecies, ...] = () if species is None else species[0]
        self._labels = np.zeros(0, np.int64) if species is None else species[1]
        radius: float | FloatArray
        mass: float | FloatArray
        if species is None:
            radius = float(bodies.ext[0, 0])
            mass = 1.0 / float(bodies.ima[0])
            smallest = radius
        else:  # each ball its kind's (the masses as given, not 1 / (1 / m))
            radius = np.array([k.radius for k in self.species])[self._labels]
            mass = np.array([k.mass for k in self.species])[self._labels]
            smallest = float(radius.min())
        self._masses = mass
        g = -float(gravity[1])
        if tc is None:
            tc = default_tc(smallest, bodies.vel, g, restitution, params.tc_fraction)
        self.tc = tc
        if notify is not None and not is_cached():
            notify(compiling_notice("event-driven"))
        try:
            self.world = EventDrivenWorld(
                bodies.pos[:, :dims] - self._origin,
                bodies.vel[:, :dims],
                box.sides,
                radius=radius,
                mass=mass,
                restitution=restitution,
                gravity=g,
                tc=tc,
                periodic=self._periodic,
                species=None if species is None else self._labels,
            )
        except InvalidInputError as error:
            field = {"positions": "body", "sides": "box.region"}.get(error.field, f"simulation.{error.field}")
            raise InvalidInputError(field, error.problem, error.got) from None
        self.guard = RunGuard(self.world)
        self.ledger = np.zeros(step_kernels.LEDGER_SIZE)
        self._events = np.zeros((0, event_rows.EVENT_COLUMNS))
        self._copied = True  # the world's arrays hold the start

    def advance(self, kernels: ModuleType | None, dt: float, restitution: float, first_step: int, steps: int) -> None:
        """Handle every event up to the end of step ``first_step + steps`` (time ``(first_step +
        steps) dt``); :meth:`copy_state` then gives the world where the balls are. ``kernels``
        and ``restitution`` are unused (the balls' own loop, one e)."""
        blocks: list[FloatArray] = []
        until = (first_step + steps) * dt
        # The balls are not brought to ``until``: only read there (state()), so a run is the
        # same to the last bit however its steps were split into calls.
        # The guard stops a run whose speeds overflow (e > 1) or whose time stalls (edmd.guard).
        guard = self.guard
        sink = (lambda block: blocks.append(block.copy())) if self.record_events else None
        self.world.run(until, sink, working=self.record_events, bring=False, between=guard, every=guard.every)
        self._copied = False
        self._events = self._rows(np.concatenate(blocks) if blocks else np.zeros((0, 24)), dt, first_step, steps)
        self._tally()

    def copy_state(self) -> None:
        """Copy where every ball is at the end of the last :meth:`advance` to the world's arrays
        (once: a gas of a million balls is only read when asked)."""
        if not self._copied:
            positions, velocities = self.world.state()
            d = self.dims
            self.bodies.pos[:, :d] = positions + self._origin
            self.bodies.vel[:, :d] = velocities
            self._copied = True

    def species_report(self) -> list[dict[str, Any]]:
        """A mixture's kinds of ball (empty for balls of one kind), each one's ``name``,
        ``count``, ``radius``, ``mass`` and ``kT`` measured, ``2 <E_a> / (d N_a)``: ``<E_a>`` its
        kinetic energy averaged over the time run so far (exact: without gravity it changes only
        at collisions), or under gravity its kinetic energy now (it changes in flight too). The
        balls are not moved (:meth:`copy_state`)."""
        if not self.species:
            return []
        world, count = self.world, len(self.species)
        energies: FloatArray
        if world.gravity == 0.0:
            energies = world.species_mean_energy()
        else:
            _, velocities = world.state()
            energy = 0.5 * self._masses * np.einsum("ij,ij->i", velocities, velocities)
            energies = np.bincount(self._labels, weights=energy, minlength=count).astype(np.float64)
        return [
            {
                "name": kind.name,
                "count": kind.count,
                "radius": kind.radius,
                "mass": kind.mass,
                "kT": 2.0 * float(energies[k]) / (self.dims * kind.count),
            }
            for k, kind in enumerate(self.species)
        ]

    def _rows(self, raw: FloatArray, dt: float, first_step: int, steps: int) -> FloatArray:
        """The loop's event rows (:mod:`collisionlab.edmd.layout`) as the engine's."""
        n = raw.shape[0]
        rows = np.zeros((n, event_rows.EVENT_COLUMNS))
        if n == 0:
            return rows
        d = self.dims
        a, b = raw[:, 1].astype(np.int64), raw[:, 2].astype(np.int64)
        # A wall first (its code, -1 - w, is the world's static -1 - w: the walls are its only
        # statics, in the same order), then bodies in the order given.
        swap = (b < 0) | ((b >= 0) & (b < a))
        sign = np.where(swap, -1.0, 1.0)[:, None]
        rows[:, 0] = event_rows.EVENT_IMPACT
        step = np.ceil(raw[:, 0] / dt)
        rows[:, 1] = np.clip(step, first_step + 1, first_step + steps)
        rows[:, 2] = raw[:, 0]
        rows[:, 3] = np.where(swap, b, a)
        rows[:, 4] = np.where(swap, a, b)
        rows[:, 5:8] = raw[:, 4:7] * sign
        rows[:, 8:11] = raw[:, 7:10]
        rows[:, 8 : 8 + d] += self._origin
        rows[:, 11] = raw[:, 10]
        rows[:, 12] = raw[:, 3]
        rows[:, 13] = raw[:, 11]
        for target, first, second in ((14, 12, 15), (20, 18, 21)):  # before, after: A's then B's
            rows[:, target : target + 3] = np.where(
                swap[:, None], raw[:, second : second + 3], raw[:, first : first + 3]
            )
            rows[:, target + 3 : target + 6] = np.where(
                swap[:, None], raw[:, first : first + 3], raw[:, second : second + 3]
            )
        return rows

    def _tally(self) -> None:
        """The ledger's running totals from the loop's accumulators (``step_kernels``' order; no
        integrator and no push-apart: the flights are exact and nothing is pushed apart)."""
        from ..edmd import layout

        world, ledger = self.world, self.ledger
        ledger[1] = world.G[layout.G_KINETIC]
        ledger[3] = -world.G[layout.G_LOST]
        ledger[5] = world.K[layout.K_PAIRS]
        ledger[6] = world.K[layout.K_WALLS]

    def events(self) -> FloatArray:
        """The event rows of the last :meth:`advance` (``event_rows.EVENT_COLUMNS`` columns)."""
        return self._events

    def release_events(self) -> None:
        self._events = np.zeros((0, event_rows.EVENT_COLUMNS))

    def nbytes(self) -> int:
        """Bytes of every array held: the event loop's, and the world's state."""
        s = self.statics
        return int(self.world.nbytes + self.bodies.nbytes() + sum(a.nbytes for a in (s.kind, s.a, s.b, s.e)))
