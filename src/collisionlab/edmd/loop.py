"""The compiled event loop: one call runs the simulation over a span of time.

Each body carries its state at its own time ``F[i, T]`` and is moved to the present only when
an event touches it (Smallenburg 2022, section 2.1). The loop takes the calendar's first
event and handles it:

* a **pair** collision with ``j``: if ``j`` has collided since the event was scheduled (its
  counter moved on) the event is stale and ``i`` is only predicted again; otherwise both are
  moved to the moment of contact (``|r| = r_i + r_j``) and given the impulse of the engine's
  contact law along the line of centres
  (:func:`~collisionlab.engine.geometry_kernels.impulse_magnitude`,
  ``j = -(1 + e) v_n / (1/m_i + 1/m_j)``, ``v_n = r . v_ij / |r|``), the changes ``-j / m_i``
  and ``+j / m_j`` along it, so momentum is kept (a mixture's balls each have their own radius
  and mass, ``F[i, RADIUS]`` and ``F[i, MASS]``: one loop for one kind of ball or many);
* a **wall**: the same law with the wall's infinite mass, ``-e`` times the velocity across it;
* a **neighbour-list** event: ``i``'s list is built again around its present position;

then the bodies touched get their next event. Inelastic collapse (infinitely many collisions
in finite time when ``e < 1``) is stopped by the TC model of Luding and McNamara (Granular
Matter 1, 113 (1998)): a collision of a body whose previous collision (with a body or a wall)
was less than ``t_c`` ago is elastic. It changes only dense, fast-colliding clusters (a heap at
rest keeps a residual jiggle of speed about ``g t_c``) and leaves dilute collisions untouched.

The loop stops at the first event after ``t_end`` (status ``DONE``), when the event buffer is
full (``BUFFER_FULL``: the caller writes it out and calls again), when ``max_events`` have been
handled (``EVENT_LIMIT``), or when a neighbour list or a cell overflows (``LIST_FULL``,
``CELL_FULL``: the caller widens the lists or the cells and starts again from the present).
"""

from __future__ import annotations

import math
from typing import Any

from .calendar import (
    calendar_clear,
    calendar_fetch_ahead,
    calendar_insert,
    calendar_next,
    calendar_pop,
    calendar_remove,
)
from .cells import CELL_FULL, LIST_FULL, build_all_lists, fetch_cells, nearest_image, rebuild_list
from .compile import borrowed, jit, jit_call, jit_inline, prefetch
from .layout import (
    COUNT,
    EDGE,
    EVENT_FULL,
    EVT,
    G_KINETIC,
    G_LOST,
    G_MAX_OVERLAP,
    G_NOW,
    G_VIRIAL,
    G_WALL,
    HPOS,
    K_BUFFERED,
    K_EVENTS,
    K_HEAP,
    K_NLIST,
    K_PAIRS,
    K_STALE,
    K_WALLS,
    KIND,
    KIND_NLIST,
    KIND_NONE,
    KIND_PAIR,
    KIND_WALL,
    MASS,
    NB_UNSCHEDULED,
    NF,
    NI,
    NNB,
    P_CUT,
    P_E,
    P_G,
    P_L,
    P_MIXED,
    P_RADII,
    P_SKIN,
    P_TC,
    PARTNER,
    PCOUNT,
    Q_DIM,
    Q_PERIODIC,
    RADIUS,
    TLAST,
    C,
    T,
    V,
    X,
)
from .predict import ceiling_time, collision_loss, contact_time, floor_time, impulse_magnitude, leave_time, wall_time

__all__ = [
    "BUFFER_FULL",
    "CELL_FULL",
    "DONE",
    "EVENT_LIMIT",
    "LIST_FULL",
    "max_overlap_now",
    "run_events",
    "start",
    "synchronize",
]

DONE = 0
BUFFER_FULL = 1
EVENT_LIMIT = 2


@jit_inline
def _advance(F: Any, i: int, now: float, g: float) -> None:
    dt = now - F[i, T]
    if dt != 0.0:
        F[i, X] += F[i, V] * dt
        F[i, X + 1] += (F[i, V + 1] - 0.5 * g * dt) * dt
        F[i, X + 2] += F[i, V + 2] * dt
        F[i, V + 1] -= g * dt
        F[i, T] = now


@jit_inline
def _soonest_pair(
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
def _predict(heap: Any, lists: Any, F: Any, IX: Any, NB: Any, P: Any, Q: Any, K: Any, i: int, now: float) -> None:
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
        tmin, kind, partner = _soonest_pair(F, IX, NB, P, i, now, tmin, kind, partner, wrap, dim, True)
    else:  # one kind of ball: no radius read (the same loop compiled apart, without the branch)
        tmin, kind, partner = _soonest_pair(F, IX, NB, P, i, now, tmin, kind, partner, wrap, dim, False)
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
def _collide(
    heap: Any,
    lists: Any,
    F: Any,
    IX: Any,
    NB: Any,
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
) -> None:
    j = IX[i, PARTNER]
    g = P[P_G]
    _advance(F, i, now, g)
    if F[j, COUNT] != F[i, PCOUNT]:
        K[K_STALE] += 1
        _predict(heap, lists, F, IX, NB, P, Q, K, i, now)
        return
    _advance(F, j, now, g)
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
        _predict(heap, lists, F, IX, NB, P, Q, K, i, now)
        return
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
    F[i, V] += fi * dx
    F[i, V + 1] += fi * dy
    F[i, V + 2] += fi * dz
    F[j, V] -= fj * dx
    F[j, V + 1] -= fj * dy
    F[j, V + 2] -= fj * dz
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
    _predict(heap, lists, F, IX, NB, P, Q, K, i, now)
    _predict(heap, lists, F, IX, NB, P, Q, K, j, now)


@jit_inline
def _bounce(
    heap: Any,
    lists: Any,
    F: Any,
    IX: Any,
    NB: Any,
    P: Any,
    Q: Any,
    G: Any,
    K: Any,
    S: Any,
    SE: Any,
    buf: Any,
    i: int,
    now: float,
) -> None:
    wall = IX[i, PARTNER]
    _advance(F, i, now, P[P_G])
    k = wall >> 1
    high = (wall & 1) == 1
    v = F[i, V + k]
    g = P[P_G]
    r = F[i, RADIUS]
    floor = wall == 2 and g > 0.0
    into = (v > 0.0) == high and v != 0.0
    if not into and not (floor and F[i, X + 1] <= r):  # not moving into this wall (any more)
        K[K_STALE] += 1
        _predict(heap, lists, F, IX, NB, P, Q, K, i, now)
        return
    e = _restitution(F, P, i, -1, now)
    inward = -1.0 if high else 1.0  # the wall's normal, towards the body
    m = F[i, MASS]
    vn = v * inward  # negative: moving into the wall
    # The contact law with the wall's infinite mass (lab eq. 24): j = -(1 + e) v_n m.
    after = v + inward * impulse_magnitude(vn, 1.0 / m, e) / m
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
    _predict(heap, lists, F, IX, NB, P, Q, K, i, now)


@jit_inline
def _fetch_rows(F: Any, IX: Any, NB: Any, i: int) -> None:
    """Prefetch body ``i``'s rows of ``F``, ``IX`` and its neighbour list (see ``_fetch_ahead``)."""
    prefetch(F, i, 0)
    prefetch(F, i, NF - 1)
    prefetch(IX, i, 0)
    prefetch(IX, i, NI - 1)
    for m in range(0, NB.shape[1], 16):
        prefetch(NB, i, m)


@jit_inline
def _fetch_neighbours(F: Any, IX: Any, NB: Any, i: int) -> None:
    """Prefetch the position, velocity and time of each of ``i``'s neighbours (what predicting
    ``i``'s next collision reads; a mixture's radii are in ``P``, at hand): ``i``'s list must be
    at hand already."""
    for m in range(IX[i, NNB]):
        j = NB[i, m]
        prefetch(F, j, X)
        prefetch(F, j, T)


@jit_inline
def _fetch_ahead(heap: Any, F: Any, IX: Any, NB: Any, P: Any, Q: Any, K: Any, CI: Any, i: int) -> None:
    """Start fetching from memory what the events about to be handled will read, so that the
    fetches run side by side while this event is worked on (with a million bodies the events
    come in no order in space, nearly every row is a cache miss, and the misses of one event
    otherwise come one after another): the rows of this event's neighbours (its body ``i`` and
    its partner, whose lists were fetched one event earlier), and the lists and the partner's
    rows of the next event (the heap's first, unless this event schedules an earlier one), or
    the cells it will look through if it rebuilds its list."""
    _fetch_neighbours(F, IX, NB, i)
    kind = IX[i, KIND]
    if kind == KIND_PAIR:
        _fetch_neighbours(F, IX, NB, IX[i, PARTNER])
    elif kind == KIND_NLIST:
        for m in range(IX[i, NNB]):
            j = NB[i, m]
            prefetch(IX, j, NNB)
            prefetch(NB, j, 0)
    if K[K_HEAP] > 0:
        k = heap[0]
        for m in range(0, NB.shape[1], 16):
            prefetch(NB, k, m)
        kind = IX[k, KIND]
        if kind == KIND_PAIR:
            _fetch_rows(F, IX, NB, IX[k, PARTNER])
        elif kind == KIND_NLIST:
            dt = F[k, EVT] - F[k, T]
            fetch_cells(
                P, Q, CI, F[k, X] + F[k, V] * dt, F[k, X + 1] + F[k, V + 1] * dt, F[k, X + 2] + F[k, V + 2] * dt
            )


@jit
def run_events(
    heap: Any,
    lists: Any,
    CI: Any,
    CF: Any,
    F: Any,
    IX: Any,
    NB: Any,
    P: Any,
    Q: Any,
    G: Any,
    K: Any,
    S: Any,
    KS: Any,
    SE: Any,
    buf: Any,
    t_end: float,
    max_events: int,
) -> int:
    """Handle events in time order up to ``t_end`` (see the module's docstring for the status).
    ``S``, ``KS`` and ``SE``: each body's species, the collisions counted by pair of species and
    each species' kinetic energy and its time integral (a mixture, see :mod:`.layout`), or
    empty (one species: nothing counted apart)."""
    # The caller holds the arrays for the whole call: the loop need not count references to them.
    heap, lists, CI, CF = borrowed(heap), borrowed(lists), borrowed(CI), borrowed(CF)
    F, IX, NB, P, Q = borrowed(F), borrowed(IX), borrowed(NB), borrowed(P), borrowed(Q)
    G, K, S, KS, SE, buf = borrowed(G), borrowed(K), borrowed(S), borrowed(KS), borrowed(SE), borrowed(buf)
    handled = 0
    while True:
        if buf.shape[0] > 0 and K[K_BUFFERED] >= buf.shape[0] - 1:
            return BUFFER_FULL
        if handled >= max_events:
            return EVENT_LIMIT
        i = calendar_next(heap, lists, F, IX, P, Q, K)
        if i < 0 or F[i, EVT] > t_end:
            G[G_NOW] = t_end
            return DONE
        now = F[i, EVT]
        G[G_NOW] = now
        calendar_pop(heap, F, IX, K)
        _fetch_ahead(heap, F, IX, NB, P, Q, K, CI, i)
        calendar_fetch_ahead(F, IX, K)
        handled += 1
        K[K_EVENTS] += 1
        kind = IX[i, KIND]
        if kind == KIND_PAIR:
            _collide(heap, lists, F, IX, NB, P, Q, G, K, S, KS, SE, buf, i, now)
        elif kind == KIND_WALL:
            _bounce(heap, lists, F, IX, NB, P, Q, G, K, S, SE, buf, i, now)
        else:
            _advance(F, i, now, P[P_G])
            K[K_NLIST] += 1
            status = rebuild_list(F, IX, NB, P, Q, CI, CF, i)
            if status != 0:
                return status
            _predict(heap, lists, F, IX, NB, P, Q, K, i, now)


@jit
def synchronize(F: Any, P: Any, now: float) -> None:
    """Move every body to ``now`` (positions and velocities then all hold at one time)."""
    g = P[P_G]
    for i in range(F.shape[0]):
        _advance(F, i, now, g)


@jit
def start(heap: Any, lists: Any, CI: Any, CF: Any, F: Any, IX: Any, NB: Any, P: Any, Q: Any, K: Any, now: float) -> int:
    """Bring every body to ``now``, build every list, and predict every event afresh (the
    beginning of a run, or a restart after the neighbour lists or cells were widened). 0, or
    ``LIST_FULL`` / ``CELL_FULL``."""
    heap, lists, CI, CF = borrowed(heap), borrowed(lists), borrowed(CI), borrowed(CF)
    F, IX, NB, P, Q, K = borrowed(F), borrowed(IX), borrowed(NB), borrowed(P), borrowed(Q), borrowed(K)
    synchronize(F, P, now)
    status = build_all_lists(F, IX, NB, P, Q, CI, CF)
    if status != 0:
        return status
    calendar_clear(lists, IX, P, K, now)
    for i in range(F.shape[0]):
        _predict(heap, lists, F, IX, NB, P, Q, K, i, now)
    return 0


@jit
def max_overlap_now(F: Any, IX: Any, NB: Any, P: Any, Q: Any) -> float:
    """The deepest overlap of any pair of neighbours or any body and wall, bodies as they are
    stored (call :func:`synchronize` first); negative: the smallest gap."""
    periodic = Q[Q_PERIODIC] != 0
    worst = -math.inf
    for i in range(F.shape[0]):
        r = F[i, RADIUS]
        for m in range(IX[i, NNB]):
            j = NB[i, m]
            if j < i:
                continue
            d2 = 0.0
            for k in range(Q[Q_DIM]):
                d = F[i, X + k] - F[j, X + k]
                if periodic:
                    d = nearest_image(d, P[P_L + k])
                d2 += d * d
            worst = max(worst, r + F[j, RADIUS] - math.sqrt(d2))
        if not periodic:
            for k in range(Q[Q_DIM]):
                worst = max(worst, r - F[i, X + k], F[i, X + k] - (P[P_L + k] - r))
    return worst
