"""A pair's separation and its first time of impact, for the contact stepper (phase 2 of
:mod:`.contact_kernels`): conservative advancement along the separating normal (Mirtich 1996),
two balls in the same field of gravity in closed form (Ericson 4.4.3); a pair touching slower
than the rest speed has no impact (it is the solve's).

Owns ``TOI_ITERATIONS``, a pair's separation at given positions or where the bodies are
(:func:`_sep_of`, :func:`_sep_now`: every other contact file asks it) and the time of impact
(:func:`_pair_toi`). It imports :mod:`.contact_law` (an impact or not), :mod:`.geometry_kernels`,
:mod:`.pair_separation` and :mod:`.contact_flight`; it must not import the candidates, impacts,
solve, push-apart, islands or the loop (which ask it, not the other way round).
"""

from __future__ import annotations

import math
from typing import Any

from ..tolerances import APPROACH_ROUNDING, TOI_GAP

if "_GEOMETRY" in globals():  # the compiled copy: the kernels it calls are compiled too
    cl: Any = globals()["_CONTACT_LAW"]
    gk: Any = globals()["_GEOMETRY"]
    ps: Any = globals()["_PAIR_SEPARATION"]
    fl: Any = globals()["_CONTACT_FLIGHT"]
else:
    from . import contact_flight as fl
    from . import contact_law as cl
    from . import geometry_kernels as gk
    from . import pair_separation as ps

#: The most iterations of conservative advancement for one prediction; the time reached is then
#: used (never after the impact: the pair is looked at again there).
TOI_ITERATIONS = 64

#: Helpers the compiled form inlines into their callers (:mod:`.compiled`).
INLINE = ("_sep_of", "_sep_now")


def _sep_of(
    kind: Any, ext: Any, s_kind: Any, s_a: Any, s_b: Any, a: int, b: int,
    ax: float, ay: float, az: float, bx: float, by: float, bz: float,
) -> Any:  # fmt: skip
    """Separation of pair ``(a, b)`` (``a < 0``: the static ``-1 - a``) with the bodies at the
    given positions, normal from a to b."""
    if a >= 0:
        return ps._pair_sep(
            kind[a], ax, ay, az, ext[a, 0], ext[a, 1], ext[a, 2], kind[b], bx, by, bz, ext[b, 0], ext[b, 1], ext[b, 2]
        )
    s = -1 - a
    return ps._static_sep(
        s_kind[s], s_a[s, 0], s_a[s, 1], s_a[s, 2], s_b[s, 0], s_b[s, 1], s_b[s, 2],
        kind[b], bx, by, bz, ext[b, 0], ext[b, 1], ext[b, 2],
    )  # fmt: skip


def _sep_now(kind: Any, pos: Any, ext: Any, s_kind: Any, s_a: Any, s_b: Any, a: int, b: int) -> Any:
    """Separation of pair ``(a, b)`` where the bodies are now (:func:`_sep_of`)."""
    if a >= 0:
        return _sep_of(
            kind, ext, s_kind, s_a, s_b, a, b, pos[a, 0], pos[a, 1], pos[a, 2], pos[b, 0], pos[b, 1], pos[b, 2]
        )
    return _sep_of(kind, ext, s_kind, s_a, s_b, a, b, 0.0, 0.0, 0.0, pos[b, 0], pos[b, 1], pos[b, 2])


def _pair_toi(
    kind: Any, pos: Any, vel: Any, acc: Any, tau: Any, ext: Any, s_kind: Any, s_a: Any, s_b: Any,
    a: int, b: int, t: float, t_end: float, rest_speed: float,
) -> float:  # fmt: skip
    """When in ``[t, t_end)`` the pair ``(a, b)`` first touches while approaching, or ``inf``, by
    conservative advancement (phase 2 of :mod:`.contact_kernels`): the gap along the current normal
    ``n`` is ``d + (w.n) s + (alpha.n) s^2 / 2`` (``w``, ``alpha``: relative velocity and
    acceleration) and the true gap is never below it, so its first root is never after the impact. A
    pair touching and moving apart is followed to when its gap along ``n`` closes again, once. A
    pair that touches approaching no faster than ``rest_speed`` gets ``inf``: that is no impact."""
    straight = a >= 0 and kind[a] <= ps.BALL_3D and kind[b] <= ps.BALL_3D
    alx = acc[b, 0] - (acc[a, 0] if a >= 0 else 0.0)
    aly = acc[b, 1] - (acc[a, 1] if a >= 0 else 0.0)
    alz = acc[b, 2] - (acc[a, 2] if a >= 0 else 0.0)
    straight = straight and alx == 0.0 and aly == 0.0 and alz == 0.0
    jumped = False
    for _ in range(TOI_ITERATIONS):
        bx, vbx = fl._at(pos, vel, acc, tau, b, t, 0)
        by, vby = fl._at(pos, vel, acc, tau, b, t, 1)
        bz, vbz = fl._at(pos, vel, acc, tau, b, t, 2)
        ax = ay = az = vax = vay = vaz = 0.0
        if a >= 0:
            ax, vax = fl._at(pos, vel, acc, tau, a, t, 0)
            ay, vay = fl._at(pos, vel, acc, tau, a, t, 1)
            az, vaz = fl._at(pos, vel, acc, tau, a, t, 2)
        sep = _sep_of(kind, ext, s_kind, s_a, s_b, a, b, ax, ay, az, bx, by, bz)
        wx, wy, wz = vbx - vax, vby - vay, vbz - vaz
        s1 = wx * sep[1] + wy * sep[2] + wz * sep[3]
        s2 = 0.5 * (alx * sep[1] + aly * sep[2] + alz * sep[3])
        if sep[0] <= TOI_GAP:
            still = APPROACH_ROUNDING * (abs(vax) + abs(vay) + abs(vaz) + abs(vbx) + abs(vby) + abs(vbz))
            if cl.is_impact(s1, rest_speed):
                return t  # an impact
            if s1 < -still or (s1 <= still and s2 < 0.0):
                return math.inf  # pressed together slowly: the solve's, until a kick predicts it again
            if jumped or s2 >= 0.0:
                return math.inf
            t += -s1 / s2  # when the gap along n is back where it is: never after the return
            jumped = True
            if t >= t_end:
                return math.inf
            continue
        if straight:
            r = ext[a, 0] + ext[b, 0]
            step = gk.time_of_impact_ball_ball(bx - ax, by - ay, bz - az, wx, wy, wz, r * r)
            if step == 0.0:  # touching by rounding although the gap said apart: now
                return t
        else:
            step = gk.first_root(sep[0], s1, s2, t_end - t)
        if step == math.inf:
            return math.inf
        t += step
        if t >= t_end:
            return math.inf
    return t
