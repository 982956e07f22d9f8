"""The record of a run: frames, collision events, skipped contacts, the ledger and a summary.

One record feeds every output (table, CSV, JSON, plots), so nothing is simulated twice.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal, Protocol

from .vector import Vector3D

if TYPE_CHECKING:
    import pandas
    from matplotlib.figure import Figure

    from .model import Scenario

__all__ = ["BodyState", "CollisionEvent", "Frame", "Ledger", "RunObserver", "RunRecord", "SkippedContact"]


def _vec(v: Vector3D) -> list[float]:
    """``v`` as a list, ``-0.0`` written ``0.0`` (a signed zero reads as another number)."""
    return [v.x + 0.0, v.y + 0.0, v.z + 0.0]


def _count(n: int, singular: str, plural: str | None = None) -> str:
    return f"{n:,} {singular if n == 1 else plural or singular + 's'}"


@dataclass(frozen=True)
class BodyState:
    name: str
    position: Vector3D
    velocity: Vector3D


@dataclass(frozen=True)
class Frame:
    """The state after ``step`` steps, at ``time`` seconds (step 0 is the start)."""

    step: int
    time: float
    bodies: tuple[BodyState, ...]

    def to_dict(self) -> dict[str, Any]:
        return {
            "step": self.step,
            "time": self.time + 0.0,
            "bodies": [
                {"name": b.name, "position": _vec(b.position), "velocity": _vec(b.velocity)} for b in self.bodies
            ],
        }


@dataclass(frozen=True)
class CollisionEvent:
    """One resolved impact, with the working of the impulse (for ``--explain``).

    ``normal`` points from ``bodies[0]`` to ``bodies[1]``; ``approach_speed`` is
    ``v_n = (v_b - v_a) . n`` before (negative when approaching); ``impulse`` is
    ``j = -(1 + e) v_n / (1/m_a + 1/m_b)``. ``restitution`` is the e applied: 0 when the
    approach was slower than the rest threshold, and then ``below_rest_threshold`` is true
    (``REST_SPEED`` in :mod:`collisionlab.tolerances`). ``static`` says that ``bodies[0]`` is an
    obstacle (infinite mass).
    """

    step: int
    time: float
    bodies: tuple[str, str]
    static: bool
    normal: Vector3D
    point: Vector3D
    approach_speed: float
    impulse: float
    restitution: float
    masses: tuple[float, float]
    velocities_before: dict[str, Vector3D]
    velocities_after: dict[str, Vector3D]
    kinetic_energy_before: float
    kinetic_energy_after: float
    below_rest_threshold: bool = False

    def to_dict(self) -> dict[str, Any]:
        return {
            "step": self.step,
            "time": self.time + 0.0,
            "bodies": list(self.bodies),
            "static": self.static,
            "normal": _vec(self.normal),
            "point": _vec(self.point),
            "approach_speed": self.approach_speed + 0.0,
            "impulse": self.impulse + 0.0,
            "restitution": self.restitution + 0.0,
            "velocities_before": {k: _vec(v) for k, v in self.velocities_before.items()},
            "velocities_after": {k: _vec(v) for k, v in self.velocities_after.items()},
            "kinetic_energy_before": self.kinetic_energy_before + 0.0,
            "kinetic_energy_after": self.kinetic_energy_after + 0.0,
            "below_rest_threshold": self.below_rest_threshold,
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
            "momentum_start": _vec(self.momentum_start),
            "momentum_end": _vec(self.momentum_end),
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
    step may follow). The CLI's writers are observers, so nothing need be held until the end."""

    def begin(self, record: RunRecord) -> None: ...

    def frame(self, frame: Frame) -> None: ...

    def events(self, events: list[CollisionEvent], skipped: list[SkippedContact], reached: int) -> None: ...

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
    events: list[CollisionEvent] = field(default_factory=list)
    skipped: list[SkippedContact] = field(default_factory=list)
    ledger: Ledger = field(default_factory=Ledger)
    warnings: list[str] = field(default_factory=list)
    #: The scenario that was run (its shapes and masses draw the plot); ``None`` when unknown.
    scenario: Scenario | None = field(default=None, repr=False, compare=False)
    #: Collisions counted by the world, kept or not (a run streamed to an observer with
    #: ``keep=False`` keeps no events, only this count; see :attr:`collision_total`).
    collision_count: int = 0

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
        """A table of the run as a pandas ``DataFrame`` (pandas is optional: ``pip install pandas``).

        ``"frames"``: one row per recorded step and body (long form; ``pivot`` gives one column
        per body): ``step, time, body, x, y, z, vx, vy, vz``. ``"events"``: one row per
        collision: ``step, time, body_a, body_b, static, normal_x..z, point_x..z,
        approach_speed, impulse, restitution, below_rest_threshold, mass_a, mass_b,
        kinetic_energy_before, kinetic_energy_after``. ``"skipped"``: ``step, time, body_a,
        body_b, reason``.
        """
        try:
            import pandas as pd
        except ImportError:
            raise ImportError(
                "RunRecord.to_dataframe needs pandas, which is not installed: pip install pandas"
            ) from None
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
            "momentum_start": _vec(self.ledger.momentum_start),
            "momentum_end": _vec(self.ledger.momentum_end),
            "kinetic_energy_start": self.ledger.kinetic_start,
            "kinetic_energy_end": self.ledger.kinetic_end,
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
                "gravity": _vec(self.gravity),
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
