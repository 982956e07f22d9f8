"""The record of a run: frames, collision events, skipped contacts, the ledger and a summary.

One record feeds every output (table, CSV, JSON, plots), so nothing is simulated twice. A
collision event, and the events of a compiled run held as arrays until read, are
:mod:`.collision_events`' (importable from here too).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal, Protocol

import numpy as np
from numpy.typing import NDArray

from .built_sequence import BuiltSequence, SequenceChain
from .collision_events import CollisionEvent, EventBlock, json_vector  # the first two importable from here too
from .extras import require
from .vector import Vector3D

if TYPE_CHECKING:
    import pandas
    from matplotlib.figure import Figure

    from .model import Scenario

__all__ = [
    "BodyState",
    "CollisionEvent",
    "EventBlock",
    "Frame",
    "FrameBodies",
    "Ledger",
    "RunObserver",
    "RunRecord",
    "SkippedContact",
]


def _count(n: int, singular: str, plural: str | None = None) -> str:
    return f"{n:,} {singular if n == 1 else plural or singular + 's'}"


@dataclass(frozen=True)
class BodyState:
    name: str
    position: Vector3D
    velocity: Vector3D


class FrameBodies(BuiltSequence[BodyState]):
    """A frame's bodies held as arrays (``positions`` and ``velocities``, ``(n, 3)``, owned), each
    :class:`BodyState` built only when read: a world of thousands of bodies writes its frames
    from the arrays (:meth:`Frame.to_dict`, the table and CSV writers) without making millions of
    vectors. Equal to any sequence of the same body states.

    >>> bodies = FrameBodies(("a",), np.array([[1.0, 2.0, 0.0]]), np.zeros((1, 3)))
    >>> bodies[0].position, bodies == (BodyState("a", Vector3D(1, 2, 0), Vector3D(0, 0, 0)),)
    (Vector3D(x=1.0, y=2.0, z=0.0), True)
    """

    def __init__(self, names: Sequence[str], positions: NDArray[np.float64], velocities: NDArray[np.float64]) -> None:
        self.names, self.positions, self.velocities = names, positions, velocities

    def __len__(self) -> int:
        return len(self.names)

    def _item(self, i: int) -> BodyState:
        return BodyState(self.names[i], Vector3D(*self.positions[i].tolist()), Vector3D(*self.velocities[i].tolist()))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Sequence):
            return NotImplemented
        return len(self) == len(other) and all(a == b for a, b in zip(self, other, strict=True))

    def __hash__(self) -> int:
        return hash(tuple(self))

    def __repr__(self) -> str:
        return repr(tuple(self))

    def dicts(self) -> list[dict[str, Any]]:
        """``Frame.to_dict``'s bodies, from the arrays (``+ 0.0``: no signed zero)."""
        positions, velocities = (self.positions + 0.0).tolist(), (self.velocities + 0.0).tolist()
        return [
            {"name": name, "position": x, "velocity": v}
            for name, x, v in zip(self.names, positions, velocities, strict=True)
        ]


@dataclass(frozen=True)
class Frame:
    """The state after ``step`` steps, at ``time`` seconds (step 0 is the start). ``bodies`` is
    a tuple, or a :class:`FrameBodies` from a world's arrays."""

    step: int
    time: float
    bodies: Sequence[BodyState]

    def to_dict(self) -> dict[str, Any]:
        bodies = self.bodies
        return {
            "step": self.step,
            "time": self.time + 0.0,
            "bodies": bodies.dicts()
            if isinstance(bodies, FrameBodies)
            else [
                {"name": b.name, "position": json_vector(b.position), "velocity": json_vector(b.velocity)}
                for b in bodies
            ],
        }


@dataclass(frozen=True)
class SkippedContact:
    """A contact that got no impulse, and why ("separating", "resting")."""

    step: int
    time: float
    bodies: tuple[str, str]
    reason: str

    def to_dict(self) -> dict[str, Any]:
        return {"step": self.step, "time": self.time + 0.0, "bodies": list(self.bodies), "reason": self.reason}


@dataclass
class Ledger:
    """Where energy went (J): total mechanical energy (kinetic + potential) at the start and the
    end, and the change put down to each cause. ``residual`` is what no cause explains
    (rounding); the causes are measured, phase by phase, not assumed."""

    kinetic_start: float = 0.0
    kinetic_end: float = 0.0
    potential_start: float = 0.0
    potential_end: float = 0.0
    momentum_start: Vector3D = field(default_factory=lambda: Vector3D(0, 0, 0))
    momentum_end: Vector3D = field(default_factory=lambda: Vector3D(0, 0, 0))
    collisions: float = 0.0
    integrator: float = 0.0
    push_apart: float = 0.0
    #: Metres: the deepest overlap the push-apart had to undo over the run (0 when no shapes
    #: ever overlapped at the end of a step's motion; rounding-level in exact mode).
    max_penetration: float = 0.0
    #: The loss predicted by theory for the collisions, sum of (1 - e^2)/2 * mu * v_n^2.
    collisions_predicted: float = 0.0

    @property
    def energy_start(self) -> float:
        return self.kinetic_start + self.potential_start

    @property
    def energy_end(self) -> float:
        return self.kinetic_end + self.potential_end

    @property
    def residual(self) -> float:
        return (self.energy_end - self.energy_start) - (self.collisions + self.integrator + self.push_apart)

    def to_dict(self) -> dict[str, Any]:
        return {
            "kinetic_start": self.kinetic_start,
            "kinetic_end": self.kinetic_end,
            "potential_start": self.potential_start,
            "potential_end": self.potential_end,
            "energy_start": self.energy_start,
            "energy_end": self.energy_end,
            "momentum_start": json_vector(self.momentum_start),
            "momentum_end": json_vector(self.momentum_end),
            "change_by_cause": {
                "collisions": self.collisions,
                "integrator": self.integrator,
                "push_apart": self.push_apart,
                "residual": self.residual,
            },
            "collisions_predicted": self.collisions_predicted,
            "max_penetration": self.max_penetration,
        }


class RunObserver(Protocol):
    """What a :meth:`World.run <collisionlab.engine.world.World.run>` tells as it happens, in
    order: :meth:`begin` (the record: title, settings, the warnings known at the start), then
    frames, events and warnings as they are produced, then :meth:`end` (the ledger is final).
    Events come in step order, each batch with the step the world has reached (a frame of that
    step may follow); a world hands them over as an :class:`EventBlock` (columns of numbers,
    events built only when read). The CLI's writers are observers, so nothing need be held until
    the end."""

    def begin(self, record: RunRecord) -> None: ...

    def frame(self, frame: Frame) -> None: ...

    def events(self, events: Sequence[CollisionEvent], skipped: Sequence[SkippedContact], reached: int) -> None: ...

    def warning(self, text: str) -> None: ...

    def end(self, record: RunRecord) -> None: ...


@dataclass
class RunRecord:
    """Everything a run produced. ``frames`` holds every recorded step (see ``World.run``)."""

    title: str
    mode: str
    dt: float
    steps: int
    restitution: float
    gravity: Vector3D
    dims: int = 3
    frames: list[Frame] = field(default_factory=list)
    #: The collisions, earliest first: a list, or (from a world) blocks of arrays whose events are
    #: built only when read, so a pile's millions of impacts cost no Python objects unless looked at.
    events: Sequence[CollisionEvent] = field(default_factory=SequenceChain)
    skipped: list[SkippedContact] = field(default_factory=list)
    ledger: Ledger = field(default_factory=Ledger)
    warnings: list[str] = field(default_factory=list)
    #: The scenario that was run (its shapes and masses draw the plot); ``None`` when unknown.
    scenario: Scenario | None = field(default=None, repr=False, compare=False)
    #: Collisions counted by the world, kept or not (a run streamed to an observer with
    #: ``keep=False`` keeps no events, only this count; see :attr:`collision_total`).
    collision_count: int = 0
    #: Each static's total impulse on the moving bodies over the run (N s, by name), when the
    #: stepper measures it (the contact solver); ``None`` otherwise. Their sum balances momentum:
    #: ``P_end - P_start - M g T`` (``M`` the bodies of finite mass).
    static_impulses: dict[str, list[float]] | None = None
    #: How exact mode treated contacts (``Settings.contacts``): ``"events"`` or ``"solve"``.
    contacts: str = "events"
    #: An event-driven mixture's kinds of ball (one per ``[[gas]]`` table), each one's ``name``,
    #: ``count``, ``radius``, ``mass`` and ``kT`` measured (:meth:`EventDrivenStepper.species_report
    #: <collisionlab.engine.event_stepper.EventDrivenStepper.species_report>`); ``None`` otherwise.
    species: list[dict[str, Any]] | None = None

    @property
    def collision_total(self) -> int:
        """The run's collisions: those counted, or those held when the record was built by hand."""
        return max(self.collision_count, len(self.events))

    def __repr__(self) -> str:
        """Counts, not contents (a long run holds thousands of frames)."""
        bodies = len(self.frames[0].bodies) if self.frames else 0
        return (
            f"<RunRecord {self.title!r}: {self.dims}D, mode {self.mode}, {self.steps} steps of {self.dt:g} s, "
            f"{_count(bodies, 'body', 'bodies')}, {_count(len(self.frames), 'frame')}, "
            f"{_count(len(self.events), 'collision')}, {_count(len(self.skipped), 'skipped contact')}, "
            f"{_count(len(self.warnings), 'warning')}>"
        )

    def to_dataframe(self, table: Literal["frames", "events", "skipped"] = "frames") -> pandas.DataFrame:
        """A table of the run as a pandas ``DataFrame`` (pandas is optional: the ``pandas`` extra,
        ``pip install 'collisionlab[pandas]'``; without it, :class:`~collisionlab.extras.MissingExtraError`).

        ``"frames"``: one row per recorded step and body (long form; ``pivot`` gives one column
        per body): ``step, time, body, x, y, z, vx, vy, vz``. ``"events"``: one row per
        collision: ``step, time, body_a, body_b, static, normal_x..z, point_x..z,
        approach_speed, impulse, restitution, below_rest_threshold, mass_a, mass_b,
        kinetic_energy_before, kinetic_energy_after``. ``"skipped"``: ``step, time, body_a,
        body_b, reason``.
        """
        pd = require("pandas", "pandas", "pandas tables (RunRecord.to_dataframe)")
        if table == "frames":
            columns = ["step", "time", "body", "x", "y", "z", "vx", "vy", "vz"]
            rows: list[tuple[Any, ...]] = [
                (f.step, f.time, b.name, *b.position.as_tuple(), *b.velocity.as_tuple())
                for f in self.frames
                for b in f.bodies
            ]
        elif table == "events":
            columns = [
                "step", "time", "body_a", "body_b", "static", "normal_x", "normal_y", "normal_z",
                "point_x", "point_y", "point_z", "approach_speed", "impulse", "restitution",
                "below_rest_threshold", "mass_a", "mass_b", "kinetic_energy_before", "kinetic_energy_after",
            ]  # fmt: skip
            rows = [
                (
                    e.step,
                    e.time,
                    *e.bodies,
                    e.static,
                    *e.normal.as_tuple(),
                    *e.point.as_tuple(),
                    e.approach_speed,
                    e.impulse,
                    e.restitution,
                    e.below_rest_threshold,
                    *e.masses,
                    e.kinetic_energy_before,
                    e.kinetic_energy_after,
                )
                for e in self.events
            ]
        elif table == "skipped":
            columns = ["step", "time", "body_a", "body_b", "reason"]
            rows = [(s.step, s.time, *s.bodies, s.reason) for s in self.skipped]
        else:
            from .errors import InvalidInputError

            raise InvalidInputError("table", "must be one of frames, events, skipped", got=table)
        return pd.DataFrame.from_records(rows, columns=columns)

    def plot(self, scenario: Scenario | None = None, size: tuple[int, int] = (1400, 800)) -> Figure:
        """The picture of ``--plot`` (trajectories, energy, momentum) as a matplotlib ``Figure``;
        ``scenario`` defaults to the one that was run."""
        from .errors import InvalidInputError

        # The one import from below the pictures into them (issue 30): a record draws itself, and
        # only when asked, so matplotlib loads only then. Not a circle: the pictures read a run
        # through their own protocol (plotting/_run.py), never this file.
        from .plotting.static import draw_figure

        scenario = scenario or self.scenario
        if scenario is None:
            raise InvalidInputError("scenario", "this record does not know its scenario; pass plot(scenario)")
        return draw_figure(self, scenario, size)

    def _repr_png_(self) -> bytes | None:
        """Jupyter shows a record as its plot (when the record knows its scenario)."""
        if self.scenario is None or not self.frames:
            return None
        import io

        buffer = io.BytesIO()
        self.plot(size=(1100, 620)).savefig(buffer, format="png")
        return buffer.getvalue()

    def summary(self) -> dict[str, Any]:
        return {
            "collisions": self.collision_total,
            "steps": self.steps,
            "time": self.frames[-1].time if self.frames else 0.0,
            "momentum_start": json_vector(self.ledger.momentum_start),
            "momentum_end": json_vector(self.ledger.momentum_end),
            "kinetic_energy_start": self.ledger.kinetic_start,
            "kinetic_energy_end": self.ledger.kinetic_end,
            **({} if self.static_impulses is None else {"static_impulses": self.static_impulses}),
            **({} if self.species is None else {"species": self.species}),
        }

    def replay(self, observer: RunObserver) -> None:
        """Tell ``observer`` this record as :meth:`World.run <collisionlab.engine.world.World.run>`
        told it: each frame after the events up to its step."""
        observer.begin(self)
        events, skipped = self.events, self.skipped
        e = s = 0
        for frame in self.frames:
            e2, s2 = e, s
            while e2 < len(events) and events[e2].step <= frame.step:
                e2 += 1
            while s2 < len(skipped) and skipped[s2].step <= frame.step:
                s2 += 1
            if e2 > e or s2 > s:
                observer.events(events[e:e2], skipped[s:s2], frame.step)
            e, s = e2, s2
            observer.frame(frame)
        if e < len(events) or s < len(skipped):
            observer.events(events[e:], skipped[s:], self.steps)
        observer.end(self)

    def header_dict(self) -> dict[str, Any]:
        """The JSON form's first keys: ``title``, ``dims``, ``settings``."""
        return {
            "title": self.title,
            "dims": self.dims,
            "settings": {
                "mode": self.mode,
                "dt": self.dt,
                "steps": self.steps,
                "restitution": self.restitution,
                "gravity": json_vector(self.gravity),
                **({"contacts": self.contacts} if self.contacts != "events" else {}),
            },
        }

    def footer_dict(self) -> dict[str, Any]:
        """The JSON form's last keys: ``summary``, ``ledger``, ``warnings``."""
        return {
            "summary": self.summary(),
            "ledger": self.ledger.to_dict(),
            "warnings": list(self.warnings),
        }

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: ``frames``, ``events``, ``summary``, ``ledger`` and more."""
        return {
            **self.header_dict(),
            "frames": [f.to_dict() for f in self.frames],
            "events": [e.to_dict() for e in self.events],
            "skipped": [s.to_dict() for s in self.skipped],
            **self.footer_dict(),
        }
