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
    calendar_next,
    calendar_pop,
)
from .cells import CELL_FULL, LIST_FULL, build_all_lists, fetch_cells, nearest_image, rebuild_list
from .collide import bounce, collide
from .compile import borrowed, jit, jit_inline, prefetch
from .layout import (
    EVT,
    G_NOW,
    K_BUFFERED,
    K_EVENTS,
    K_HEAP,
    K_NLIST,
    KIND,
    KIND_NLIST,
    KIND_PAIR,
    KIND_WALL,
    NF,
    NI,
    NNB,
    P_G,
    P_L,
    PARTNER,
    Q_DIM,
    Q_PERIODIC,
    RADIUS,
    T,
    V,
    X,
)
from .schedule import advance, predict_next

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
        partner = -1
        if kind == KIND_PAIR:
            partner = collide(heap, lists, F, IX, P, Q, G, K, S, KS, SE, buf, i, now)
        elif kind == KIND_WALL:
            bounce(F, IX, P, G, K, S, SE, buf, i, now)
        else:
            advance(F, i, now, P[P_G])
            K[K_NLIST] += 1
            status = rebuild_list(F, IX, NB, P, Q, CI, CF, i)
            if status != 0:
                return status
        # The next events of i, then of its partner if it collided: one copy of the prediction in
        # the loop's code, which numba inlines where it is called (a copy at each of the seven
        # places that predicted made the loop's compile several times longer and larger; the
        # same prediction called, not inlined, ran slower: bench/LOG.md, "One prediction").
        while i >= 0:
            predict_next(heap, lists, F, IX, NB, P, Q, K, i, now)
            i, partner = partner, -1


@jit
def synchronize(F: Any, P: Any, now: float) -> None:
    """Move every body to ``now`` (positions and velocities then all hold at one time)."""
    g = P[P_G]
    for i in range(F.shape[0]):
        advance(F, i, now, g)


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
        predict_next(heap, lists, F, IX, NB, P, Q, K, i, now)
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
