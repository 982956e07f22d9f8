"""What a run checks while it runs: positions and speeds stay in the range collisionlab simulates
(:mod:`collisionlab.limits` decides the range and checks a scenario before it runs), and a
number that overflowed during a step is named with the step. :class:`RangeGuard` watches a run
between its chunks of steps (:mod:`collisionlab.engine.world_runs`); a run that leaves the range
stops with :class:`~collisionlab.errors.OutOfRangeError`, so no output ever holds ``inf`` or
``NaN``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from .errors import InvalidInputError, OutOfRangeError
from .limits import (
    MAX_RUN_COORDINATE,
    MAX_RUN_SPEED,
    MAX_TRAVEL_PER_SIZE,
    ScenarioNumbers,
    closing_speed,
    reach,
)
from .vector import Vector3D

__all__ = ["RangeGuard", "is_overflow"]


class RangeGuard:
    """Watches a run step by step: positions and speeds stay within ``MAX_RUN_COORDINATE`` and
    ``MAX_RUN_SPEED`` (else :class:`OutOfRangeError`), and in exact mode a warning is given once
    when bodies come to move too far per step for time of impact to resolve."""

    def __init__(self, scenario: ScenarioNumbers) -> None:
        self.names = scenario.bodies.names()
        self.dt = scenario.settings.dt
        self.exact = scenario.settings.mode == "exact"
        self.reach = reach(scenario)
        self.warned = False

    def check(
        self, step: int, time: float, positions: Sequence[Vector3D], velocities: Sequence[Vector3D]
    ) -> str | None:
        """Raise when a body left the range; return a warning (once) when exact mode may miss."""
        speeds = []
        for name, x, v in zip(self.names, positions, velocities, strict=True):
            if max(abs(x.x), abs(x.y), abs(x.z)) > MAX_RUN_COORDINATE:
                raise OutOfRangeError(
                    f"step {step} (t = {time:g} s): '{name}' reached position {_short(x)}, beyond the "
                    f"{MAX_RUN_COORDINATE:g} m collisionlab simulates: the scenario's numbers are too large to simulate"
                )
            if max(abs(v.x), abs(v.y), abs(v.z)) > MAX_RUN_SPEED:
                raise OutOfRangeError(
                    f"step {step} (t = {time:g} s): '{name}' reached velocity {_short(v)}, beyond the "
                    f"{MAX_RUN_SPEED:g} m/s collisionlab simulates: the scenario's numbers are too large to simulate "
                    "(restitution above 1 adds energy at every collision)"
                )
            speeds.append(v.length())
        return self._travel_warning(step, closing_speed(speeds)) if self.exact and not self.warned else None

    def _travel_warning(self, step: int, closing: float) -> str | None:
        """A warning (once) when bodies closing at ``closing`` m/s outrun time of impact."""
        if closing * self.dt <= self.reach:
            return None
        self.warned = True
        return (
            f"from step {step} bodies close by {closing * self.dt:.3g} m per step, more than "
            f"{MAX_TRAVEL_PER_SIZE:g} times the smallest body's size: time of impact may miss collisions; "
            "use a smaller dt"
        )

    def check_arrays(self, step: int, time: float, positions: Any, velocities: Any) -> str | None:
        """:meth:`check` on arrays ``(n, 3)`` in the order the bodies were given, with no Python
        loop over the bodies (a NaN counts as out of range)."""
        inside = (np.max(np.abs(positions), axis=1) <= MAX_RUN_COORDINATE) & (
            np.max(np.abs(velocities), axis=1) <= MAX_RUN_SPEED
        )
        if not np.all(inside):
            i = int(np.argmin(inside))
            if np.all(np.isfinite(positions[i])) and np.all(np.isfinite(velocities[i])):
                x, v = Vector3D(*positions[i].tolist()), Vector3D(*velocities[i].tolist())
                self._one(i, step, time, x, v)  # raises, naming the position or the speed
            raise OutOfRangeError(
                f"step {step} (t = {time:g} s): '{self.names[i]}' reached a number that overflowed: the "
                "scenario's numbers are too large to simulate"
            )
        if not self.exact or self.warned:
            return None
        speeds = np.sqrt(np.einsum("ij,ij->i", velocities, velocities))
        return self._travel_warning(step, float(np.sort(speeds)[-2:].sum()))

    def _one(self, i: int, step: int, time: float, x: Vector3D, v: Vector3D) -> None:
        """:meth:`check` for body ``i`` alone (raises with its name)."""
        names, self.names = self.names, [self.names[i]]
        try:
            self.check(step, time, [x], [v])
        finally:
            self.names = names

    def overflowed(self, step: int, error: Exception) -> OutOfRangeError:
        """The error for a number that overflowed during ``step`` (``error`` says which)."""
        return OutOfRangeError(
            f"step {step}: a number overflowed ({error}): the scenario's numbers are too large to simulate"
        )


def _short(v: Vector3D) -> str:
    return "(" + ", ".join(f"{c:.3g}" for c in v) + ")"


def is_overflow(error: Exception) -> bool:
    """Whether an error raised during a step is a number that overflowed (inf or NaN)."""
    if isinstance(error, ArithmeticError):
        return True
    got = getattr(error, "got", None)
    return isinstance(error, InvalidInputError) and isinstance(got, float) and not math.isfinite(got)
