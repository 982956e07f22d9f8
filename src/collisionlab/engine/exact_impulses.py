"""The exact stepper's impulses: ``j = -(1 + e) v_n / (1/m_a + 1/m_b)`` along a contact normal
(lab eqs. 12, 15, 24), each body answering through the supports it rests on. An impact
(:mod:`.exact_impacts`) and a resting contact's stop of a slow approach (:mod:`.exact_rest`) both
kick through here; the kinetic energy a kick changes, and an impact's predicted loss and count, go
to the ledger.

Owns how a body answers a unit impulse (:func:`_response`) and the kick (:func:`_kick`). It
imports only the contact law (:mod:`.contact_law`); it must not import the other exact files (it
finds no contact and moves no body).
"""

from __future__ import annotations

from typing import Any

if "_CONTACT_LAW" in globals():  # the compiled copy: the kernels it calls are compiled too
    cl: Any = globals()["_CONTACT_LAW"]
else:
    from . import contact_law as cl

#: Helpers the compiled form inlines into their callers (:mod:`.compiled`): the small ones, and
#: those the loop calls for every pair it looks at, which take arrays (a call costs a reference
#: count taken and given back for each array it passes; inlined into a ``NO_REFCOUNT`` phase,
#: none at all).
INLINE = (
    "_response",
    "_kick",
)


def _response(i: int, dx: float, dy: float, dz: float, ima: Any, sup: Any, nsup: Any, free: bool) -> Any:
    """How body ``i`` answers a unit impulse along ``d``: a body resting on supports cannot be
    pushed into them, so the part along a support's normal goes to the support (unless ``free``).
    Returns the direction ``m`` its velocity changes in (per unit impulse, times its mass), its
    inverse mass along ``d``, ``(m.d) / m`` (``(1 - (s.d)^2) / m`` on one support ``s``, ``1/m``
    free), and ``|m|^2 / m``."""
    mx = dx
    my = dy
    mz = dz
    if not free:
        for s in range(nsup[i]):
            into = mx * sup[i, s, 0] + my * sup[i, s, 1] + mz * sup[i, s, 2]
            if into < 0.0:
                mx -= sup[i, s, 0] * into
                my -= sup[i, s, 1] * into
                mz -= sup[i, s, 2] * into
    return mx, my, mz, (mx * dx + my * dy + mz * dz) * ima[i], (mx * mx + my * my + mz * mz) * ima[i]


def _kick(
    a: int,
    b: int,
    nx: float,
    ny: float,
    nz: float,
    vn: float,
    e: float,
    vel: Any,
    ima: Any,
    sup: Any,
    nsup: Any,
    ledger: Any,
    impact: bool,
) -> float:
    """Apply ``j = -(1 + e) v_n / (1/m_a + 1/m_b)`` along ``n`` (A gets minus it; lab eqs. 12,
    15, 24), each body answering through its supports (:func:`_response`; its inverse mass along
    ``n`` is then smaller). The supports' normals are those of the moment they were found, so if
    that answer would add kinetic energy (beyond what ``e > 1`` adds free) the kick is applied
    free: a free impulse changes it by ``-(1 - e^2) mu v_n^2 / 2``. The kinetic energy it changes
    goes to ``ledger[1]``; an impact (not a resting contact's stop) also adds its predicted loss
    to ``ledger[3]`` and counts in ``ledger[5]`` or ``ledger[6]``. Returns ``j`` (0 when neither
    body can move)."""
    ax = ay = az = bx = by = bz = 0.0
    inv_sum = 0.0
    j = 0.0
    for attempt in range(2):
        free = attempt == 1
        ax = ay = az = 0.0
        inv_a = energy_a = 0.0
        if a >= 0 and ima[a] > 0.0:
            ax, ay, az, inv_a, energy_a = _response(a, -nx, -ny, -nz, ima, sup, nsup, free)
        bx = by = bz = 0.0
        inv_b = energy_b = 0.0
        if ima[b] > 0.0:
            bx, by, bz, inv_b, energy_b = _response(b, nx, ny, nz, ima, sup, nsup, free)
        inv_sum = inv_a + inv_b
        if inv_sum <= 0.0:
            if free:
                return 0.0
            continue
        j = cl.impulse_magnitude(vn, inv_sum, e)
        if free:
            break
        u = vel[b, 0] * bx + vel[b, 1] * by + vel[b, 2] * bz
        if a >= 0:
            u += vel[a, 0] * ax + vel[a, 1] * ay + vel[a, 2] * az
        gained = j * u + 0.5 * j * j * (energy_a + energy_b)
        if gained <= max(0.0, -cl.collision_loss(vn, inv_sum, e)):
            break
    kinetic = 0.0
    if a >= 0 and ima[a] > 0.0:
        before = vel[a, 0] ** 2 + vel[a, 1] ** 2 + vel[a, 2] ** 2
        vel[a, 0] = cl.pushed_velocity(vel[a, 0], j, ima[a], ax)
        vel[a, 1] = cl.pushed_velocity(vel[a, 1], j, ima[a], ay)
        vel[a, 2] = cl.pushed_velocity(vel[a, 2], j, ima[a], az)
        kinetic += 0.5 * (vel[a, 0] ** 2 + vel[a, 1] ** 2 + vel[a, 2] ** 2 - before) / ima[a]
    if ima[b] > 0.0:
        before = vel[b, 0] ** 2 + vel[b, 1] ** 2 + vel[b, 2] ** 2
        vel[b, 0] = cl.pushed_velocity(vel[b, 0], j, ima[b], bx)
        vel[b, 1] = cl.pushed_velocity(vel[b, 1], j, ima[b], by)
        vel[b, 2] = cl.pushed_velocity(vel[b, 2], j, ima[b], bz)
        kinetic += 0.5 * (vel[b, 0] ** 2 + vel[b, 1] ** 2 + vel[b, 2] ** 2 - before) / ima[b]
    ledger[1] += kinetic
    if impact:
        ledger[3] -= cl.collision_loss(vn, inv_sum, e)
        if a >= 0:
            ledger[5] += 1.0
        else:
            ledger[6] += 1.0
    return float(j)
