"""Phase 1 of the Forward Euler stepper (:mod:`.step_kernels`): integrate, position first,
``x += v dt`` then ``v += g dt`` (the lab's part VI), booking the energy it changes. A kernel
file like the others: plain floats and arrays, the same source as Python and compiled by numba.

It imports nothing; the loop (:mod:`.step_kernels`) calls it, then puts back a body this carried
across a line or plane (:mod:`.euler_clamps`).
"""

from __future__ import annotations

from typing import Any

__all__: list[str] = []


def _integrate(pos: Any, vel: Any, ima: Any, gravity: Any, dt: float, ledger: Any) -> None:
    """Forward Euler, position first: ``x += v dt`` then ``v += g dt`` (static bodies keep v).
    The energy this changes (kinetic plus ``-m g.x``) goes to ``ledger[0]``."""
    n = pos.shape[0]
    gx = gravity[0]
    gy = gravity[1]
    gz = gravity[2]
    change = 0.0
    for i in range(n):
        vx = vel[i, 0]
        vy = vel[i, 1]
        vz = vel[i, 2]
        pos[i, 0] = pos[i, 0] + vx * dt
        pos[i, 1] = pos[i, 1] + vy * dt
        pos[i, 2] = pos[i, 2] + vz * dt
        if ima[i] > 0.0:
            wx = vx + gx * dt
            wy = vy + gy * dt
            wz = vz + gz * dt
            vel[i, 0] = wx
            vel[i, 1] = wy
            vel[i, 2] = wz
            kinetic = 0.5 * ((wx * wx + wy * wy + wz * wz) - (vx * vx + vy * vy + vz * vz))
            potential = -(gx * vx + gy * vy + gz * vz) * dt
            change += (kinetic + potential) / ima[i]
    ledger[0] += change
