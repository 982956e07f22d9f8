"""Exact flight, the exact stepper's motion between impacts (:mod:`.exact_kernels`): a body flies
``x(t) = x + v t + a t^2 / 2``, ``v(t) = v + a t`` from its own time ``tau[i]`` (each body is
brought to an impact's time only when the impact needs it), and the energy a flight changes (none
in free flight, a support's work otherwise) goes to the ledger.

Owns a coordinate's flight (:func:`_flown`), its work (:func:`_flight_work`) and a body's or every
body's flight to a time (:func:`_advance`, :func:`_advance_all`). It imports no other file of the
engine, and every exact file may import it: it must stay so (no contact, impulse or bound here).
"""

from __future__ import annotations

from typing import Any

#: Helpers the compiled form inlines into their callers (:mod:`.compiled`): the small ones, and
#: those the loop calls for every pair it looks at, which take arrays (a call costs a reference
#: count taken and given back for each array it passes; inlined into a ``NO_REFCOUNT`` phase,
#: none at all).
INLINE = (
    "_flown",
    "_flight_work",
    "_advance",
)


def _flown(x: float, v: float, a: float, d: float) -> Any:
    """One coordinate's position and velocity after a flight of ``d`` at acceleration ``a``:
    ``(x + v d + a d^2 / 2, v + a d)``.

    >>> _flown(1.0, 2.0, -10.0, 0.5)
    (0.75, -3.0)
    """
    return x + v * d + 0.5 * a * d * d, v + a * d


def _flight_work(
    vx: float, vy: float, vz: float, ax: float, ay: float, az: float, gravity: Any, d: float, ima_i: float
) -> float:
    """The energy a flight of ``d`` at acceleration ``a`` changes (kinetic plus ``-m g.x``: zero in
    free flight, the work of a support otherwise): ``m [v.(a - g) d + (a.a - g.a) d^2 / 2]``."""
    va = vx * (ax - gravity[0]) + vy * (ay - gravity[1]) + vz * (az - gravity[2])
    aa = ax * (ax - gravity[0]) + ay * (ay - gravity[1]) + az * (az - gravity[2])
    return float((va * d + 0.5 * aa * d * d) / ima_i)


def _advance(i: int, t: float, pos: Any, vel: Any, acc: Any, tau: Any, ima: Any, gravity: Any, ledger: Any) -> None:
    """Bring body ``i`` from its own time ``tau[i]`` to ``t`` exactly:
    ``x += v d + a d^2 / 2``, ``v += a d``; the energy the flight changes goes to ``ledger[0]``
    (:func:`_flight_work`)."""
    d = t - tau[i]
    if d <= 0.0:
        return
    if ima[i] > 0.0:
        ledger[0] += _flight_work(vel[i, 0], vel[i, 1], vel[i, 2], acc[i, 0], acc[i, 1], acc[i, 2], gravity, d, ima[i])
    for k in range(3):
        pos[i, k], vel[i, k] = _flown(pos[i, k], vel[i, k], acc[i, k], d)
    tau[i] = t


def _advance_all(t: float, pos: Any, vel: Any, acc: Any, tau: Any, ima: Any, gravity: Any, ledger: Any) -> None:
    """:func:`_advance` for every body, in order. Its own function, not inlined: an inlined helper
    that takes arrays costs reference counts taken and given back at every call (numba does not
    prune them in a loop), several times the flight itself, so the loop reads the arrays here."""
    energy = ledger[0]  # summed in the same order as body after body would
    for i in range(pos.shape[0]):
        d = t - tau[i]
        if d <= 0.0:
            continue
        if ima[i] > 0.0:
            energy += _flight_work(
                vel[i, 0], vel[i, 1], vel[i, 2], acc[i, 0], acc[i, 1], acc[i, 2], gravity, d, ima[i]
            )  # fmt: skip
        for k in range(3):
            pos[i, k], vel[i, k] = _flown(pos[i, k], vel[i, k], acc[i, k], d)
        tau[i] = t
    ledger[0] = energy
