"""What an event does to the bodies (compiled, inlined into the event loop, :mod:`.loop`): a pair
:func:`collide`, or a body :func:`bounce` off a wall (the loop then predicts the bodies' next
events), by the engine's contact law with ``e`` or, under the TC model, 1
(:func:`_restitution`); the ledger's sums, the species' tallies, and the event's row of the
buffer (:func:`_record`, with ``run(..., working=True)`` the normal, contact point and
velocities too). See the loop's docstring for the law and the TC model.
"""

from __future__ import annotations

import math
from typing import Any

from .calendar import (
    calendar_remove,
)
from .cells import nearest_image
from .compile import jit_call, jit_inline
from .layout import (
    COUNT,
    EVENT_FULL,
    G_KINETIC,
    G_LOST,
    G_MAX_OVERLAP,
    G_VIRIAL,
    G_WALL,
    K_BUFFERED,
    K_PAIRS,
    K_STALE,
    K_WALLS,
    MASS,
    P_E,
    P_G,
    P_L,
    P_TC,
    PARTNER,
    PCOUNT,
    Q_DIM,
    Q_PERIODIC,
    RADIUS,
    TLAST,
    V,
    X,
)
from .predict import collision_loss, impulse_magnitude, pushed_velocity
from .schedule import advance

__all__ = ["bounce", "collide"]


@jit_call
def _restitution(F: Any, P: Any, i: int, j: int, now: float) -> float:
    """``e``, or 1 under the TC model when ``i`` (or ``j >= 0``) collided less than ``t_c`` ago."""
    e: float = P[P_E]
    if e == 1.0:
        return e
    tc = P[P_TC]
    if now - F[i, TLAST] < tc or (j >= 0 and now - F[j, TLAST] < tc):
        return 1.0
    return e


@jit_call
def _record(buf: Any, K: Any, now: float, a: int, b: int, impulse: float) -> int:
    """Start an event's row (time, a, b, impulse); returns its index, or -1 when the buffer has
    no room (the loop stops for it to be emptied before that happens)."""
    n: int = K[K_BUFFERED]
    if n >= buf.shape[0]:
        return -1
    buf[n, 0] = now
    buf[n, 1] = a
    buf[n, 2] = b
    buf[n, 3] = impulse
    K[K_BUFFERED] = n + 1
    return n


@jit_call
def _record_working(
    buf: Any, row: int, nx: float, ny: float, nz: float, px: float, py: float, pz: float, vn: float, e: float
) -> None:
    """The normal, the contact point, the normal speed before and ``e`` of row ``row`` (an
    ``EVENT_FULL`` buffer); the velocities are written by :func:`_record_velocities`."""
    buf[row, 4] = nx
    buf[row, 5] = ny
    buf[row, 6] = nz
    buf[row, 7] = px
    buf[row, 8] = py
    buf[row, 9] = pz
    buf[row, 10] = vn
    buf[row, 11] = e


@jit_call
def _record_velocities(buf: Any, row: int, column: int, F: Any, i: int) -> None:
    """Body ``i``'s velocity into columns ``column .. column + 2`` of row ``row``."""
    buf[row, column] = F[i, V]
    buf[row, column + 1] = F[i, V + 1]
    buf[row, column + 2] = F[i, V + 2]


@jit_call
def _species_energy(SE: Any, a: int, now: float, change: float) -> None:
    """Species ``a``'s kinetic energy changes by ``change`` at ``now``: its time integral so far
    first (``SE[a]``: the energy, the time it holds since, the integral), exact without gravity,
    where the energy changes only at collisions."""
    SE[a, 2] += SE[a, 0] * (now - SE[a, 1])
    SE[a, 1] = now
    SE[a, 0] += change


@jit_inline
def collide(
    heap: Any,
    lists: Any,
    F: Any,
    IX: Any,
    P: Any,
    Q: Any,
    G: Any,
    K: Any,
    S: Any,
    KS: Any,
    SE: Any,
    buf: Any,
    i: int,
    now: float,
) -> int:
    """Body ``i`` meets the partner it was scheduled to hit at ``now``: both collide, or (the
    partner collided since, or they no longer approach) the event is counted stale. The caller
    then predicts ``i``'s next event, and the partner's if it is returned (-1: none); the
    partner's scheduled event is out of the calendar already."""
    j: int = IX[i, PARTNER]
    g = P[P_G]
    advance(F, i, now, g)
    if F[j, COUNT] != F[i, PCOUNT]:
        K[K_STALE] += 1
        return -1
    advance(F, j, now, g)
    dx = F[i, X] - F[j, X]
    dy = F[i, X + 1] - F[j, X + 1]
    dz = F[i, X + 2] - F[j, X + 2]
    if Q[Q_PERIODIC] != 0:
        dx = nearest_image(dx, P[P_L])
        dy = nearest_image(dy, P[P_L + 1])
        dz = nearest_image(dz, P[P_L + 2]) if Q[Q_DIM] == 3 else dz
    b = dx * (F[i, V] - F[j, V]) + dy * (F[i, V + 1] - F[j, V + 1]) + dz * (F[i, V + 2] - F[j, V + 2])
    if b >= 0.0:  # already moving apart (rounding at a grazing contact): nothing to do
        K[K_STALE] += 1
        return -1
    r2 = dx * dx + dy * dy + dz * dz
    r = math.sqrt(r2)
    e = _restitution(F, P, i, j, now)
    mi = F[i, MASS]
    mj = F[j, MASS]
    # The contact law (collisionlab.engine.geometry_kernels): along n = (x_j - x_i) / r, i
    # approaches j at v_n = b / r < 0; j = -(1 + e) v_n / (1/m_i + 1/m_j), i gets -j n / m_i, j
    # gets +j n / m_j (lab eqs. 12, 15).
    if mi == mj:  # one division fewer each way
        impulse = impulse_magnitude(b / r, 2.0 / mi, e)
        fi = impulse / (mi * r)  # per unit of -(x_i - x_j): the change of i's velocity along dx
        fj = fi
    else:
        impulse = impulse_magnitude(b / r, 1.0 / mi + 1.0 / mj, e)
        fi = impulse / (mi * r)
        fj = impulse / (mj * r)
    row = -1
    if buf.shape[0] > 0:
        row = _record(buf, K, now, i, j, impulse)
        if row >= 0 and buf.shape[1] >= EVENT_FULL:
            ri = F[i, RADIUS] / r
            _record_working(
                buf, row, -dx / r, -dy / r, -dz / r, F[i, X] - dx * ri, F[i, X + 1] - dy * ri, F[i, X + 2] - dz * ri,
                b / r, e,
            )  # fmt: skip
            _record_velocities(buf, row, 12, F, i)
            _record_velocities(buf, row, 15, F, j)
    # Kinetic energy before and after: each body's m v^2 (the sum of both, in the order it had
    # before mixtures, when the masses are equal: a run of one mass keeps its last bits).
    kinetic_i = F[i, V] ** 2 + F[i, V + 1] ** 2 + F[i, V + 2] ** 2
    kinetic_j = F[j, V] ** 2 + F[j, V + 1] ** 2 + F[j, V + 2] ** 2
    kinetic = kinetic_i + F[j, V] ** 2 + F[j, V + 1] ** 2 + F[j, V + 2] ** 2
    # The contact law's velocity update, v + (j / m) n, pushed along the unnormalised dx (|dx| = r)
    # by j / (m r) with the mass already in it (inverse mass 1): one division fewer than n's, and
    # the same bits as before the update had one home (a form that divided dx by r moved the
    # gas-mixture example's output: bench/LOG.md).
    F[i, V] = pushed_velocity(F[i, V], fi, 1.0, dx)
    F[i, V + 1] = pushed_velocity(F[i, V + 1], fi, 1.0, dy)
    F[i, V + 2] = pushed_velocity(F[i, V + 2], fi, 1.0, dz)
    F[j, V] = pushed_velocity(F[j, V], -fj, 1.0, dx)
    F[j, V + 1] = pushed_velocity(F[j, V + 1], -fj, 1.0, dy)
    F[j, V + 2] = pushed_velocity(F[j, V + 2], -fj, 1.0, dz)
    after_i = F[i, V] ** 2 + F[i, V + 1] ** 2 + F[i, V + 2] ** 2
    if mi == mj:
        kinetic_after = after_i + F[j, V] ** 2 + F[j, V + 1] ** 2 + F[j, V + 2] ** 2
        G[G_KINETIC] += 0.5 * mi * (kinetic_after - kinetic)
        G[G_LOST] += collision_loss(b / r, 2.0 / mi, e)  # (1 - e^2)/2 mu v_n^2, mu = m/2
    else:
        after_j = F[j, V] ** 2 + F[j, V + 1] ** 2 + F[j, V + 2] ** 2
        G[G_KINETIC] += 0.5 * (mi * (after_i - kinetic_i) + mj * (after_j - kinetic_j))
        G[G_LOST] += collision_loss(b / r, 1.0 / mi + 1.0 / mj, e)  # mu = 1 / (1/m_i + 1/m_j)
    G[G_VIRIAL] += impulse * r  # r_ij . dp_i = (j / r) r^2, positive
    if S.shape[0] > 0:  # a mixture: the pair's species, and each one's kinetic energy
        a = S[i]
        c = S[j]
        KS[a, c] += 1
        KS[c, a] += 1
        _species_energy(SE, a, now, 0.5 * mi * (after_i - kinetic_i))
        _species_energy(SE, c, now, 0.5 * mj * (F[j, V] ** 2 + F[j, V + 1] ** 2 + F[j, V + 2] ** 2 - kinetic_j))
    overlap = F[i, RADIUS] + F[j, RADIUS] - r
    if overlap > G[G_MAX_OVERLAP]:
        G[G_MAX_OVERLAP] = overlap
    if row >= 0 and buf.shape[1] >= EVENT_FULL:
        _record_velocities(buf, row, 18, F, i)
        _record_velocities(buf, row, 21, F, j)
    F[i, TLAST] = now
    F[j, TLAST] = now
    F[i, COUNT] += 1.0
    F[j, COUNT] += 1.0
    K[K_PAIRS] += 1
    calendar_remove(heap, lists, F, IX, Q, K, j)
    return j


@jit_inline
def bounce(F: Any, IX: Any, P: Any, G: Any, K: Any, S: Any, SE: Any, buf: Any, i: int, now: float) -> None:
    """Body ``i`` meets the wall it was scheduled to hit at ``now``: bounced off it (or, if it no
    longer moves into the wall, counted stale); the caller then predicts ``i``'s next event."""
    wall = IX[i, PARTNER]
    advance(F, i, now, P[P_G])
    k = wall >> 1
    high = (wall & 1) == 1
    v = F[i, V + k]
    g = P[P_G]
    r = F[i, RADIUS]
    floor = wall == 2 and g > 0.0
    into = (v > 0.0) == high and v != 0.0
    if not into and not (floor and F[i, X + 1] <= r):  # not moving into this wall (any more)
        K[K_STALE] += 1
        return
    e = _restitution(F, P, i, -1, now)
    inward = -1.0 if high else 1.0  # the wall's normal, towards the body
    m = F[i, MASS]
    vn = v * inward  # negative: moving into the wall
    # The contact law with the wall's infinite mass (lab eq. 24): j = -(1 + e) v_n m.
    after = pushed_velocity(v, impulse_magnitude(vn, 1.0 / m, e), 1.0 / m, inward)
    if floor:
        # The floor never sends a body back for less than t_c: the flight after a bounce lasts
        # 2 v / g >= t_c. Without this a body pressed onto the floor by one above it could
        # chatter at ever smaller speeds, elastically (TC), at an unbounded rate.
        after = max(after, 0.5 * g * P[P_TC])
    impulse = m * abs(after - v)
    row = -1
    if buf.shape[0] > 0:
        row = _record(buf, K, now, i, -1 - wall, impulse)
        if row >= 0 and buf.shape[1] >= EVENT_FULL:
            # The normal from the body (a) to the wall (b), against the wall's own.
            nx = -inward if k == 0 else 0.0
            ny = -inward if k == 1 else 0.0
            nz = -inward if k == 2 else 0.0
            _record_working(buf, row, nx, ny, nz, F[i, X] + r * nx, F[i, X + 1] + r * ny, F[i, X + 2] + r * nz, vn, e)
            _record_velocities(buf, row, 12, F, i)
            for c in range(15, 18):
                buf[row, c] = 0.0
                buf[row, c + 6] = 0.0
    F[i, V + k] = after
    if row >= 0 and buf.shape[1] >= EVENT_FULL:
        _record_velocities(buf, row, 18, F, i)
    G[G_WALL + wall] += impulse
    G[G_LOST] += collision_loss(vn, 1.0 / m, e)  # theory: (1 - e^2)/2 m v_n^2 (the floor's rule aside)
    G[G_KINETIC] += 0.5 * m * (after * after - v * v)
    if S.shape[0] > 0:
        _species_energy(SE, S[i], now, 0.5 * m * (after * after - v * v))
    overlap = F[i, X + k] - (P[P_L + k] - r) if high else r - F[i, X + k]
    if overlap > G[G_MAX_OVERLAP]:
        G[G_MAX_OVERLAP] = overlap
    F[i, TLAST] = now
    F[i, COUNT] += 1.0
    K[K_WALLS] += 1
