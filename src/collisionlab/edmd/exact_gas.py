"""The exact gas behind ``collisionlab gas --mode exact``: its settings (:class:`ExactGas`: balls,
box, packing fraction, restitution, gravity, species) and the start they make (a lattice, or a
dense mixture spread apart), as an event-driven world or as a scenario for the engine's world.
What a run of it measures is :mod:`.observables`'.
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
from ..particles.scenarios import ball_volume
from ..tolerances import START_GAP
from ..validate import finite_number, non_negative, positive, whole_number
from ..vector import Vector3D
from .spread import SPREAD_SWEEPS, spread_apart
from .start import box_side, gaussian_velocities, lattice, lattice_sites
from .world import EventDrivenWorld

__all__ = [
    "BOUNDARIES",
    "DEFAULT_TC",
    "FRACTION_SUM_TOLERANCE",
    "FRAMES",
    "SPECIES_FORM",
    "ExactGas",
    "Species",
    "parse_species",
    "species_counts",
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
