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

A mixture (:class:`Species`) reports the same, and per species ``kT_a = sum_a m v^2 / (d N_a)``
(equipartition: every species at the same ``kT``), and per ordered pair of species ``(a, b)``
how often one ball of ``a`` hits a ball of ``b``, beside Enskog's rate
(:func:`.theory.enskog_pair_rates`); ``Z`` against BMCSL (3D) or Santos, Yuste and Lopez de
Haro's equation (2D), :func:`.theory.mixture_compressibility`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import NDArray

from .. import limits
from ..errors import InvalidInputError
from ..model import BodyBlock, Box, Scenario, Settings
from ..particles.scenarios import ball_volume
from ..tolerances import START_GAP
from ..validate import finite_number, non_negative, positive, whole_number
from ..vector import Vector3D
from .spread import SPREAD_SWEEPS, spread_apart
from .start import box_side, gaussian_velocities, lattice, lattice_sites
from .theory import enskog_collision_rate, enskog_pair_rates, ideal_compressibility, mixture_compressibility
from .world import EventDrivenWorld, EventSink

if TYPE_CHECKING:
    from ..engine.world import World
    from ..trajectory import FrameWriter, Types
    from .structure import Observer

__all__ = [
    "BOUNDARIES",
    "DEFAULT_TC",
    "FRACTION_SUM_TOLERANCE",
    "FRAMES",
    "SPECIES_FORM",
    "Checkpointer",
    "ExactGas",
    "Species",
    "frame_times",
    "measure",
    "observer_for",
    "parse_species",
    "run_end",
    "run_exact_gas",
    "run_on_world",
    "species_counts",
    "species_report",
    "trajectory_types",
]

#: ``collisionlab gas --boundary``: hard walls, or a periodic box.
BOUNDARIES: tuple[str, ...] = ("walls", "periodic")
#: Time units (radius 1, mass 1, kT 1: a typical ball moves 0.01 radius in it). The TC model's
#: ``t_c`` when ``e < 1`` or under gravity and none is given; see :mod:`.loop` for what it does.
DEFAULT_TC = 0.01
#: Steps of an exact gas's scenario: the world brings every ball to the end of each step it is
#: asked for (a frame), and takes as many steps in one call as fill a fraction of a second.
FRAMES = 1000
#: How far the species' number fractions may sum from 1 (numbers typed with six or more
#: decimals, 1/3 as 0.333333); they are then divided by their sum.
FRACTION_SUM_TOLERANCE = 1e-6
#: ``collisionlab gas --species``: one species, its fields separated by colons.
SPECIES_FORM = "NAME:FRACTION:RADIUS[:MASS]"
#: A mixture's calls of the loop: each runs at least this long (then Python looks at progress
#: and signals), the steps of one call doubling until it does.
CHUNK_SECONDS = 0.05


@dataclass(frozen=True)
class Species:
    """One kind of ball of a mixture: ``fraction`` of the balls by number, of ``radius`` and
    ``mass`` (``None``: proportional to the ball's area (2D) or volume (3D), a ball of radius 1
    weighing 1: ``mass = radius^dim``, the default ball's mass at the default radius)."""

    name: str
    fraction: float
    radius: float
    mass: float | None = None

    def checked(self) -> Species:
        """The same species, validated (:class:`InvalidInputError`, field ``species``)."""
        if not self.name or not self.name.isprintable() or ":" in self.name:
            raise InvalidInputError(
                "species", f"a name must be printable and without ':' ({SPECIES_FORM})", got=self.name
            )
        fraction = _species_number(self.fraction, "fraction", self.name)
        if not 0.0 < fraction <= 1.0:
            raise InvalidInputError(
                "species", f"{self.name}: FRACTION must be in (0, 1] (expected {SPECIES_FORM})", got=fraction
            )
        radius = _species_number(self.radius, "radius", self.name)
        if radius <= 0.0:
            raise InvalidInputError("species", f"{self.name}: RADIUS must be > 0 (expected {SPECIES_FORM})", got=radius)
        mass = None if self.mass is None else _species_number(self.mass, "mass", self.name)
        if mass is not None and mass <= 0.0:
            raise InvalidInputError("species", f"{self.name}: MASS must be > 0 (expected {SPECIES_FORM})", got=mass)
        return Species(self.name, fraction, radius, mass)

    def mass_in(self, dim: int) -> float:
        """The mass of one ball: :attr:`mass`, or ``radius^dim`` (see the class)."""
        return self.mass if self.mass is not None else self.radius**dim


def _species_number(value: object, what: str, name: str) -> float:
    try:
        return finite_number(value, "species")
    except InvalidInputError:
        raise InvalidInputError(
            "species", f"{name}: {what.upper()} must be a finite number (expected {SPECIES_FORM})", got=value
        ) from None


def parse_species(text: str) -> Species:
    """One ``--species`` value, ``NAME:FRACTION:RADIUS[:MASS]``, as a checked :class:`Species`.

    >>> parse_species("big:0.5:1")
    Species(name='big', fraction=0.5, radius=1.0, mass=None)
    >>> parse_species("small:0.5:0.5:2").mass
    2.0
    """
    fields = text.split(":")
    if len(fields) not in (3, 4):
        raise InvalidInputError("species", f"expected {SPECIES_FORM}: 3 or 4 fields", got=text)
    numbers: list[float] = []
    for what, field in zip(("fraction", "radius", "mass"), fields[1:], strict=False):
        try:
            numbers.append(float(field))
        except ValueError:
            raise InvalidInputError(
                "species", f"{what.upper()} must be a number (expected {SPECIES_FORM})", got=text
            ) from None
    return Species(fields[0], *numbers).checked()


def species_counts(species: tuple[Species, ...], n: int) -> list[int]:
    """Balls of each species among ``n``: ``fraction * n`` rounded so that they sum to ``n``
    (the largest remainders get the balls left over; ties to the first).

    >>> species_counts((Species("a", 0.5, 1.0), Species("b", 0.5, 0.5)), 5)
    [3, 2]
    """
    exact = [sp.fraction * n for sp in species]
    counts = [math.floor(x) for x in exact]
    left = n - sum(counts)
    order = sorted(range(len(species)), key=lambda k: (-(exact[k] - counts[k]), k))
    for k in order[:left]:
        counts[k] += 1
    return counts


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
    #: A mixture (empty: ``n`` balls of ``radius`` and ``mass``); ``fraction`` is then the
    #: packing fraction of all the species together.
    species: tuple[Species, ...] = ()

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
        species = self._species_checked(n)
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
            species=species,
        )

    def _species_checked(self, n: int) -> tuple[Species, ...]:
        """The species validated, names unique, fractions summing to 1 (then divided by their
        sum) and each with at least one ball among ``n``."""
        if not self.species:
            return ()
        species = tuple(sp.checked() for sp in self.species)
        names = [sp.name for sp in species]
        twice = sorted({name for name in names if names.count(name) > 1})
        if twice:
            raise InvalidInputError(
                "species", f"each NAME once (expected {SPECIES_FORM}, repeated)", got=", ".join(twice)
            )
        total = math.fsum(sp.fraction for sp in species)
        if abs(total - 1.0) > FRACTION_SUM_TOLERANCE:
            raise InvalidInputError(
                "species", f"the FRACTIONs must sum to 1, within {FRACTION_SUM_TOLERANCE:g} ({SPECIES_FORM})", got=total
            )
        species = tuple(Species(sp.name, sp.fraction / total, sp.radius, sp.mass) for sp in species)
        for sp, count in zip(species, species_counts(species, n), strict=True):
            if count == 0:
                raise InvalidInputError("species", f"{sp.name}: fraction {sp.fraction:g} of {n:,} balls is no ball")
        return species

    def mixture(self) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64], list[int]]:
        """A checked mixture's balls: each one's species (seeded, shuffled), radius and mass, and
        the count of each species."""
        counts = species_counts(self.species, self.n)
        kinds = np.repeat(np.arange(len(counts)), counts)
        # A stream of its own: the lattice's sites and the velocities use the seed's first.
        np.random.default_rng([self.seed, 1]).shuffle(kinds)
        radii = np.array([sp.radius for sp in self.species])[kinds]
        masses = np.array([sp.mass_in(self.dim) for sp in self.species])[kinds]
        return kinds, radii, masses, counts

    def _mixture_start(self, radii: NDArray[np.float64]) -> tuple[NDArray[np.float64], float]:
        """Sites for a mixture and the box side: a lattice whose spacing exceeds the largest
        diameter, in the box that holds all the balls at :attr:`fraction`; where that lattice
        would overlap, its sites in that box spread apart (:mod:`.spread`)."""
        largest = float(radii.max())
        volume = float(sum(ball_volume(float(r), self.dim) for r in radii))
        side = (volume / self.fraction) ** (1.0 / self.dim)
        # the lattice of balls of the largest radius in that box: its packing fraction
        as_largest = self.n * ball_volume(largest, self.dim) / side**self.dim
        side = box_side(self.n, self.dim, as_largest, largest)  # the same side, as the lattice rounds it
        periodic = self.boundary == "periodic"
        try:
            return lattice(self.n, self.dim, as_largest, largest, periodic, self.seed), side
        except InvalidInputError:
            pass
        if periodic and side < 8.0 * largest:
            raise InvalidInputError(
                "fraction",
                f"too dense to start this mixture: a periodic box must be at least 4 largest diameters wide "
                f"({side:.3g} for {self.n:,} balls; more balls)",
                got=self.fraction,
            )
        positions, _ = lattice_sites(self.n, self.dim, side, largest, periodic, self.seed)
        if spread_apart(positions, radii, side, periodic, START_GAP, SPREAD_SWEEPS) < 0:
            raise InvalidInputError(
                "fraction",
                f"too dense to start this mixture: spread apart from a lattice for {SPREAD_SWEEPS:,} sweeps, its "
                "balls still overlap (lower --fraction)",
                got=self.fraction,
            )
        return positions, side

    def mixture_velocities(self, masses: NDArray[np.float64]) -> NDArray[np.float64]:
        """Seeded Gaussian velocities of variance ``kT / m`` per ball, the total momentum zero,
        scaled so that the kinetic energy is exactly ``dim N kT / 2``."""
        v = np.random.default_rng(self.seed).normal(0.0, 1.0, size=(self.n, self.dim)) / np.sqrt(masses)[:, None]
        if self.n > 1:
            v -= (masses @ v) / masses.sum()
        energy = 0.5 * float(np.einsum("i,ij,ij->", masses, v, v))
        if energy > 0.0:
            v *= math.sqrt(0.5 * self.dim * self.n * self.kt / energy)
        return v

    def scenario(self, frames: int = FRAMES) -> Scenario:
        """The gas as a scenario: the balls as one block named ``ball`` in a box ``[0, L]`` of
        walls or periodic, ``mode = "exact"``: the engine's world runs it event by event
        (:mod:`collisionlab.engine.event_stepper`), ``frames`` steps of ``time / frames``.
        Not for a mixture: the engine's event-driven scenarios hold balls of one radius and
        mass, and a mixture runs on :meth:`world` (:func:`run_exact_gas` does it)."""
        s = self.checked()
        if s.species:
            raise InvalidInputError("species", "a mixture runs on ExactGas.world(), not as a scenario")
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
        if s.species:
            kinds, radii, masses, _ = s.mixture()
            positions, side = s._mixture_start(radii)
            return EventDrivenWorld(
                positions,
                s.mixture_velocities(masses),
                [side] * s.dim,
                radius=radii,
                mass=masses,
                species=kinds,
                restitution=s.restitution,
                gravity=s.gravity,
                tc=s.tc or 0.0,
                periodic=periodic,
            )
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
        # in diameters: of the smallest ball in a mixture
        "max_overlap": max(tally.max_contact_overlap, world.max_overlap())
        / (2.0 * (float(world.radii.min()) if world.mixed else world.radius)),
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
    sink: EventSink | None = None,
    balls: EventDrivenWorld | None = None,
) -> dict[str, Any]:
    """Run ``gas`` on the engine's world (``world``, fresh from ``World(gas.scenario())``, or one
    made now) for ``gas.time`` and report: the JSON of ``collisionlab gas --mode exact``.
    ``between(done, total)`` is called between chunks of steps (progress, Ctrl-C). With
    ``write_frame``, ``frames`` frames at equal times are written through it
    (:func:`collisionlab.trajectory.advance_in_frames`: ``frames - 1`` must divide the
    scenario's steps, see :func:`~collisionlab.trajectory.steps_for_frames`). ``calling`` makes
    each compiled call (:meth:`World.advance <collisionlab.engine.world.World.advance>`).

    A mixture (``gas.species``) runs on its :class:`EventDrivenWorld` alone, the same loop
    (its report, pair rates and theory, is the world's own): ``world`` does not apply,
    ``balls`` is its world if made already (fresh from ``gas.world()``), ``sink`` receives its
    collisions (:meth:`EventDrivenWorld.run`'s blocks; the engine's world streams a scenario's
    itself), and ``frames`` frames are written at the times :func:`frame_times` (``write_frame``
    made for :func:`trajectory_types`)."""
    from ..engine.event_stepper import EventDrivenStepper
    from ..engine.world import World

    gas = gas.checked()
    if gas.species:
        world_of_balls = gas.world() if balls is None else balls
        return run_on_world(gas, world_of_balls, between, calling, sink, frames=frames, write_frame=write_frame)
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
    report: dict[str, Any] = _settings_report(gas)
    report.update(measure(balls, energy_start, seconds))
    report["bytes_per_body"] = world.nbytes() / gas.n
    elastic_gas = gas.restitution == 1.0 and gas.gravity == 0.0
    report["compressibility_theory"] = ideal_compressibility(gas.fraction, gas.dim) if elastic_gas else None
    report["collision_rate_enskog"] = (
        enskog_collision_rate(gas.fraction, gas.dim, gas.radius, gas.mass, report["kT"]) if elastic_gas else None
    )
    return report


def run_end(time: float) -> float:
    """The time a run of ``time`` ends at: :data:`FRAMES` steps of ``time / FRAMES``, as the
    engine steps a scenario (it may differ from ``time`` in the last bit)."""
    return FRAMES * (time / FRAMES)


#: Saves a run: called with the total energy at time 0 and the loop's seconds so far, between
#: two calls of the loop (the world as stored, never brought to one time before it).
Checkpointer = Callable[[float, float], None]


def frame_times(time: float, frames: int) -> list[float]:
    """The times of ``frames`` trajectory frames over a run of ``time`` on an event-driven world
    (:func:`run_on_world`): ``end k / (frames - 1)``, ``k = 0 .. frames - 1``, ``end`` the run's
    :func:`run_end` (the last one exactly); one frame: the end.

    >>> frame_times(2.0, 5), frame_times(2.0, 1)
    ([0.0, 0.5, 1.0, 1.5, 2.0], [2.0])
    """
    end = run_end(time)
    if frames <= 1:
        return [end]
    return [end * k / (frames - 1) for k in range(frames - 1)] + [end]


def trajectory_types(gas: ExactGas) -> Types:
    """The balls of a checked ``gas`` as a trajectory names them
    (:class:`collisionlab.trajectory.Types`): a mixture's species in the order given, each ball
    its own; one kind of ball: type ``A`` of :attr:`ExactGas.radius`."""
    from ..trajectory import Types

    if not gas.species:
        return Types.one_kind(gas.n, gas.radius)
    kinds, radii, _, _ = gas.mixture()
    return Types(tuple(sp.name for sp in gas.species), kinds.astype(np.int64), radii)


def run_on_world(
    gas: ExactGas,
    balls: EventDrivenWorld,
    between: Callable[[int, int], None] | None = None,
    calling: Callable[[Callable[[], None]], None] | None = None,
    sink: EventSink | None = None,
    *,
    energy_start: float | None = None,
    seconds: float = 0.0,
    every: float | None = None,
    checkpoint: Checkpointer | None = None,
    observer: Observer | None = None,
    frames: int = 0,
    write_frame: FrameWriter | None = None,
) -> dict[str, Any]:
    """Run a checked ``gas`` (one kind of ball or a mixture) on its :class:`EventDrivenWorld`
    ``balls`` from its present time to :func:`run_end` of ``gas.time``, in calls ending at the
    ``FRAMES`` step ends of ``time / FRAMES`` (as the engine steps a scenario: the same
    result, to the last bit) of at least :data:`CHUNK_SECONDS` each, then measure it: the
    report of :func:`run_exact_gas`.

    A run continued from a checkpoint passes its ``energy_start`` (the total energy at time 0;
    ``None``: the world is fresh, at time 0) and the loop's ``seconds`` so far. ``checkpoint``
    is called at every multiple of ``every`` (simulated time) before the end, and at the end,
    before anything is measured (measuring brings the bodies to one time). Where the calls of
    the loop end does not change the run (:meth:`EventDrivenWorld.run`), so a run checkpointed
    or not, or continued from any of its checkpoints, ends the same to the last bit.

    ``observer`` (:class:`.structure.Observer`, made for this world and run) is stopped at as
    it asks (its samples, and the stops that unwrap positions between them), which does not
    change the run either; its fields (``rdf``, ``msd``, ...) join the report.

    ``write_frame`` (:class:`collisionlab.trajectory.FrameWriter`) is given ``frames`` frames,
    at the times :func:`frame_times` (step: the frame's index; each ball where :meth:`state`
    puts it), stopping there as the observer does: the run is the same with them or without."""
    import time

    from .guard import RunGuard

    guard = RunGuard(balls)
    if energy_start is None:
        energy_start = balls.kinetic_energy() + balls.potential_energy()  # (at time 0: moves nothing)
    dt = gas.time / FRAMES
    end = run_end(gas.time)
    now = balls.time
    if end < now:
        raise InvalidInputError("time", f"must be at least the run's present time {now!r}", got=gas.time)
    done = min(FRAMES, max(0, int(now // dt)))  # step ends passed already
    while done < FRAMES and (done + 1) * dt <= now:
        done += 1
    interval = math.inf if every is None or checkpoint is None else every
    saves = math.floor(now / interval) + 1 if math.isfinite(interval) else 1  # the next at saves * interval
    while saves * interval <= now:
        saves += 1
    stops = frame_times(gas.time, frames) if write_frame is not None and frames > 0 else []
    shot = 0  # frames written
    while shot < len(stops) and stops[shot] <= now:  # (a fresh world: the start's)
        assert write_frame is not None
        write_frame(shot, balls.time, *balls.state())
        shot += 1
    chunk = 1
    while done < FRAMES:
        step = min(chunk, FRAMES - done)
        until = (done + step) * dt
        save = saves * interval <= until and saves * interval < end
        if save:
            until = saves * interval
        look = observer is not None and observer.next_stop() <= until
        if observer is not None and look:
            until = observer.next_stop()
            save = save and saves * interval <= until
        shoot = shot < len(stops) and stops[shot] <= until
        if shoot:
            until = stops[shot]
            save = save and saves * interval <= until
            look = look and observer is not None and observer.next_stop() <= until

        def work(until: float = until) -> None:
            balls.run(until, sink, bring=False, between=guard, every=guard.every)

        started = time.perf_counter()
        if calling is None:
            work()
        else:
            calling(work)
        took = time.perf_counter() - started
        seconds += took
        if until == (done + step) * dt:
            done += step
        if observer is not None and look:
            observer.stop()
        if shoot and write_frame is not None:
            write_frame(shot, balls.time, *balls.state())
            shot += 1
        if save and checkpoint is not None:  # (a finite interval: there is one)
            checkpoint(energy_start, seconds)
            saves += 1
        if between is not None:  # after every call, a checkpoint's too: signals are looked at here
            between(done, FRAMES)
        if took < CHUNK_SECONDS:
            chunk *= 2
    if checkpoint is not None:
        checkpoint(energy_start, seconds)
    report: dict[str, Any] = _settings_report(gas)
    report.update(measure(balls, energy_start, seconds))
    elastic_gas = gas.restitution == 1.0 and gas.gravity == 0.0
    if gas.species:
        report.update(species_report(gas, balls, report["kT"]))
    else:  # as run_exact_gas reports one kind of ball
        report["compressibility_theory"] = ideal_compressibility(gas.fraction, gas.dim) if elastic_gas else None
        report["collision_rate_enskog"] = (
            enskog_collision_rate(gas.fraction, gas.dim, gas.radius, gas.mass, report["kT"]) if elastic_gas else None
        )
    if observer is not None:
        one_kind = elastic_gas and not gas.species
        report.update(observer.report(report["kT"], gas.fraction, gas.mass if one_kind else None))
    return report


def observer_for(gas: ExactGas, balls: EventDrivenWorld, observe: tuple[str, ...], samples: int) -> Observer:
    """An :class:`.structure.Observer` of ``observe`` (names of
    :data:`.structure.OBSERVABLES`) for a checked ``gas`` run on its fresh world ``balls``:
    ``samples`` equal times to the run's end, the species named as given (one kind: ``A``)."""
    from .structure import Observer

    if gas.species:
        kinds = gas.mixture()[0]
        names = [sp.name for sp in gas.species]
    else:
        kinds, names = np.zeros(gas.n, dtype=np.int64), ["A"]
    return Observer(balls, run_end(gas.time), samples, "rdf" in observe, "msd" in observe, kinds, names)


def species_report(gas: ExactGas, world: EventDrivenWorld, kt: float) -> dict[str, Any]:
    """A mixture's own fields of the report: ``compressibility_theory`` and
    ``collision_rate_enskog`` for the mixture (elastic, no gravity; else ``None``), ``species``
    (each one's name, count, radius, mass and kT) and ``pair_collision_rates`` (per ordered pair
    ``(a, b)``: the collisions between the two species, ``rate`` = how often one ball of ``a``
    hits a ball of ``b`` per unit time, and Enskog's ``rate_enskog``). A species' ``kT`` is
    ``2 <E_a> / (d N_a)``, ``<E_a>`` its kinetic energy averaged over the run (exact: it changes
    only at collisions), or under gravity the end's."""
    kinds, _, _, counts = gas.mixture()
    if gas.gravity == 0.0:  # averaged over the run (a snapshot of N_a balls scatters by sqrt(2 / (d N_a)))
        energies = world.species_mean_energy().tolist()
    else:  # the energy changes between collisions too: the end's
        velocities = world.velocities
        energy = 0.5 * world.masses * np.einsum("ij,ij->i", velocities, velocities)
        energies = [float(energy[kinds == k].sum()) for k in range(len(counts))]
    t = world.time
    tally = world.tally()
    dim = gas.dim
    fractions = [count / gas.n for count in counts]
    diameters = [2.0 * sp.radius for sp in gas.species]
    species_masses = [sp.mass_in(dim) for sp in gas.species]
    elastic_gas = gas.restitution == 1.0 and gas.gravity == 0.0
    rates = enskog_pair_rates(fractions, diameters, species_masses, gas.fraction, dim, kt) if elastic_gas else None
    pairs = []
    for a, first in enumerate(gas.species):
        for b, second in enumerate(gas.species):
            # a ball of a in a collision with a ball of b (counted for each of a's: twice if a = b)
            hits = tally.species_collisions[a][b]
            pairs.append(
                {
                    "species": [first.name, second.name],
                    "collisions": hits // 2 if a == b else hits,
                    "rate": hits / (counts[a] * t) if t > 0 else 0.0,
                    "rate_enskog": rates[a][b] if rates is not None else None,
                }
            )
    return {
        "compressibility_theory": mixture_compressibility(fractions, diameters, gas.fraction, dim)
        if elastic_gas
        else None,
        "collision_rate_enskog": sum(x * sum(row) for x, row in zip(fractions, rates, strict=True))
        if rates is not None
        else None,
        "bytes_per_body": world.nbytes / gas.n,
        "species": [
            {
                "name": sp.name,
                "count": count,
                "radius": sp.radius,
                "mass": sp.mass_in(dim),
                "kT": 2.0 * energies[k] / (dim * count),
            }
            for k, (sp, count) in enumerate(zip(gas.species, counts, strict=True))
        ],
        "pair_collision_rates": pairs,
    }


def _settings_report(gas: ExactGas) -> dict[str, Any]:
    """The head of a gas run's report: the settings it ran with."""
    return {
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
