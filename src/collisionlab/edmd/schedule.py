"""Moving a body to the present and scheduling its next event (compiled, inlined into the event
loop, :mod:`.loop`).

A body's state holds at its own time ``F[i, T]``; :func:`advance` brings it to ``now`` along
its flight (a parabola under gravity ``g`` along ``-y``). :func:`predict_next` puts into the
calendar the soonest of its events: leaving its neighbour list, hitting a wall, or hitting a
neighbour (:func:`soonest_pair`), each time found by :mod:`.predict`'s closed forms.
"""

from __future__ import annotations

import math
from typing import Any

from .calendar import (
    calendar_insert,
)
from .cells import nearest_image
from .compile import jit_inline
from .layout import (
    COUNT,
    EDGE,
    EVT,
    HPOS,
    KIND,
    KIND_NLIST,
    KIND_NONE,
    KIND_PAIR,
    KIND_WALL,
    NB_UNSCHEDULED,
    NNB,
    P_CUT,
    P_G,
    P_L,
    P_MIXED,
    P_RADII,
    P_SKIN,
    PARTNER,
    PCOUNT,
    Q_DIM,
    Q_PERIODIC,
    RADIUS,
    C,
    T,
    V,
    X,
)
from .predict import ceiling_time, contact_time, floor_time, leave_time, wall_time

__all__ = ["advance", "predict_next", "soonest_pair"]


@jit_inline
def advance(F: Any, i: int, now: float, g: float) -> None:
    dt = now - F[i, T]
    if dt != 0.0:
        F[i, X] += F[i, V] * dt
        F[i, X + 1] += (F[i, V + 1] - 0.5 * g * dt) * dt
        F[i, X + 2] += F[i, V + 2] * dt
        F[i, V + 1] -= g * dt
        F[i, T] = now


@jit_inline
def soonest_pair(
    F: Any,
    IX: Any,
    NB: Any,
    P: Any,
    i: int,
    now: float,
    tmin: float,
    kind: int,
    partner: int,
    wrap: bool,
    dim: int,
    mixed: bool,
) -> tuple[float, int, int]:
    """The soonest contact of ``i`` with a neighbour, if sooner than ``tmin`` (then kind
    ``KIND_PAIR`` and the neighbour); else ``tmin``, ``kind`` and ``partner`` as given."""
    g = P[P_G]
    half_g = 0.5 * g
    xi = F[i, X]
    yi = F[i, X + 1]
    zi = F[i, X + 2]
    vx = F[i, V]
    vy = F[i, V + 1]
    vz = F[i, V + 2]
    ri = F[i, RADIUS]
    sigma = ri + ri
    sigma2 = sigma * sigma
    for m in range(IX[i, NNB]):
        j = NB[i, m]
        dt = now - F[j, T]
        dx = xi - (F[j, X] + F[j, V] * dt)
        dz = zi - (F[j, X + 2] + F[j, V + 2] * dt)
        if g == 0.0:  # the common case, without the parabola's terms
            dy = yi - (F[j, X + 1] + F[j, V + 1] * dt)
            dvy = vy - F[j, V + 1]
        else:
            dy = yi - (F[j, X + 1] + (F[j, V + 1] - half_g * dt) * dt)
            dvy = vy - (F[j, V + 1] - g * dt)
        if wrap:
            dx = nearest_image(dx, P[P_L])
            dy = nearest_image(dy, P[P_L + 1])
            if dim == 3:
                dz = nearest_image(dz, P[P_L + 2])
        if mixed:  # each pair its own contact distance (the radii follow the parameters in P)
            contact = ri + P[P_RADII + j]
            t = contact_time(dx, dy, dz, vx - F[j, V], dvy, vz - F[j, V + 2], contact * contact)
        else:
            t = contact_time(dx, dy, dz, vx - F[j, V], dvy, vz - F[j, V + 2], sigma2)
        if t < tmin:
            tmin = t
            kind = KIND_PAIR
            partner = j
    return tmin, kind, partner


@jit_inline
def predict_next(heap: Any, lists: Any, F: Any, IX: Any, NB: Any, P: Any, Q: Any, K: Any, i: int, now: float) -> None:
    """Schedule body ``i``'s next event (``i`` holds at ``now``): the soonest of leaving its
    list, hitting a wall, or hitting a neighbour."""
    g = P[P_G]
    xi = F[i, X]
    yi = F[i, X + 1]
    zi = F[i, X + 2]
    vx = F[i, V]
    vy = F[i, V + 1]
    vz = F[i, V + 2]
    ri = F[i, RADIUS]
    mixed = P[P_MIXED] != 0.0
    # How far i may drift from its list's centre: two bodies off each other's lists, centres at
    # least P_CUT apart, stay r_i + r_j apart if the skins sum to P_CUT - r_i - r_j; so each
    # body's own skin is P_CUT / 2 - r_i (the small, fast balls of a mixture get the larger).
    skin = 0.5 * P[P_CUT] - ri if mixed else P[P_SKIN]
    tmin = leave_time(xi - F[i, C], yi - F[i, C + 1], zi - F[i, C + 2], vx, vy, vz, g, skin)
    kind = KIND_NLIST
    partner = -1
    dim = Q[Q_DIM]
    periodic = Q[Q_PERIODIC] != 0
    if not periodic:
        r = ri
        for k in range(dim):
            lo = r
            hi = P[P_L + k] - r
            x = F[i, X + k]
            v = F[i, V + k]
            if k == 1 and g > 0.0:
                t_lo = floor_time(x, v, g, lo)
                t_hi = ceiling_time(x, v, g, hi)
                if t_lo < t_hi:
                    t = t_lo
                    wall = 2
                else:
                    t = t_hi
                    wall = 3
            else:
                t = wall_time(x, v, lo, hi)
                wall = 2 * k + (1 if v > 0.0 else 0)
            if t < tmin:
                tmin = t
                kind = KIND_WALL
                partner = wall
    wrap = periodic and IX[i, EDGE] != 0
    if mixed:
        tmin, kind, partner = soonest_pair(F, IX, NB, P, i, now, tmin, kind, partner, wrap, dim, True)
    else:  # one kind of ball: no radius read (the same loop compiled apart, without the branch)
        tmin, kind, partner = soonest_pair(F, IX, NB, P, i, now, tmin, kind, partner, wrap, dim, False)
    if tmin == math.inf:
        IX[i, KIND] = KIND_NONE
        IX[i, HPOS] = NB_UNSCHEDULED
        F[i, EVT] = math.inf
        return
    F[i, EVT] = now + tmin
    IX[i, KIND] = kind
    IX[i, PARTNER] = partner
    if kind == KIND_PAIR:
        F[i, PCOUNT] = F[partner, COUNT]
    calendar_insert(heap, lists, F, IX, P, Q, K, i)
