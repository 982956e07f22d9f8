"""A run as the pictures read it: :class:`DrawnRun`, the parts of a
:class:`~collisionlab.record.RunRecord` that a plot, an animation or a page draws.

Protocols, not the record's classes: :meth:`RunRecord.plot <collisionlab.record.RunRecord.plot>`
draws through :mod:`.static`, so importing :mod:`collisionlab.record` from the pictures would be
an import circle (issue 30). mypy checks that a ``RunRecord`` has every part named here where the
record hands itself to :func:`~.static.draw_figure`, and where the CLI hands one to a writer.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Protocol

from ..vector import Vector3D

__all__ = ["DrawnBody", "DrawnEvent", "DrawnFrame", "DrawnLedger", "DrawnRun"]


class DrawnBody(Protocol):
    """A body in a frame (:class:`~collisionlab.record.BodyState`)."""

    @property
    def name(self) -> str: ...
    @property
    def position(self) -> Vector3D: ...
    @property
    def velocity(self) -> Vector3D: ...


class DrawnFrame(Protocol):
    """A recorded step (:class:`~collisionlab.record.Frame`)."""

    @property
    def step(self) -> int: ...
    @property
    def time(self) -> float: ...
    @property
    def bodies(self) -> Sequence[DrawnBody]: ...


class DrawnEvent(Protocol):
    """A collision (:class:`~collisionlab.record.CollisionEvent`)."""

    @property
    def step(self) -> int: ...
    @property
    def time(self) -> float: ...
    @property
    def bodies(self) -> tuple[str, str]: ...
    @property
    def point(self) -> Vector3D: ...


class DrawnLedger(Protocol):
    """Where the energy went (:class:`~collisionlab.record.Ledger`), as the plot prints it."""

    @property
    def energy_start(self) -> float: ...
    @property
    def energy_end(self) -> float: ...
    @property
    def collisions(self) -> float: ...
    @property
    def integrator(self) -> float: ...
    @property
    def push_apart(self) -> float: ...
    @property
    def residual(self) -> float: ...


class DrawnRun(Protocol):
    """A run (:class:`~collisionlab.record.RunRecord`): its settings, frames, events and ledger,
    and its JSON form (the interactive page embeds it)."""

    @property
    def title(self) -> str: ...
    @property
    def mode(self) -> str: ...
    @property
    def dt(self) -> float: ...
    @property
    def steps(self) -> int: ...
    @property
    def restitution(self) -> float: ...
    @property
    def gravity(self) -> Vector3D: ...
    @property
    def dims(self) -> int: ...
    @property
    def frames(self) -> Sequence[DrawnFrame]: ...
    @property
    def events(self) -> Sequence[DrawnEvent]: ...
    @property
    def ledger(self) -> DrawnLedger: ...
    def to_dict(self) -> dict[str, Any]: ...
