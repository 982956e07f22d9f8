"""Exact flight, the contact stepper's motion (phases 2 and 4 of :mod:`.contact_kernels`): a
body flies its parabola ``x + v t + g t^2 / 2`` (a kinematic body, of infinite mass, its line)
from its own time ``tau[i]``, and is brought to a time only when an impact or the end of a flight
needs it.

Owns a coordinate's position and velocity at a time (:func:`_at`) and a body's or every body's
flight to a time (:func:`_advance`, :func:`_advance_all`). It imports no other file of the engine,
and every contact file may import it: it must stay so (no pair, impact or solve here).
"""

from __future__ import annotations

from typing import Any

#: Helpers the compiled form inlines into their callers (:mod:`.compiled`).
INLINE = ("_at",)


def _at(pos: Any, vel: Any, acc: Any, tau: Any, i: int, t: float, k: int) -> Any:
    """Coordinate ``k`` of body ``i``'s position and velocity at time ``t`` of its flight."""
    d = t - tau[i]
    return pos[i, k] + vel[i, k] * d + 0.5 * acc[i, k] * d * d, vel[i, k] + acc[i, k] * d


def _advance(pos: Any, vel: Any, acc: Any, tau: Any, i: int, t: float) -> None:
    """Bring body ``i`` to time ``t`` of its flight."""
    for k in range(3):
        pos[i, k], vel[i, k] = _at(pos, vel, acc, tau, i, t, k)
    tau[i] = t


def _advance_all(pos: Any, vel: Any, acc: Any, tau: Any, t: float) -> None:
    for i in range(pos.shape[0]):
        _advance(pos, vel, acc, tau, i, t)
