"""Every tunable of a world in one typed object, passed to the world (never baked into kernels)."""

from __future__ import annotations

from dataclasses import dataclass

from ..tolerances import CONTACT_MARGIN, CONTACT_SLOP, REST_SPEED, SOLVER_MARGIN
from ..validate import non_negative, positive, whole_number

__all__ = [
    "COMPILE_ABOVE",
    "DEFAULT_PASSES",
    "DEFAULT_SETTLE_PASSES",
    "DEFAULT_TC_FRACTION",
    "SOLVE_COMPILE_ABOVE",
    "WorldParams",
]

#: Most sweeps over a step's contacts, for impulses and again for push-apart. A sweep that
#: changes nothing ends them early, so a dilute gas makes about two; a resting heap needs several
#: so that a ball pressed between a neighbour and the floor is pushed out within the step.
DEFAULT_PASSES = 8

#: Most sweeps of impulses per step in a world with gravity while one still changes some body's
#: speed by more than ``rest_speed`` (Forward Euler): a column of 10 spheres needs about 100 to
#: settle exactly (its Gauss-Seidel sweeps pass the floor's push up one ball at a time); with the
#: 8 of ``DEFAULT_PASSES`` it sank 1.6 J of 490.5 J in 10 s and shook (0.8 J), with these it sinks
#: 0.09 J (2.6 mJ of motion left). A pile sweeps this many every step, so this is also its cost
#: (the column's 1,000 steps in the kernels' Python form: 4 s with 8, 13 s with these).
DEFAULT_SETTLE_PASSES = 64

#: The TC model's time (event-driven stepper) as a fraction of the time a typical ball takes to
#: cross its radius: the value ``collisionlab gas --mode exact`` uses (0.01 in units of radius 1
#: and unit speed), small enough that dilute collisions never feel it (Luding and McNamara 1998).
DEFAULT_TC_FRACTION = 0.01

#: Body-steps (bodies x steps) above which a world runs the compiled kernels; below it, the same
#: kernels run as Python (the lab's cases never wait for a compiler).
COMPILE_ABOVE = 200_000

#: The same for a world whose contacts are solved (``contacts = "solve"``): its Python form
#: costs about a thousand times a Forward Euler body-step (bench/README.md, "Piles"), so above
#: this a run would wait longer in Python than most do for the kernels to load.
SOLVE_COMPILE_ABOVE = 1_000


@dataclass(frozen=True)
class WorldParams:
    """How a world resolves contacts. Units: metres and metres per second.

    ``slop``: the gap push-apart leaves between two overlapping shapes, so a resolved pair is
    not found again next step. ``solver_margin``: impulses act on pairs closer than this, not
    only overlapping ones (a stack left ``slop`` apart stays supported). ``contact_margin``: a
    pair that collided stays "in contact" (its next impulses are not new events) until it is
    farther apart than this. ``rest_speed``: approaches slower than this get e = 0 in a world
    with gravity (without it nothing rests, and a slow graze is a true collision).
    ``passes``: most sweeps of impulses, and of push-apart, per step. ``settle_passes``: most
    sweeps of impulses per step in a Forward Euler world with gravity, past ``passes`` only while
    a sweep still changes some speed by more than ``rest_speed``. ``compiled``: ``None``
    decides by size (:data:`COMPILE_ABOVE`, :data:`SOLVE_COMPILE_ABOVE`), ``True``/``False``
    force it. ``tc_fraction``: the event-driven stepper's TC time, when the scenario gives none,
    as this fraction of the time a typical ball takes to cross its radius
    (:func:`~collisionlab.engine.event_stepper.default_tc`).

    >>> WorldParams().passes
    8
    >>> WorldParams(passes=0)
    Traceback (most recent call last):
    ...
    collisionlab.errors.InvalidInputError: passes: must be a whole number >= 1 (got 0)
    """

    slop: float = CONTACT_SLOP
    solver_margin: float = SOLVER_MARGIN
    contact_margin: float = CONTACT_MARGIN
    rest_speed: float = REST_SPEED
    passes: int = DEFAULT_PASSES
    settle_passes: int = DEFAULT_SETTLE_PASSES
    compiled: bool | None = None
    tc_fraction: float = DEFAULT_TC_FRACTION

    def __post_init__(self) -> None:
        object.__setattr__(self, "slop", non_negative(self.slop, "slop"))
        object.__setattr__(self, "solver_margin", non_negative(self.solver_margin, "solver_margin"))
        object.__setattr__(self, "contact_margin", positive(self.contact_margin, "contact_margin"))
        object.__setattr__(self, "rest_speed", non_negative(self.rest_speed, "rest_speed"))
        object.__setattr__(self, "passes", whole_number(self.passes, "passes", minimum=1))
        object.__setattr__(self, "settle_passes", whole_number(self.settle_passes, "settle_passes", minimum=1))
        object.__setattr__(self, "tc_fraction", non_negative(self.tc_fraction, "tc_fraction"))
