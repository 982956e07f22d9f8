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
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

from .. import limits
from ..errors import InvalidInputError
from ..model import BodyBlock, Box, Scenario, Settings
from ..validate import non_negative, positive, whole_number
from ..vector import Vector3D
from .start import box_side, gaussian_velocities, lattice
from .theory import enskog_collision_rate, ideal_compressibility
from .world import EventDrivenWorld

if TYPE_CHECKING:
    from ..engine.world import World
    from ..trajectory import FrameWriter

__all__ = ["BOUNDARIES", "DEFAULT_TC", "FRAMES", "ExactGas", "measure", "run_exact_gas"]

#: ``collisionlab gas --boundary``: hard walls, or a periodic box.
BOUNDARIES: tuple[str, ...] = ("walls", "periodic")
#: Time units (radius 1, mass 1, kT 1: a typical ball moves 0.01 radius in it). The TC model's
#: ``t_c`` when ``e < 1`` or under gravity and none is given; see :mod:`.loop` for what it does.
DEFAULT_TC = 0.01
#: Steps of an exact gas's scenario: the world brings every ball to the end of each step it is
#: asked for (a frame), and takes as many steps in one call as fill a fraction of a second.
FRAMES = 1000


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
        if gravity > 0.0 and self.boundary == "periodic":
            raise InvalidInputError("gravity", "needs walls (a periodic box has no floor)", got=gravity)
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

    def scenario(self, frames: int = FRAMES) -> Scenario:
        """The gas as a scenario: the balls as one block named ``ball`` in a box ``[0, L]`` of
        walls or periodic, ``mode = "exact"``: the engine's world runs it event by event
        (:mod:`collisionlab.engine.event_stepper`), ``frames`` steps of ``time / frames``."""
        s = self.checked()
        periodic = s.boundary == "periodic"
        shape: Literal["circle", "sphere"] = "circle" if s.dim == 2 else "sphere"
        block = BodyBlock(
            "ball",
            shape,
            (s.radius,) * 3,
            lattice(s.n, s.dim, s.fraction, s.radius, periodic, s.seed),
            gaussian_velocities(s.n, s.dim, s.kt, s.mass, s.seed),
            s.mass,
        )
        side = box_side(s.n, s.dim, s.fraction, s.radius)
        settings = Settings(
            dt=s.time / frames,
            steps=frames,
            restitution=s.restitution,
            gravity=Vector3D(0.0, -s.gravity, 0.0),
            mode="exact",
            tc=s.tc,
        )
        box = Box((0.0,) * s.dim, (side,) * s.dim, "periodic" if periodic else "walls")
        return Scenario(settings, [block], title=f"exact gas of {s.n:,} {shape}s", box=box)

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


def run_exact_gas(
    gas: ExactGas,
    world: World | None = None,
    between: Callable[[int, int], None] | None = None,
    frames: int = 0,
    write_frame: FrameWriter | None = None,
    calling: Callable[[Callable[[], None]], None] | None = None,
) -> dict[str, Any]:
    """Run ``gas`` on the engine's world (``world``, fresh from ``World(gas.scenario())``, or one
    made now) for ``gas.time`` and report: the JSON of ``collisionlab gas --mode exact``.
    ``between(done, total)`` is called between chunks of steps (progress, Ctrl-C). With
    ``write_frame``, ``frames`` frames at equal times are written through it
    (:func:`collisionlab.trajectory.advance_in_frames`: ``frames - 1`` must divide the
    scenario's steps, see :func:`~collisionlab.trajectory.steps_for_frames`). ``calling`` makes
    each compiled call (:meth:`World.advance <collisionlab.engine.world.World.advance>`)."""
    from ..engine.event_stepper import EventDrivenStepper
    from ..engine.world import World

    gas = gas.checked()
    world = World(gas.scenario(), events=False) if world is None else world
    stepper = world.stepper
    if not isinstance(stepper, EventDrivenStepper):
        raise InvalidInputError("world", "must run the gas event by event (a world of gas.scenario())")
    balls = stepper.world
    energy_start = balls.kinetic_energy() + balls.potential_energy()
    remaining = world.scenario.settings.steps - world.step_index
    if write_frame is not None and frames > 0:
        from ..trajectory import advance_in_frames

        seconds = advance_in_frames(world, remaining, frames, write_frame, between, calling)
    else:
        seconds = world.advance(remaining, between, calling=calling)
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
    report.update(measure(balls, energy_start, seconds))
    report["bytes_per_body"] = world.nbytes() / gas.n
    elastic_gas = gas.restitution == 1.0 and gas.gravity == 0.0
    report["compressibility_theory"] = ideal_compressibility(gas.fraction, gas.dim) if elastic_gas else None
    report["collision_rate_enskog"] = (
        enskog_collision_rate(gas.fraction, gas.dim, gas.radius, gas.mass, report["kT"]) if elastic_gas else None
    )
    return report
