"""What a run measures: pressure from the collision virial and from the walls, collision rate,
temperature, energy drift, overlap; and the exact gas behind ``collisionlab gas --mode exact``.

For hard bodies the force is a sum of impulses, so the virial theorem gives the pressure from
the collisions themselves (Allen and Tildesley, *Computer Simulation of Liquids*, 2nd ed.,
eq. 2.69 and section 3.7.2; Smallenburg 2022, eq. 7):

    Z = P V / (N kT) = 1 + W / (d N kT t),   W = sum over collisions of r_ij . dp_i,

with ``d`` the dimension and ``t`` the time simulated. With walls the pressure is also the
momentum given to the walls per unit area and time, ``P = sum_w J_w / A_w / (2 d t)`` (the
mean over the ``2 d`` walls); near walls the density is not the bulk density, so the two
routes differ by a surface term of order ``sigma / L``. ``kT = 2 E_kin / (d N)`` at the end.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import limits
from ..errors import InvalidInputError, OutOfRangeError
from ..validate import non_negative, positive, whole_number
from . import layout as L
from .start import box_side, gaussian_velocities, lattice
from .theory import enskog_collision_rate, ideal_compressibility
from .world import EventDrivenWorld, EventSink

__all__ = ["BOUNDARIES", "DEFAULT_TC", "ExactGas", "measure", "run_exact_gas"]

#: Events handled between two looks at the run (an interrupt, the speeds): a fraction of a second
#: at the 0.3-0.9 M collisions per second of bench/README.md.
CHUNK_EVENTS = 1 << 16
#: The same when e > 1 (each collision adds energy), so that speeds cannot overflow in between.
GROWING_CHUNK_EVENTS = 32
#: Events at one instant after which a run is stopped: time no longer advances (see _Guard).
STALL_EVENTS = CHUNK_EVENTS
#: ``collisionlab gas --boundary``: hard walls, or a periodic box.
BOUNDARIES: tuple[str, ...] = ("walls", "periodic")
#: Time units (radius 1, mass 1, kT 1: a typical ball moves 0.01 radius in it). The TC model's
#: ``t_c`` when ``e < 1`` or under gravity and none is given; see :mod:`.loop` for what it does.
DEFAULT_TC = 0.01


@dataclass(frozen=True)
class ExactGas:
    """The exact gas: ``n`` balls of radius 1 and mass 1 on a lattice at packing ``fraction``,
    seeded Gaussian velocities at ``kt``; ``tc`` defaults to :data:`DEFAULT_TC` when ``e < 1`` or
    under gravity (0 otherwise: collisions are elastic anyway)."""

    n: int
    dim: int = 3
    fraction: float = 0.2
    boundary: str = "walls"
    time: float = 10.0
    seed: int = 0
    restitution: float = 1.0
    gravity: float = 0.0
    tc: float | None = None
    kt: float = 1.0
    radius: float = 1.0
    mass: float = 1.0

    def checked(self) -> ExactGas:
        """The same settings, validated (:class:`InvalidInputError` names the field)."""
        n = limits.gas_balls(self.n, "n")
        dim = whole_number(self.dim, "dim")
        if dim not in (2, 3):
            raise InvalidInputError("dim", "must be 2 or 3", got=self.dim)
        fraction = limits.within(positive(self.fraction, "fraction"), "fraction", limits.MIN_GAS_FRACTION, math.inf)
        if fraction >= (0.9069 if dim == 2 else 0.7405):
            raise InvalidInputError(
                "fraction", "must be below close packing (0.9069 in 2D, 0.7405 in 3D)", got=fraction
            )
        if self.boundary not in BOUNDARIES:
            raise InvalidInputError("boundary", f"must be one of {', '.join(BOUNDARIES)}", got=self.boundary)
        tc = self.tc
        # The same range as every scenario (collisionlab.limits): e = 1e308 would run for ever.
        restitution = limits.restitution(self.restitution, "restitution")
        gravity = limits.within(non_negative(self.gravity, "gravity"), "gravity", 0.0, limits.MAX_ACCELERATION)
        if tc is None:
            tc = DEFAULT_TC if restitution < 1.0 or gravity > 0.0 else 0.0
        return ExactGas(
            n=n,
            dim=dim,
            fraction=fraction,
            boundary=self.boundary,
            time=limits.gas_time(self.time, "time"),
            seed=whole_number(self.seed, "seed", minimum=0),
            restitution=restitution,
            gravity=gravity,
            tc=non_negative(tc, "tc"),
            kt=positive(self.kt, "kt"),
            radius=positive(self.radius, "radius"),
            mass=positive(self.mass, "mass"),
        )

    def world(self) -> EventDrivenWorld:
        s = self.checked()
        periodic = s.boundary == "periodic"
        positions = lattice(s.n, s.dim, s.fraction, s.radius, periodic, s.seed)
        velocities = gaussian_velocities(s.n, s.dim, s.kt, s.mass, s.seed)
        side = box_side(s.n, s.dim, s.fraction, s.radius)
        return EventDrivenWorld(
            positions,
            velocities,
            [side] * s.dim,
            radius=s.radius,
            mass=s.mass,
            restitution=s.restitution,
            gravity=s.gravity,
            tc=s.tc or 0.0,
            periodic=periodic,
        )


def measure(world: EventDrivenWorld, energy_start: float, seconds: float) -> dict[str, Any]:
    """The observables of ``world`` after a run from time 0 (see the module's docstring)."""
    tally = world.tally()
    n, dim, t = world.n, world.dim, tally.time
    kinetic = world.kinetic_energy()
    energy = kinetic + world.potential_energy()
    kt = 2.0 * kinetic / (dim * n)
    volume = float(world.sides.prod())
    nkt = n * kt
    report: dict[str, Any] = {
        "sim_time": t,
        "collisions": tally.pair_collisions,
        "wall_collisions": tally.wall_collisions,
        "events": tally.events,
        "seconds": seconds,
        "collisions_per_s": tally.pair_collisions / seconds if seconds > 0 else None,
        "kT": kt,
        "compressibility": 1.0 + tally.virial / (dim * nkt * t) if nkt > 0 and t > 0 else None,
        "collision_rate": 2.0 * tally.pair_collisions / (n * t) if t > 0 else 0.0,
        "energy_drift": (energy - energy_start) / energy_start if energy_start != 0 else 0.0,
        "energy_lost_in_collisions": tally.energy_lost,
        "max_overlap": max(tally.max_contact_overlap, world.max_overlap()) / (2.0 * world.radius),
        "bytes_per_body": world.nbytes / n,
    }
    if not world.periodic:
        pressures = [
            tally.wall_momentum[w] / (volume / float(world.sides[w // 2])) / t if t > 0 else 0.0 for w in range(2 * dim)
        ]
        pressure = sum(pressures) / len(pressures)
        report["compressibility_walls"] = pressure * volume / nkt if nkt > 0 else None
        report["wall_momentum"] = list(tally.wall_momentum)
    return report


class _Guard:
    """What the run calls between chunks of events: the caller's ``between`` (e.g. a look for
    Ctrl-C), then two checks that end a run which cannot go on, with OutOfRangeError: speeds
    beyond ``limits.MAX_GAS_SPEED`` (with e > 1 every collision adds energy), and time that no
    longer advances (``STALL_EVENTS`` events at one instant: balls so fast that they cross their
    neighbour-list shell within the resolution of the time, or an inelastic collapse when
    ``tc = 0``; the loop would spin there for ever). Both read the state as stored (each ball at
    its own time), not moved to the present, so the run stays the same to the last bit."""

    def __init__(self, world: EventDrivenWorld, between: Callable[[], None] | None) -> None:
        self.world, self.between = world, between
        self.time, self.events = world.time, world.tally().events

    def __call__(self) -> None:
        if self.between is not None:
            self.between()
        world = self.world
        fastest = float(np.abs(world.F[:, L.V : L.V + world.dim]).max())
        if not fastest <= limits.MAX_GAS_SPEED:  # (NaN too)
            raise OutOfRangeError(
                f"the exact gas at t = {world.time:.6g}: speeds grew beyond {limits.MAX_GAS_SPEED:g} "
                f"(restitution {world.restitution:g} > 1 adds energy at every collision): too large to simulate"
            )
        events = world.tally().events
        if world.time > self.time:
            self.time, self.events = world.time, events
        elif events - self.events >= STALL_EVENTS:
            raise OutOfRangeError(
                f"the exact gas at t = {world.time:.6g}: time stopped advancing ({events - self.events:,} events "
                f"at one instant; speeds up to {fastest:.3g}: too fast for the resolution of the time, or an "
                "inelastic collapse with tc = 0): too large to simulate"
            )


def run_exact_gas(
    gas: ExactGas,
    sink: EventSink | None = None,
    world: EventDrivenWorld | None = None,
    between: Callable[[], None] | None = None,
) -> dict[str, Any]:
    """Run ``gas`` (built now unless ``world``, fresh from ``gas.world()``, is given) for
    ``gas.time`` and report: the JSON of ``collisionlab gas --mode exact``. ``between`` is called
    every :data:`CHUNK_EVENTS` events or so (a fraction of a second): it may raise to stop the
    run (the command line's Ctrl-C). A run whose speeds pass ``limits.MAX_GAS_SPEED``, or whose
    time stops advancing, stops with :class:`~collisionlab.errors.OutOfRangeError`."""
    gas = gas.checked()
    world = gas.world() if world is None else world
    energy_start = world.kinetic_energy() + world.potential_energy()
    began = time.perf_counter()
    # With e > 1 a collision can multiply a speed by up to 2 + e: GROWING_CHUNK_EVENTS of them
    # take a speed within the range no further than 1e100 * 12^32 ~ 1e135 (its square is finite).
    every = CHUNK_EVENTS if gas.restitution <= 1.0 else GROWING_CHUNK_EVENTS
    world.run(gas.time, sink, between=_Guard(world, between), every=every)
    seconds = time.perf_counter() - began
    report: dict[str, Any] = {
        "n": gas.n,
        "dim": gas.dim,
        "fraction": gas.fraction,
        "mode": "exact",
        "boundary": gas.boundary,
        "seed": gas.seed,
        "restitution": gas.restitution,
        "gravity": gas.gravity,
        "tc": gas.tc,
    }
    report.update(measure(world, energy_start, seconds))
    elastic_gas = gas.restitution == 1.0 and gas.gravity == 0.0
    report["compressibility_theory"] = ideal_compressibility(gas.fraction, gas.dim) if elastic_gas else None
    report["collision_rate_enskog"] = (
        enskog_collision_rate(gas.fraction, gas.dim, gas.radius, gas.mass, report["kT"]) if elastic_gas else None
    )
    return report
