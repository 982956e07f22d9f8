"""The contact stepper over arrays: impacts at their time of impact, slow and resting contacts
solved together at mid-step, supported bodies at rest asleep. Written once: Python for small
worlds, compiled by numba (:mod:`collisionlab.engine.compiled`) for large ones.

One step of ``dt`` (``h = dt / 2``), in this fixed order:

1. **Candidates.** Every pair that can meet before the step ends is listed (sort and sweep along
   x, the order kept from step to step so the insertion sort is nearly free; Ericson 7.2.1): two
   bodies whose boxes, each widened by ``u dt``, overlap and whose gap is within ``2 u dt``, a
   body and a static within ``u dt + |g| dt^2 / 2``; ``u`` bounds every awake body's speed over
   the step. Two sleeping bodies are never listed. A kick past ``u``, or a body woken, lists
   again from that time.
2. **Flight to mid-step** with impacts: every body flies its parabola ``x + v t + g t^2 / 2``
   (a kinematic body, of infinite mass, its line). Each candidate pair's time of impact is found
   by conservative advancement along the separating normal (Mirtich 1996; two balls in the same
   field of gravity in closed form, Ericson 4.4.3), the earliest first. An approach faster than
   the rest speed ``v_rest`` is an impact: ``j = -(1 + e) v_n / (1/m_a + 1/m_b)`` (lab eqs. 12,
   15, 24), an event, and the pair's bodies have their other pairs predicted again (a row of
   touching balls passes a blow along, one impact after another, as in Newton's cradle). A slower
   approach is no event: it is left to the solve. A body's impacts past ``MAX_BODY_IMPACTS`` in
   one half step are perfectly inelastic (a collapsing cluster).
3. **Solve at mid-step** (Moreau's midpoint scheme; Moreau 1988, Jean 1999): every candidate
   pair touching, or apart and approaching slower than ``v_rest``, is a contact. Their normal
   impulses ``P >= 0`` are found together so that no pair is closing at the step's end: a pair
   in contact stops approaching (an overlap stops growing; push-apart undoes it), and a pair
   still apart may close its gap no sooner than it is solved again (a speculative contact, as in
   Box2D v3). That is a bound-constrained quadratic program in ``P`` (the Signorini condition at
   velocity level), started from the last step's impulses (contact memory, keyed by the pair)
   and iterated until every contact's projected gradient is below ``SOLVER_TOLERANCE``: first by
   MPRGP (modified proportioning with reduced gradient projections, Dostal 2009; conjugate
   gradients on the pushing contacts, which end a stack's in a few iterations), then, for a heap
   whose pushing set keeps changing, by accelerated projected gradient descent (APGD; Mazhar et
   al. 2015), both far fewer iterations than Gauss-Seidel sweeps for the bottom of a deep pile,
   up to ``MPRGP_SWEEPS`` and ``APGD_SWEEPS``. A body at rest on a support
   gets ``-g h`` at mid-step, which its flight turns into 0 by the step's end: an impulse applied
   at mid-step between two exact half flights is Moreau's ``x' = x + (v + v') dt / 2``,
   ``v' = v + g dt + P / m``, so free flight stays exact and a support does no work on a body at
   rest.
4. **Flight to the step's end**, with impacts as in 2.
5. **End of the step**: overlaps deeper than ``slop`` left (the solve's residual) are pushed
   apart, all at once, without touching velocities (the energy in the ledger's
   push-apart column); then **sleep**: bodies joined by contacts form islands (union-find). An island that
   touches a static, holds no kinematic body, and whose bodies all stayed slower than
   ``SLEEP_SPEED`` for ``SLEEP_TIME`` falls asleep: it no longer flies, is solved or listed
   against itself, and its supports go on carrying exactly its weight (``static_impulses``). An
   island is pushed apart once more as it falls asleep, to convergence (``SETTLE_ROUNDS``): a
   pile at rest shows no overlap one step's push-apart left. An impact on a sleeping body, or a
   contact of an awake body with it, wakes its island.

Each static's total impulse on the bodies is summed in ``static_impulse`` (momentum balance:
their sum is ``P_end - P_start - M g T``).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..tolerances import APPROACH_ROUNDING, SLEEP_SPEED, SLEEP_TIME, SOLVER_TOLERANCE, TOI_GAP

if "_GEOMETRY" in globals():  # the compiled copy: the kernels it calls are compiled too
    gk: Any = globals()["_GEOMETRY"]
    sk: Any = globals()["_STEP"]
    eh: Any = globals()["_HEAP"]
else:
    from . import event_heap as eh
    from . import geometry_kernels as gk
    from . import step_kernels as sk

__all__ = ["MAX_IMPACTS_PER_STEP", "PAIR_COLUMNS", "STATUS_SIZE", "run_contact_steps"]

#: The most impacts resolved within one flight; past it the flight ends without the rest (the
#: world warns; ``status[0]`` counts such flights).
MAX_IMPACTS_PER_STEP = 100_000
#: The most impacts with e one body takes in one half step's flight: its later ones in it are
#: perfectly inelastic (e = 0), and past four times as many its approaches are left to the
#: solve, as slow ones are (a cluster of bodies squeezed together would otherwise collide ever
#: faster: inelastic collapse, McNamara and Young 1992). A blow passing along a row of touching
#: balls (Newton's cradle) takes two impacts per ball.
MAX_BODY_IMPACTS = 8
#: The calendar has room for this many entries per candidate pair (and 2 more): a full one is
#: compacted (:func:`~collisionlab.engine.event_heap.heap_compact`) to at most the current ones.
HEAP_ROOM = 2
#: The most iterations of conservative advancement for one prediction; the time reached is then
#: used (never after the impact: the pair is looked at again there).
TOI_ITERATIONS = 64
#: The most iterations of a solve most of whose touching contacts are new (nothing to start from: a
#: stack's first step, where a column of k balls needs of the order of k^2 sweeps).
COLD_SOLVER_SWEEPS = 2000
#: A warm solve's most MPRGP iterations (enough for a stack), then APGD's (a heap); one that
#: stops there is counted in ``status[2]``. Fewer left the 2,000-circle pour jittering
#: (bench/README.md, ``bench_piles.py``).
MPRGP_SWEEPS = 50
APGD_SWEEPS = 300
#: The most rounds of push-apart at the end of a step, and the most iterations of each (a
#: solve of its own, from the gaps anew): MPRGP alone (with APGD after 20 of it, the pour's
#: push-apart booked 1 J a step and the pile never slept). One short round: a step's overlaps
#: are the solve's residual, and more rounds only move the pile about (the 2,000-circle pour
#: booked twice the push-apart energy with 2 x 100 and slept later; with 1 x 5 its overlaps
#: grew and it never slept: bench/LOG.md).
PUSH_ROUNDS = 1
PUSH_MPRGP = 20
PUSH_APGD = 0
#: Push-apart's rounds and iterations over an island as it falls asleep: once, so thorough.
SETTLE_ROUNDS = 8
SETTLE_MPRGP = 50
SETTLE_APGD = 2000
#: An axis counts as spanned by a sleeping island's support normals when its diagonal entry of
#: ``sum P_w n_w n_w^T`` is more than this fraction of the trace (dimensionless): a 2D world's
#: z axis (exactly 0) never is, and a share along an axis no support pushes on is not booked.
SPAN_FRACTION = 1e-12
#: Columns of a pair's float row in the solve: height (times ``|g|``), normal (3), gap at
#: mid-step, impulse, target normal velocity, inverse mass sum, what the relative acceleration
#: adds to the normal velocity by the step's end.
PAIR_COLUMNS = 9
#: Counters returned to the world: flights that hit MAX_IMPACTS_PER_STEP, impacts, solves that
#: hit their cap, listings, bodies asleep now, iterations of the solves.
STATUS_SIZE = 6
#: What a flight returns with: it reached its end; it must list the candidates again first.
DONE = 0
RESTART = 1

INLINE = ("_at", "_sep_of", "_sep_now", "_key", "_find", "_kick")


# --- flight ----------------------------------------------------------------------------------------
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


def _sep_of(
    kind: Any, ext: Any, s_kind: Any, s_a: Any, s_b: Any, a: int, b: int,
    ax: float, ay: float, az: float, bx: float, by: float, bz: float,
) -> Any:  # fmt: skip
    """Separation of pair ``(a, b)`` (``a < 0``: the static ``-1 - a``) with the bodies at the
    given positions, normal from a to b."""
    if a >= 0:
        return sk._pair_sep(
            kind[a], ax, ay, az, ext[a, 0], ext[a, 1], ext[a, 2], kind[b], bx, by, bz, ext[b, 0], ext[b, 1], ext[b, 2]
        )
    s = -1 - a
    return sk._static_sep(
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
    conservative advancement (the module's phase 2): the gap along the current normal ``n`` is
    ``d + (w.n) s + (alpha.n) s^2 / 2`` (``w``, ``alpha``: relative velocity and acceleration)
    and the true gap is never below it, so its first root is never after the impact. A pair
    touching and moving apart is followed to when its gap along ``n`` closes again, once. A
    pair that touches approaching no faster than ``rest_speed`` gets ``inf``: that is no impact."""
    straight = a >= 0 and kind[a] <= sk.BALL_3D and kind[b] <= sk.BALL_3D
    alx = acc[b, 0] - (acc[a, 0] if a >= 0 else 0.0)
    aly = acc[b, 1] - (acc[a, 1] if a >= 0 else 0.0)
    alz = acc[b, 2] - (acc[a, 2] if a >= 0 else 0.0)
    straight = straight and alx == 0.0 and aly == 0.0 and alz == 0.0
    jumped = False
    for _ in range(TOI_ITERATIONS):
        bx, vbx = _at(pos, vel, acc, tau, b, t, 0)
        by, vby = _at(pos, vel, acc, tau, b, t, 1)
        bz, vbz = _at(pos, vel, acc, tau, b, t, 2)
        ax = ay = az = vax = vay = vaz = 0.0
        if a >= 0:
            ax, vax = _at(pos, vel, acc, tau, a, t, 0)
            ay, vay = _at(pos, vel, acc, tau, a, t, 1)
            az, vaz = _at(pos, vel, acc, tau, a, t, 2)
        sep = _sep_of(kind, ext, s_kind, s_a, s_b, a, b, ax, ay, az, bx, by, bz)
        wx, wy, wz = vbx - vax, vby - vay, vbz - vaz
        s1 = wx * sep[1] + wy * sep[2] + wz * sep[3]
        s2 = 0.5 * (alx * sep[1] + aly * sep[2] + alz * sep[3])
        if sep[0] <= TOI_GAP:
            still = APPROACH_ROUNDING * (abs(vax) + abs(vay) + abs(vaz) + abs(vbx) + abs(vby) + abs(vbz))
            if -s1 > rest_speed:
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


def _predict(
    kind: Any, pos: Any, vel: Any, acc: Any, tau: Any, ext: Any, s_kind: Any, s_a: Any, s_b: Any,
    pairs: Any, ver: Any, p: int, t: float, t_end: float, rest_speed: float, ht: Any, hk: Any, hv: Any, size: int,
) -> int:  # fmt: skip
    """Predict pair ``p`` again from ``t``: a new version, on the calendar if it meets before
    ``t_end``; returns the calendar's size."""
    ver[p] += 1
    when = _pair_toi(kind, pos, vel, acc, tau, ext, s_kind, s_a, s_b, pairs[p, 0], pairs[p, 1], t, t_end, rest_speed)
    if when >= t_end:
        return size
    size = eh.heap_compact(ht, hk, hv, size, ver)
    return int(eh.heap_push(ht, hk, hv, size, when, p, ver[p]))


# --- islands ---------------------------------------------------------------------------------------
def _root(parent: Any, i: int) -> int:
    """The root of ``i`` in a union-find forest, halving the path on the way (Tarjan)."""
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


def _wake(
    island: Any, asleep: Any, acc: Any, ima: Any, gravity: Any, tau: Any, t: float, which: int,
    rows_i: Any, rows_f: Any, row_count: Any, static_impulse: Any, held: float,
) -> int:  # fmt: skip
    """Wake every body of island ``which`` at time ``t``; returns how many woke. Its supports
    carried it for the fraction ``held`` of this step: that share of their impulse per step is
    booked (:func:`_sleep` books only the islands asleep at the step's end)."""
    woke = sk._int(0)
    for i in range(island.shape[0]):
        if asleep[i] != 0 and island[i] == which:
            asleep[i] = 0
            tau[i] = t
            for k in range(3):
                acc[i, k] = gravity[k] if ima[i] > 0.0 else 0.0
            woke += 1
    for r in range(row_count[0]):
        if asleep[rows_i[r, 1]] == 0 and island[rows_i[r, 1]] == which:
            for k in range(3):
                static_impulse[rows_i[r, 0], k] += held * rows_f[r, k]
    return int(woke)


# --- candidates ----------------------------------------------------------------------------------
def _list_pairs(
    kind: Any, pos: Any, ext: Any, asleep: Any, s_kind: Any, s_a: Any, s_b: Any,
    order: Any, lo: Any, dims: int, reach: float, static_reach: float, pairs: Any,
) -> Any:  # fmt: skip
    """The candidate pairs (module phase 1) into ``pairs`` (grown when full); returns it and the
    count. ``order`` keeps the bodies sorted by their lower x bound from the last listing."""
    n = pos.shape[0]
    for i in range(n):
        lo[i] = pos[i, 0] - ext[i, 0] - reach
    for q in range(1, n):  # insertion sort: the order of the last step is nearly right
        i = order[q]
        key = lo[i]
        r = q - 1
        while r >= 0 and lo[order[r]] > key:
            order[r + 1] = order[r]
            r -= 1
        order[r + 1] = i
    count = sk._int(0)
    for q in range(n):
        i = order[q]
        hi = pos[i, 0] + ext[i, 0] + reach
        for r in range(q + 1, n):
            j = order[r]
            if lo[j] > hi:
                break
            if asleep[i] != 0 and asleep[j] != 0:
                continue
            if abs(pos[i, 1] - pos[j, 1]) > ext[i, 1] + ext[j, 1] + 2.0 * reach:
                continue
            if dims == 3 and abs(pos[i, 2] - pos[j, 2]) > ext[i, 2] + ext[j, 2] + 2.0 * reach:
                continue
            a, b = (i, j) if i < j else (j, i)
            sep = _sep_of(
                kind, ext, s_kind, s_a, s_b, a, b, pos[a, 0], pos[a, 1], pos[a, 2], pos[b, 0], pos[b, 1], pos[b, 2]
            )
            if sep[0] > 2.0 * reach:
                continue
            if count == pairs.shape[0]:
                pairs = _grown_int(pairs)
            pairs[count, 0] = a
            pairs[count, 1] = b
            count += 1
    for i in range(n):
        if asleep[i] != 0:
            continue
        for s in range(s_kind.shape[0]):
            sep = _sep_of(kind, ext, s_kind, s_a, s_b, -1 - s, i, 0.0, 0.0, 0.0, pos[i, 0], pos[i, 1], pos[i, 2])
            if sep[0] > static_reach:
                continue
            if count == pairs.shape[0]:
                pairs = _grown_int(pairs)
            pairs[count, 0] = -1 - s
            pairs[count, 1] = i
            count += 1
    return pairs, count


def _grown_int(a: Any) -> Any:
    grown = np.zeros((2 * a.shape[0] + 16, a.shape[1]), np.int64)
    grown[: a.shape[0]] = a
    return grown


def _grown_float(a: Any, rows: int) -> Any:
    if a.shape[0] >= rows:
        return a
    grown = np.zeros((max(rows, 2 * a.shape[0] + 16), a.shape[1]))
    grown[: a.shape[0]] = a
    return grown


def _adjacency(pairs: Any, count: int, n: int, start: Any, adj: Any) -> Any:
    """Each body's pairs: ``adj[start[i]:start[i + 1]]`` (a counting sort); returns ``adj``."""
    if adj.shape[0] < 2 * count:
        adj = np.zeros(4 * count + 16, np.int64)
    for i in range(n + 1):
        start[i] = 0
    for p in range(count):
        for end in range(2):
            i = pairs[p, end]
            if i >= 0:
                start[i + 1] += 1
    for i in range(n):
        start[i + 1] += start[i]
    fill = start[:n].copy()
    for p in range(count):
        for end in range(2):
            i = pairs[p, end]
            if i >= 0:
                adj[fill[i]] = p
                fill[i] += 1
    return adj


def _speed_bound(vel: Any, asleep: Any, gravity: Any, dt: float) -> float:
    """A bound on every awake body's speed over a step: the fastest now, plus what gravity adds
    in a step (and what the solve may give back of it)."""
    fastest = 0.0
    for i in range(vel.shape[0]):
        if asleep[i] == 0:
            fastest = max(fastest, math.sqrt(vel[i, 0] ** 2 + vel[i, 1] ** 2 + vel[i, 2] ** 2))
    g = math.sqrt(gravity[0] ** 2 + gravity[1] ** 2 + gravity[2] ** 2)
    return fastest + 2.0 * g * dt


# --- impacts ---------------------------------------------------------------------------------------
def _flight(
    kind: Any, pos: Any, vel: Any, acc: Any, tau: Any, ext: Any, ima: Any, eb: Any, ids: Any,
    s_kind: Any, s_a: Any, s_b: Any, s_e: Any, gravity: Any, asleep: Any, island: Any,
    pairs: Any, count: int, ver: Any, hits: Any, ht: Any, hk: Any, hv: Any, start: Any, adj: Any,
    t: float, t_end: float, u: float, e_default: float, rest_speed: float,
    step: int, dt: float, record: bool, events: Any, event_count: Any, ledger: Any,
    static_impulse: Any, rows_i: Any, rows_f: Any, row_count: Any, status: Any,
) -> Any:  # fmt: skip
    """Fly from ``t`` to ``t_end`` (times within the step), resolving impacts earliest first
    (module phase 2) from a calendar of predictions (:mod:`.event_heap`; a pair's older
    predictions are dropped by version). Returns ``(code, t, events)``: ``DONE`` with every body
    at ``t_end``, or ``RESTART`` at ``t`` (every body brought there) when a kick outran ``u`` or
    woke an island. ``hits`` counts each body's impacts in this flight."""
    size = sk._int(0)
    for p in range(count):
        size = _predict(
            kind, pos, vel, acc, tau, ext, s_kind, s_a, s_b, pairs, ver, p, t, t_end, rest_speed, ht, hk, hv, size
        )
    before = np.zeros(6)
    for _ in range(MAX_IMPACTS_PER_STEP):
        best = -1
        while size > 0:
            best = hk[0]
            current = hv[0] == ver[best]
            t_next = ht[0]
            size = eh.heap_pop(ht, hk, hv, size)
            if current:
                break
            best = -1
        if best < 0:
            _advance_all(pos, vel, acc, tau, t_end)
            return DONE, t_end, events
        a = pairs[best, 0]
        b = pairs[best, 1]
        t = t_next
        _advance(pos, vel, acc, tau, b, t)
        if a >= 0:
            _advance(pos, vel, acc, tau, a, t)
        sep = _sep_now(kind, pos, ext, s_kind, s_a, s_b, a, b)
        vn = 0.0
        for k in range(3):
            vn += (vel[b, k] - (vel[a, k] if a >= 0 else 0.0)) * sep[1 + k]
        most = max(hits[b], hits[a] if a >= 0 else 0)
        if -vn <= rest_speed or most >= 4 * MAX_BODY_IMPACTS:
            continue  # a slow approach, or a body in a cluster that will not stop: the solve's
        sleeper = b if asleep[b] != 0 else (a if a >= 0 and asleep[a] != 0 else -1)
        if sleeper >= 0:
            _wake(island, asleep, acc, ima, gravity, tau, t, island[sleeper], rows_i, rows_f, row_count,
                  static_impulse, t / dt)  # fmt: skip
            _advance_all(pos, vel, acc, tau, t)
            return RESTART, t, events
        ima_a = ima[a] if a >= 0 else 0.0
        inv_sum = ima_a + ima[b]
        if inv_sum == 0.0:
            continue
        e = sk._pair_e(eb[a] if a >= 0 else s_e[-1 - a], eb[b], e_default) if most < MAX_BODY_IMPACTS else 0.0
        j = gk.impulse_magnitude(vn, inv_sum, e)
        kinetic = 0.0
        for k in range(3):
            before[k] = vel[a, k] if a >= 0 else 0.0
            before[3 + k] = vel[b, k]
            vb = vel[b, k] + j * ima[b] * sep[1 + k]
            if ima[b] > 0.0:
                kinetic += (vb * vb - vel[b, k] * vel[b, k]) / ima[b]
            vel[b, k] = vb
            if a >= 0:
                va = vel[a, k] - j * ima_a * sep[1 + k]
                if ima_a > 0.0:
                    kinetic += (va * va - vel[a, k] * vel[a, k]) / ima_a
                vel[a, k] = va
            else:
                static_impulse[-1 - a, k] += j * sep[1 + k]
        ledger[1] += 0.5 * kinetic
        ledger[3] -= 0.5 * (1.0 - e * e) * vn * vn / inv_sum
        ledger[5 if a >= 0 else 6] += 1.0
        status[1] += 1
        if record:
            id_a = ids[a] if a >= 0 else a
            when = (step - 1) * dt + t
            events = sk._write_event(events, event_count[0], sk.EVENT_IMPACT, step, when, id_a, ids[b], sep, vn, j, e,
                                     before, vel, a, b)  # fmt: skip
            event_count[0] += 1
        outran = False
        for end in range(2):
            i = b if end == 0 else a
            if i < 0:
                continue
            hits[i] += 1
            if vel[i, 0] ** 2 + vel[i, 1] ** 2 + vel[i, 2] ** 2 > u * u:
                outran = True
            for q in range(start[i], start[i + 1]):
                size = _predict(kind, pos, vel, acc, tau, ext, s_kind, s_a, s_b, pairs, ver, adj[q], t, t_end,
                                rest_speed, ht, hk, hv, size)  # fmt: skip
        if outran:
            _advance_all(pos, vel, acc, tau, t)
            return RESTART, t, events
    status[0] += 1
    _advance_all(pos, vel, acc, tau, t_end)
    return DONE, t_end, events


# --- the solve -------------------------------------------------------------------------------------
def _key(a: int, b: int, m: int, n: int) -> int:
    """A pair's key in the contact memory (a static ``a = -1 - s`` comes first)."""
    return (a + m) * n + b


def _find(keys: Any, count: int, key: int) -> int:
    """Where ``key`` is in the sorted ``keys[:count]``, or -1 (binary search)."""
    lo = sk._int(0)
    hi = count
    while lo < hi:
        mid = (lo + hi) // 2
        if keys[mid] < key:
            lo = mid + 1
        else:
            hi = mid
    return lo if lo < count and keys[lo] == key else -1


def _solve(
    kind: Any, pos: Any, vel: Any, acc: Any, ext: Any, ima: Any, s_kind: Any, s_a: Any, s_b: Any,
    asleep: Any, pairs: Any, count: int, pf: Any, contacts: Any, memory: Any, memory_lam: Any,
    memory_count: Any, gravity: Any, dt: float, rest_speed: float, contact_margin: float, ledger: Any,
    static_impulse: Any, status: Any,
) -> Any:  # fmt: skip
    """The mid-step solve (module phase 3) over the candidates; every body is at mid-step.
    Returns ``(contacts, c, memory, memory_lam, woken)``: the contacts' pair numbers, how many,
    the new memory, and a sleeping body an awake one touches (-1 if none: then nothing is
    solved, the caller wakes its island and lists again)."""
    m = s_kind.shape[0]
    n = pos.shape[0]
    h = 0.5 * dt
    c = sk._int(0)
    cold = sk._int(0)  # contacts touching with nothing remembered
    for p in range(count):
        a = pairs[p, 0]
        b = pairs[p, 1]
        sep = _sep_now(kind, pos, ext, s_kind, s_a, s_b, a, b)
        vn = 0.0
        gn = 0.0
        for k in range(3):
            vn += (vel[b, k] - (vel[a, k] if a >= 0 else 0.0)) * sep[1 + k]
            gn += (acc[b, k] - (acc[a, k] if a >= 0 else 0.0)) * sep[1 + k]
        if -vn > rest_speed and sep[0] > contact_margin:
            continue  # an impact to come: the flights' (one passed over in a collapsing cluster is solved)
        if sep[0] > contact_margin and asleep[b] + (asleep[a] if a >= 0 else 0) != 0:
            continue  # not touching a sleeper yet: it wakes when it is touched
        if asleep[b] != 0:
            return contacts, 0, memory, memory_lam, b
        if a >= 0 and asleep[a] != 0:
            return contacts, 0, memory, memory_lam, a
        inv_sum = (ima[a] if a >= 0 else 0.0) + ima[b]
        if inv_sum == 0.0:
            continue
        if c == contacts.shape[0]:
            grown = np.zeros(2 * c + 16, np.int64)
            grown[:c] = contacts
            contacts = grown
        contacts[c] = p
        c += 1
        for k in range(3):
            pf[p, 1 + k] = sep[1 + k]
        pf[p, 0] = -(gravity[0] * sep[4] + gravity[1] * sep[5] + gravity[2] * sep[6])  # height x |g|
        pf[p, 4] = sep[0]
        # The gap at the step's end is G + v'_n h, G = gap - (alpha.n) h^2 / 2 (the second half's
        # flight): a pair apart (G >= 0) may close it no sooner than a step later (G + v'_n 1.5 dt
        # >= 0: it is solved again before it could touch); an overlap (G < 0) stops closing, and
        # push-apart undoes it. (A target that pushed overlaps apart would ask a jammed pile to
        # lift itself: impulses growing step after step, then let go as a kick.)
        undipped = sep[0] - 0.5 * gn * h * h
        pf[p, 6] = -undipped / (3.0 * h) if undipped >= 0.0 else 0.0
        pf[p, 7] = inv_sum
        pf[p, 8] = gn * h
        found = _find(memory, memory_count[0], _key(a, b, m, n))
        pf[p, 5] = memory_lam[found] if found >= 0 else 0.0
        cold += found < 0 and sep[0] <= contact_margin
    heights = np.empty(c)
    for q in range(c):
        heights[q] = pf[contacts[q], 0]
    contacts[:c] = contacts[:c][np.argsort(heights, kind="mergesort")]  # lowest first: a weight
    # passes down a heap to its floor in one sweep (a stable sort: the same order both forms)
    kinetic = _contact_kinetic(pairs, contacts, c, vel, ima, n)
    approach = np.empty(c)  # each contact's normal velocity before the solve
    for q in range(c):
        approach[q] = _normal_velocity(pairs, pf, contacts[q], vel)
    for q in range(c):  # the warm start
        p = contacts[q]
        _apply(pairs, pf, p, vel, ima, pf[p, 5])
    # The contacts as dense rows in sweep order, what every sweep reads in sequence: bodies;
    # normal (3), target, inverse mass sum, the acceleration's share, impulse.
    ca = np.empty(c, np.int64)
    cb = np.empty(c, np.int64)
    cf = np.empty((c, 7))
    for q in range(c):
        p = contacts[q]
        ca[q] = pairs[p, 0]
        cb[q] = pairs[p, 1]
        for k in range(3):
            cf[q, k] = pf[p, 1 + k]
        cf[q, 3] = pf[p, 6]
        cf[q, 4] = pf[p, 7]
        cf[q, 5] = pf[p, 8]
        cf[q, 6] = pf[p, 5]
    if 2 * cold > c:
        if not _mprgp(ca, cb, cf, c, vel, ima, n, sk._int(COLD_SOLVER_SWEEPS), status):
            status[2] += 1
    elif not _qp(ca, cb, cf, c, vel, ima, n, sk._int(MPRGP_SWEEPS), sk._int(APGD_SWEEPS), status):
        status[2] += 1
    for q in range(c):
        pf[contacts[q], 5] = cf[q, 6]
    ledger[1] += _contact_kinetic(pairs, contacts, c, vel, ima, n) - kinetic
    # Theory's account of the same, contact by contact: an impulse P that takes a normal velocity
    # from v_n to v_n' does work P (v_n + v_n') / 2 (kinetic energy is quadratic: with
    # dv = M^-1 J^T P, dK = P.J v + P.A P / 2 and v_n' = v_n + (A P)_n), summed over the contacts;
    # for one contact stopped (v_n' = 0, P = -mu v_n) the lab's -(1 - e^2) mu v_n^2 / 2 at e = 0.
    work = 0.0
    for q in range(c):
        p = contacts[q]
        work += pf[p, 5] * (approach[q] + _normal_velocity(pairs, pf, p, vel))
    ledger[3] += 0.5 * work
    kept = sk._int(0)
    for q in range(c):
        kept += pf[contacts[q], 5] > 0.0
    memory = np.empty(kept, np.int64)  # the pairs pushing, for the warm start and the islands
    lam = np.empty(kept)
    kept = sk._int(0)
    for q in range(c):
        p = contacts[q]
        a = pairs[p, 0]
        if pf[p, 5] <= 0.0:
            continue
        memory[kept] = _key(a, pairs[p, 1], m, n)
        lam[kept] = pf[p, 5]
        kept += 1
        if a < 0:
            for k in range(3):
                static_impulse[-1 - a, k] += pf[p, 5] * pf[p, 1 + k]
    order = np.argsort(memory)  # the keys are distinct: any sort gives this order
    memory_count[0] = kept
    return contacts, c, memory[order], lam[order], -1


def _gradient(ca: Any, cb: Any, cf: Any, c: int, vel: Any, g: Any) -> None:
    """Each contact's gradient ``g = v_n + (alpha.n) h - target``: how much faster than its
    target it separates by the step's end (the velocities ``vel`` hold the impulses so far)."""
    for q in range(c):
        a = ca[q]
        b = cb[q]
        vn = cf[q, 5] - cf[q, 3]
        for k in range(3):
            vn += (vel[b, k] - (vel[a, k] if a >= 0 else 0.0)) * cf[q, k]
        g[q] = vn


def _product(ca: Any, cb: Any, cf: Any, c: int, ima: Any, d: Any, u: Any, ad: Any, g: Any) -> Any:
    """``ad = A d`` with ``A = J M^-1 J^T`` (the Delassus operator): ``u`` (all 0 on entry) gets
    each body's velocity change from the impulses ``d`` (``u = M^-1 J^T d``), ``ad`` each
    contact's normal part of it (``J u``). Returns ``(d.A d, g.d, the longest step -t d keeps
    every impulse >= 0)``, summed in the same pass."""
    for q in range(c):
        _kick(u, ima, ca[q], cb[q], cf, q, d[q])
    dad = 0.0
    gd = 0.0
    feasible = math.inf
    for q in range(c):
        a = ca[q]
        b = cb[q]
        s = 0.0
        for k in range(3):
            s += (u[b, k] - (u[a, k] if a >= 0 else 0.0)) * cf[q, k]
        ad[q] = s
        dad += d[q] * s
        gd += g[q] * d[q]
        if d[q] > 0.0:
            feasible = min(feasible, cf[q, 6] / d[q])
    return dad, gd, feasible


def _move(ca: Any, cb: Any, cf: Any, c: int, vel: Any, u: Any, g: Any, ad: Any, d: Any, step: float) -> float:
    """Impulses ``-= step d``, and with them the velocities and the gradient; ``u`` is left all
    0. Returns the new free gradient's product with ``ad`` (the conjugate step's ``phi.A p``)."""
    fad = 0.0
    for q in range(c):
        cf[q, 6] = max(cf[q, 6] - step * d[q], 0.0)
        g[q] -= step * ad[q]
        if cf[q, 6] > 0.0:
            fad += g[q] * ad[q]
        a = ca[q]
        b = cb[q]
        for k in range(3):
            vel[b, k] -= step * u[b, k]
            u[b, k] = 0.0  # each body moved once
            if a >= 0:
                vel[a, k] -= step * u[a, k]
                u[a, k] = 0.0
    return fad


def _bound(ca: Any, cb: Any, c: int, ima: Any, n: int) -> float:
    """Gershgorin's bound on ``||A||``, ``A = J M^-1 J^T``: the largest row sum of ``|A|``."""
    degree = np.zeros(n)
    for q in range(c):
        degree[cb[q]] += 1.0
        if ca[q] >= 0:
            degree[ca[q]] += 1.0
    norm = 0.0
    for q in range(c):
        a = ca[q]
        b = cb[q]
        norm = max(norm, ima[b] * degree[b] + (ima[a] * degree[a] if a >= 0 else 0.0))
    return norm


def _qp(ca: Any, cb: Any, cf: Any, c: int, vel: Any, ima: Any, n: int, first: int, then: int, status: Any) -> bool:
    """The contacts' quadratic program: up to ``first`` iterations of :func:`_mprgp` (which ends a
    stack's in a few), then up to ``then`` of :func:`_apgd` from where it stopped (a heap's).
    Returns whether it converged."""
    if _mprgp(ca, cb, cf, c, vel, ima, n, first, status):
        return True
    return then > 0 and _apgd(ca, cb, cf, c, vel, ima, n, then, status)


def _apgd(ca: Any, cb: Any, cf: Any, c: int, vel: Any, ima: Any, n: int, iterations: int, status: Any) -> bool:
    """The quadratic program of :func:`_mprgp` by accelerated projected gradient descent (Nesterov's
    method with the gradient restart; Mazhar, Heyn, Negrut and Tasora 2015, as in Chrono): each
    iteration a step ``1 / ||A||`` down the gradient at the extrapolated point ``y``, projected
    onto ``P >= 0``, then ``y`` moved on with momentum. Where the pushing set keeps changing
    (a heap of balls in a lattice has more contacts than degrees of freedom: ``A`` is singular
    and MPRGP spends its iterations restarting) it gains steadily, at three passes over the
    contacts an iteration. ``vel`` holds the velocities of the impulses ``cf[:, 6]`` on entry and
    on return. Returns whether every projected gradient fell to ``SOLVER_TOLERANCE`` (tested at
    ``y``; the impulses kept are the last projected step's, which ``y`` leads by its momentum step:
    taking ``y`` instead moved the 400-circle pour's trajectory so that its floor was booked a
    sideways share of the momentum sleep stopped, 2.6e-3 N s: ``_along_normals``' remainder)."""
    norm = _bound(ca, cb, c, ima, n)
    if norm == 0.0:
        return True
    step = 1.0 / norm
    g = np.empty(c)
    y = np.empty(c)  # the extrapolated impulses; ``vel`` holds their velocities meanwhile
    nxt = np.empty(c)
    for q in range(c):
        y[q] = cf[q, 6]
    theta = 1.0
    done = False
    for _ in range(iterations):
        status[5] += 1
        _gradient(ca, cb, cf, c, vel, g)
        worst = 0.0
        rising = 0.0
        for q in range(c):
            if y[q] > 0.0:
                worst = max(worst, abs(g[q]))
            elif g[q] < 0.0:
                worst = max(worst, -g[q])
            nxt[q] = max(y[q] - step * g[q], 0.0)
            rising += g[q] * (nxt[q] - cf[q, 6])
        if worst <= SOLVER_TOLERANCE:
            done = True
            break
        squared = theta * theta
        then = 0.5 * (theta * math.sqrt(squared + 4.0) - squared)
        beta = theta * (1.0 - theta) / (squared + then)
        theta = then
        if rising > 0.0:  # the objective would rise: start the momentum afresh
            beta = 0.0
            theta = 1.0
        for q in range(c):
            ahead = nxt[q] + beta * (nxt[q] - cf[q, 6])
            _kick(vel, ima, ca[q], cb[q], cf, q, ahead - y[q])
            y[q] = ahead
            cf[q, 6] = nxt[q]
    for q in range(c):  # the velocities back to the impulses' own
        _kick(vel, ima, ca[q], cb[q], cf, q, cf[q, 6] - y[q])
    return done


def _mprgp(ca: Any, cb: Any, cf: Any, c: int, vel: Any, ima: Any, n: int, iterations: int, status: Any) -> bool:
    """Solve the contacts' impulses ``P >= 0`` (``cf[:, 6]``, started from the warm start the
    velocities already hold) so that each pair separates by the step's end at least at its
    target speed, and does so exactly where it pushes (Signorini, at velocity level): the
    bound-constrained quadratic program ``min P.A P / 2 + P.(v_n - target)``, ``P >= 0``, by
    modified proportioning with reduced gradient projections (MPRGP: Dostal and Schoeberl 2005;
    Dostal, *Optimal Quadratic Programming Algorithms*, 2009, ch. 8): conjugate gradients on the
    contacts that push, an expansion step where one would stop pushing, a proportioning step
    where one that does not push is pulled in. While the set of pushing contacts holds, the
    conjugate gradients converge with the square root of ``A``'s condition number, where
    Gauss-Seidel sweeps go with the condition number itself (a pile k layers deep: k^2).
    Returns whether every contact's projected gradient fell to ``SOLVER_TOLERANCE``."""
    g = np.empty(c)
    p = np.empty(c)
    ap = np.empty(c)
    d = np.empty(c)
    u = np.zeros((n, 3))
    norm = _bound(ca, cb, c, ima, n)
    if norm == 0.0:
        return True
    bar = 1.0 / norm  # the expansion's fixed step, in (0, 2/||A||]
    _gradient(ca, cb, cf, c, vel, g)
    for q in range(c):
        p[q] = g[q] if cf[q, 6] > 0.0 else 0.0
    for _ in range(iterations):
        status[5] += 1
        worst = 0.0
        chopped = 0.0
        reduced = 0.0
        for q in range(c):
            if cf[q, 6] > 0.0:
                worst = max(worst, abs(g[q]))
                reduced += min(cf[q, 6] / bar, g[q]) * g[q]
            elif g[q] < 0.0:
                worst = max(worst, -g[q])
                chopped += g[q] * g[q]
        if worst <= SOLVER_TOLERANCE:
            return True
        if chopped <= reduced:  # proportional: a conjugate gradient step on the free set
            pap, gp, feasible = _product(ca, cb, cf, c, ima, p, u, ap, g)
            if pap <= 0.0:
                _move(ca, cb, cf, c, vel, u, g, ap, p, 0.0)  # (clears u)
                for q in range(c):
                    p[q] = g[q] if cf[q, 6] > 0.0 else 0.0
                continue
            step = gp / pap
            if step <= feasible:
                gamma = _move(ca, cb, cf, c, vel, u, g, ap, p, step) / pap
                for q in range(c):
                    p[q] = (g[q] if cf[q, 6] > 0.0 else 0.0) - gamma * p[q]
                continue
            _move(ca, cb, cf, c, vel, u, g, ap, p, feasible)  # to the bound, then expand
            for q in range(c):
                d[q] = cf[q, 6] - max(cf[q, 6] - bar * g[q], 0.0) if cf[q, 6] > 0.0 else 0.0
        else:  # proportioning: release the contacts the gradient pulls in
            for q in range(c):
                d[q] = min(g[q], 0.0) if cf[q, 6] <= 0.0 else 0.0
            dad, gd, _ = _product(ca, cb, cf, c, ima, d, u, ap, g)
            _move(ca, cb, cf, c, vel, u, g, ap, d, gd / dad if dad > 0.0 else 0.0)
            _gradient(ca, cb, cf, c, vel, g)
            for q in range(c):
                p[q] = g[q] if cf[q, 6] > 0.0 else 0.0
            continue
        _product(ca, cb, cf, c, ima, d, u, ap, g)
        _move(ca, cb, cf, c, vel, u, g, ap, d, 1.0)
        _gradient(ca, cb, cf, c, vel, g)  # afresh: rounding does not pile up
        for q in range(c):
            p[q] = g[q] if cf[q, 6] > 0.0 else 0.0
    return False


def _apply(pairs: Any, pf: Any, p: int, vel: Any, ima: Any, impulse: float) -> None:
    """Apply ``impulse`` along pair ``p``'s normal: ``v_b += P n / m_b``, ``v_a -= P n / m_a``."""
    a = pairs[p, 0]
    b = pairs[p, 1]
    for k in range(3):
        vel[b, k] += impulse * ima[b] * pf[p, 1 + k]
        if a >= 0:
            vel[a, k] -= impulse * ima[a] * pf[p, 1 + k]


def _normal_velocity(pairs: Any, pf: Any, p: int, vel: Any) -> float:
    """Pair ``p``'s relative velocity along its normal (``pf[p, 1:4]``), ``v_b - v_a``."""
    a = pairs[p, 0]
    b = pairs[p, 1]
    vn = 0.0
    for k in range(3):
        vn += (vel[b, k] - (vel[a, k] if a >= 0 else 0.0)) * pf[p, 1 + k]
    return vn


def _kick(vel: Any, ima: Any, a: int, b: int, cf: Any, q: int, impulse: float) -> None:
    """:func:`_apply` on a dense contact row ``q`` (normal in ``cf[q, :3]``)."""
    for k in range(3):
        vel[b, k] += impulse * ima[b] * cf[q, k]
        if a >= 0:
            vel[a, k] -= impulse * ima[a] * cf[q, k]


def _contact_kinetic(pairs: Any, contacts: Any, c: int, vel: Any, ima: Any, n: int) -> float:
    """Kinetic energy of the bodies in the contacts, each counted once."""
    seen = np.zeros(n, np.bool_)
    kinetic = 0.0
    for q in range(c):
        p = contacts[q]
        for end in range(2):
            i = pairs[p, end]
            if i >= 0 and not seen[i] and ima[i] > 0.0:
                seen[i] = True
                kinetic += 0.5 * (vel[i, 0] ** 2 + vel[i, 1] ** 2 + vel[i, 2] ** 2) / ima[i]
    return kinetic


# --- the end of a step -------------------------------------------------------------------------
def _push_apart(
    kind: Any, pos: Any, ext: Any, ima: Any, asleep: Any, s_kind: Any, s_a: Any, s_b: Any,
    pairs: Any, count: int, gravity: Any, slop: float, ledger: Any, rounds: int, first: int, then: int,
) -> None:  # fmt: skip
    """Pairs overlapping by more than ``slop`` are moved apart until they touch, velocities
    untouched (a sleeping body does not move). All at once: the displacements ``d = M^-1 J^T P``
    with ``P >= 0`` and every listed pair's gap ``+ J d >= 0``, the smallest in the mass norm,
    are the same quadratic program as the velocity solve's (:func:`_mprgp`, with gaps for
    velocities; the split impulse of Catto's and Bullet's solvers), so an overlap wedged in a
    pile is undone by moving the pile around it, not traded for a new one each step. Up to
    ``rounds`` rounds of at most ``first`` and ``then`` iterations each (:func:`_qp`), each from
    the gaps anew (a circle moved sideways along a neighbour ends a little into it). The energy
    this changes (``-m g.dx``) goes to ``ledger[2]``, the deepest overlap to ``ledger[4]``."""
    n = pos.shape[0]
    gaps = np.empty(count)
    for _ in range(rounds):
        deepest = 0.0
        for p in range(count):
            gaps[p] = _sep_now(kind, pos, ext, s_kind, s_a, s_b, pairs[p, 0], pairs[p, 1])[0]
            deepest = max(deepest, -gaps[p])
        if deepest <= slop:
            return
        ledger[4] = max(ledger[4], deepest)
        weight = np.zeros(n)
        for i in range(n):
            if asleep[i] == 0:
                weight[i] = ima[i]
        ca = np.empty(count, np.int64)
        cb = np.empty(count, np.int64)
        cf = np.zeros((count, 7))
        c = sk._int(0)
        for p in range(count):
            a = pairs[p, 0]
            b = pairs[p, 1]
            if gaps[p] >= deepest or weight[b] + (weight[a] if a >= 0 else 0.0) == 0.0:
                continue  # (a pair farther apart than the deepest overlap cannot be pushed into one)
            sep = _sep_now(kind, pos, ext, s_kind, s_a, s_b, a, b)
            ca[c] = a
            cb[c] = b
            for k in range(3):
                cf[c, k] = sep[1 + k]
            cf[c, 5] = gaps[p]
            c += 1
        shift = np.zeros((n, 3))
        scratch = np.zeros(STATUS_SIZE, np.int64)
        _qp(ca, cb, cf, c, shift, weight, n, first, then, scratch)
        for i in range(n):
            if weight[i] > 0.0:
                for k in range(3):
                    pos[i, k] += shift[i, k]
                    ledger[2] -= gravity[k] * shift[i, k] / weight[i]


def _along_normals(rows_f: Any, first: int, last: int, total: float, target: Any) -> Any:
    """Share the impulse ``target`` among the support rows ``first:last`` (each an impulse
    ``P_w n_w`` on one body, ``total`` the sum of the ``P_w``), each share along the row's own
    normal, so that a frictionless wall is never booked a push along itself: the shares
    ``c_w n_w`` with ``c_w = P_w n_w.y`` and ``(sum P_w n_w n_w^T) y = target`` (the least change
    weighted by ``1/P_w``), over the axes the normals span. What the normals cannot carry (a
    remainder of rounding: an island at rest is held along every axis gravity pulls) is shared
    in proportion to ``P_w``, so the shares always sum to ``target``. Returns them, one row each."""
    rows = last - first
    shares = np.zeros((rows, 3))
    if rows == 0:
        return shares
    mat = np.zeros((3, 3))
    for w in range(first, last):
        size = math.sqrt(rows_f[w, 0] ** 2 + rows_f[w, 1] ** 2 + rows_f[w, 2] ** 2)
        if size == 0.0:
            continue
        for i in range(3):
            for j in range(3):
                mat[i, j] += rows_f[w, i] * rows_f[w, j] / size
    axes = np.zeros(3, np.int64)  # the axes the normals span (a 2D world's z is never one)
    count = sk._int(0)
    for k in range(3):
        if mat[k, k] > SPAN_FRACTION * (mat[0, 0] + mat[1, 1] + mat[2, 2]):
            axes[count] = k
            count += 1
    y = np.zeros(3)
    if count > 0:
        sub = np.empty((count, count))
        rhs = np.empty(count)
        for i in range(count):
            rhs[i] = target[axes[i]]
            for j in range(count):
                sub[i, j] = mat[axes[i], axes[j]]
        solved = _solve_small(sub, rhs, count)
        for i in range(count):
            y[axes[i]] = solved[i]
    carried = np.zeros(3)
    for w in range(first, last):
        size = math.sqrt(rows_f[w, 0] ** 2 + rows_f[w, 1] ** 2 + rows_f[w, 2] ** 2)
        if size == 0.0:
            continue
        c = rows_f[w, 0] * y[0] + rows_f[w, 1] * y[1] + rows_f[w, 2] * y[2]  # P_w n_w.y, times size
        for k in range(3):
            shares[w - first, k] = c * rows_f[w, k] / size
            carried[k] += shares[w - first, k]
    for w in range(first, last):  # the remainder, in proportion to P_w
        part = math.sqrt(rows_f[w, 0] ** 2 + rows_f[w, 1] ** 2 + rows_f[w, 2] ** 2) / total
        for k in range(3):
            shares[w - first, k] += (target[k] - carried[k]) * part
    return shares


def _solve_small(mat: Any, rhs: Any, count: int) -> Any:
    """``mat x = rhs`` for a symmetric positive definite ``count`` x ``count`` matrix (1 to 3):
    Cholesky, written out (no LAPACK needed in the compiled form)."""
    low = np.zeros((count, count))
    for i in range(count):
        for j in range(i + 1):
            acc = mat[i, j]
            for k in range(j):
                acc -= low[i, k] * low[j, k]
            if i == j:
                low[i, i] = math.sqrt(max(acc, 0.0))
            else:
                low[i, j] = acc / low[j, j] if low[j, j] > 0.0 else 0.0
    x = np.zeros(count)
    for i in range(count):  # forward, then back
        acc = rhs[i]
        for k in range(i):
            acc -= low[i, k] * x[k]
        x[i] = acc / low[i, i] if low[i, i] > 0.0 else 0.0
    for i in range(count - 1, -1, -1):
        acc = x[i]
        for k in range(i + 1, count):
            acc -= low[k, i] * x[k]
        x[i] = acc / low[i, i] if low[i, i] > 0.0 else 0.0
    return x


def _carry(rows_i: Any, rows_f: Any, row_count: Any, asleep: Any, static_impulse: Any) -> None:
    """One step of the sleeping islands' weight on their supports: each row of a body still
    asleep adds its impulse to its static's ``static_impulse``; a woken body's rows are dropped."""
    kept = sk._int(0)
    for r in range(row_count[0]):
        if asleep[rows_i[r, 1]] != 0:
            for k in range(3):
                static_impulse[rows_i[r, 0], k] += rows_f[r, k]
                rows_f[kept, k] = rows_f[r, k]
            rows_i[kept, 0] = rows_i[r, 0]
            rows_i[kept, 1] = rows_i[r, 1]
            kept += 1
    row_count[0] = kept


def _at_rest(vel: Any, ima: Any, asleep: Any) -> bool:
    """Whether nothing can move this step: every body of finite mass asleep, every kinematic one
    still. The step then only carries the sleepers' weight (:func:`_carry`): a settled pile costs
    a pass over its supports, not a listing, flight, solve and push-apart of every body."""
    for i in range(vel.shape[0]):
        if asleep[i] != 0:
            continue
        if ima[i] > 0.0 or vel[i, 0] != 0.0 or vel[i, 1] != 0.0 or vel[i, 2] != 0.0:
            return False
    return True


def _sleep(
    kind: Any, pos: Any, vel: Any, ext: Any, ima: Any, s_kind: Any, s_a: Any, s_b: Any, asleep: Any, still: Any,
    island: Any, parent: Any, memory: Any, memory_lam: Any, c: int, gravity: Any, dt: float,
    rows_i: Any, rows_f: Any, row_count: Any, ledger: Any, static_impulse: Any, status: Any,
) -> Any:  # fmt: skip
    """Islands and sleep (module phase 5) over the last solve's contacts (the memory: keys and
    impulses); returns ``(rows_i, rows_f)``, the sleeping supports' impulse per step (static,
    body; impulse), grown when full. First the rows of islands still asleep are added to
    ``static_impulse`` (a woken island's are dropped)."""
    m = s_kind.shape[0]
    _carry(rows_i, rows_f, row_count, asleep, static_impulse)
    n = vel.shape[0]
    for i in range(n):
        parent[i] = i
        if asleep[i] == 0:
            slow = vel[i, 0] ** 2 + vel[i, 1] ** 2 + vel[i, 2] ** 2 < SLEEP_SPEED * SLEEP_SPEED
            still[i] = still[i] + dt if slow and ima[i] > 0.0 else 0.0
    supported = np.zeros(n, np.bool_)
    for q in range(c):
        a = memory[q] // n - m
        b = memory[q] % n
        if a < 0:
            supported[b] = True
            continue
        ra = _root(parent, a)
        rb = _root(parent, b)
        if ra != rb:
            parent[max(ra, rb)] = min(ra, rb)
    least = np.full(n, math.inf)
    held = np.zeros(n, np.bool_)
    for i in range(n):
        if asleep[i] != 0:
            continue
        r = _root(parent, i)
        least[r] = min(least[r], still[i])
        held[r] = held[r] or supported[i]
    g = math.sqrt(gravity[0] ** 2 + gravity[1] ** 2 + gravity[2] ** 2)
    for r in range(n):
        if parent[r] != r or asleep[r] != 0 or not held[r] or least[r] < SLEEP_TIME or g == 0.0:
            continue
        # The island of root r falls asleep: its supports carry its weight from now on, split as
        # this step's solve split it, and take the momentum it gives up now.
        mass = 0.0
        px = py = pz = 0.0
        for i in range(n):
            if asleep[i] == 0 and _root(parent, i) == r:
                m_i = 1.0 / ima[i]
                mass += m_i
                px += m_i * vel[i, 0]
                py += m_i * vel[i, 1]
                pz += m_i * vel[i, 2]
                stopped = 0.5 * m_i * (vel[i, 0] ** 2 + vel[i, 1] ** 2 + vel[i, 2] ** 2)
                ledger[1] -= stopped  # a loss by definition: measured and theory alike
                ledger[3] -= stopped
        total = 0.0
        sx = sy = sz = 0.0
        first = row_count[0]
        for q in range(c):
            a = memory[q] // n - m
            b = memory[q] % n
            if a >= 0 or _root(parent, b) != r or memory_lam[q] <= 0.0:
                continue
            sep = _sep_of(kind, ext, s_kind, s_a, s_b, a, b, 0.0, 0.0, 0.0, pos[b, 0], pos[b, 1], pos[b, 2])
            if row_count[0] == rows_i.shape[0]:
                rows_i = _grown_int(rows_i)
                rows_f = _grown_float(rows_f, 2 * rows_f.shape[0] + 16)
            w = row_count[0]
            rows_i[w, 0] = -1 - a
            rows_i[w, 1] = b
            for k in range(3):
                rows_f[w, k] = memory_lam[q] * sep[1 + k]
            sx += rows_f[w, 0]
            sy += rows_f[w, 1]
            sz += rows_f[w, 2]
            total += memory_lam[q]
            row_count[0] += 1
        if total == 0.0:
            continue
        need = np.empty(3)
        for k in range(3):
            need[k] = -mass * gravity[k] * dt - (sx if k == 0 else (sy if k == 1 else sz))
        last = row_count[0]
        shares = _along_normals(rows_f, first, last, total, need)
        momentum = np.array((px, py, pz))
        stopped = _along_normals(rows_f, first, last, total, momentum)  # what sleep took away
        for w in range(first, last):
            s = rows_i[w, 0]
            for k in range(3):
                rows_f[w, k] += shares[w - first, k]
                static_impulse[s, k] -= stopped[w - first, k]
        for i in range(n):
            if asleep[i] == 0 and _root(parent, i) == r:
                asleep[i] = 1
                island[i] = r
                still[i] = 0.0
                for k in range(3):
                    vel[i, k] = 0.0
    count = sk._int(0)
    for i in range(n):
        count += asleep[i]
    status[4] = count
    return rows_i, rows_f


# --- the loop ----------------------------------------------------------------------------------
def _relist(
    kind: Any, pos: Any, vel: Any, ext: Any, asleep: Any, s_kind: Any, s_a: Any, s_b: Any, gravity: Any,
    order: Any, lo: Any, start: Any, lists: Any, dims: int, left: float, contact_margin: float, status: Any,
) -> Any:  # fmt: skip
    """List the candidates for the ``left`` seconds of the step still to fly (every body at the
    same time). ``lists`` is ``(pairs, pf, adj, ver, ht, hk, hv)``: the pairs, their float rows,
    each body's pairs, and the calendar's arrays, grown to fit; returns ``(u, count, lists)``."""
    pairs, pf, adj, ver, ht, hk, hv = lists
    u = _speed_bound(vel, asleep, gravity, left)
    g = math.sqrt(gravity[0] ** 2 + gravity[1] ** 2 + gravity[2] ** 2)
    reach = u * left + contact_margin
    static_reach = u * left + 0.5 * g * left * left + contact_margin
    pairs, count = _list_pairs(kind, pos, ext, asleep, s_kind, s_a, s_b, order, lo, dims, reach, static_reach, pairs)
    adj = _adjacency(pairs, count, pos.shape[0], start, adj)
    pf = _grown_float(pf, count)
    if ver.shape[0] < count:
        ver = np.zeros(2 * count, np.int64)
        ht = np.zeros(HEAP_ROOM * 2 * count + 2)
        hk = np.zeros(ht.shape[0], np.int64)
        hv = np.zeros(ht.shape[0], np.int64)
    status[3] += 1
    return u, count, (pairs, pf, adj, ver, ht, hk, hv)


def run_contact_steps(
    kind: Any, pos: Any, vel: Any, ext: Any, ima: Any, eb: Any, ids: Any,
    s_kind: Any, s_a: Any, s_b: Any, s_e: Any, gravity: Any, dims: int, dt: float, e_default: float,
    rest_speed: float, slop: float, contact_margin: float, first_step: int, steps: int, record: bool,
    tau: Any, acc: Any, asleep: Any, still: Any, island: Any, parent: Any, order: Any, lo: Any, start: Any,
    pairs: Any, pf: Any, adj: Any, contacts: Any, memory: Any, memory_lam: Any, memory_count: Any,
    rows_i: Any, rows_f: Any, row_count: Any,
    events: Any, event_count: Any, ledger: Any, static_impulse: Any, status: Any,
) -> Any:  # fmt: skip
    """Run ``steps`` steps of ``dt`` from step ``first_step`` (module docstring). The bodies stay
    in the order given (``ids`` only names them in events). Everything after ``record`` is kept
    between calls; the arrays that can grow come back: ``(pairs, pf, adj, contacts, memory,
    memory_lam, rows_i, rows_f, events)``. ``rest_speed`` is the world's ``v_rest``."""
    n = pos.shape[0]
    h = 0.5 * dt
    hits = np.zeros(n, np.int64)
    empty = np.zeros(0, np.int64)
    lists = (pairs, pf, adj, empty, np.zeros(0), empty, empty)
    u = 0.0
    count = sk._int(0)
    for step in range(first_step, first_step + steps):
        if _at_rest(vel, ima, asleep):
            _carry(rows_i, rows_f, row_count, asleep, static_impulse)
            continue
        for i in range(n):
            tau[i] = 0.0
            for k in range(3):
                acc[i, k] = gravity[k] if ima[i] > 0.0 and asleep[i] == 0 else 0.0
        t = 0.0
        left = dt  # list the candidates for this much of the step before flying on (< 0: listed)
        for half in range(2):
            t_end = h if half == 0 else dt
            while half == 1:  # the solve at mid-step, after the first half's flight
                pairs, pf = lists[0], lists[1]
                contacts, _, memory, memory_lam, woken = _solve(
                    kind, pos, vel, acc, ext, ima, s_kind, s_a, s_b, asleep, pairs, count, pf, contacts, memory,
                    memory_lam, memory_count, gravity, dt, rest_speed, contact_margin, ledger, static_impulse, status,
                )  # fmt: skip
                if woken < 0:
                    if _speed_bound(vel, asleep, gravity, h) > u:
                        left = h
                    break
                _wake(island, asleep, acc, ima, gravity, tau, h, island[woken], rows_i, rows_f, row_count,
                      static_impulse, 0.5)  # fmt: skip
                u, count, lists = _relist(kind, pos, vel, ext, asleep, s_kind, s_a, s_b, gravity, order, lo, start,
                                          lists, dims, h, contact_margin, status)  # fmt: skip
            hits[:] = 0
            while True:
                if left > 0.0:
                    u, count, lists = _relist(kind, pos, vel, ext, asleep, s_kind, s_a, s_b, gravity, order, lo, start,
                                              lists, dims, left, contact_margin, status)  # fmt: skip
                    left = -1.0
                pairs, _, adj, ver, ht, hk, hv = lists
                code, t, events = _flight(
                    kind, pos, vel, acc, tau, ext, ima, eb, ids, s_kind, s_a, s_b, s_e, gravity, asleep, island,
                    pairs, count, ver, hits, ht, hk, hv, start, adj, t, t_end, u, e_default, rest_speed, step + 1,
                    dt, record, events, event_count, ledger, static_impulse, rows_i, rows_f, row_count, status,
                )  # fmt: skip
                if code == DONE:
                    break
                left = dt - t
        pairs, pf, adj = lists[0], lists[1], lists[2]
        _push_apart(kind, pos, ext, ima, asleep, s_kind, s_a, s_b, pairs, count, gravity, slop, ledger,
                    sk._int(PUSH_ROUNDS), sk._int(PUSH_MPRGP), sk._int(PUSH_APGD))  # fmt: skip
        asleep_before = asleep.copy()
        rows_i, rows_f = _sleep(
            kind, pos, vel, ext, ima, s_kind, s_a, s_b, asleep, still, island, parent, memory, memory_lam,
            memory_count[0], gravity, dt, rows_i, rows_f, row_count, ledger, static_impulse, status,
        )  # fmt: skip
        if (asleep != asleep_before).any():  # an island fell asleep: it is left as it lies, so
            # without the overlaps one step's push-apart left (what a pile at rest shows)
            _push_apart(kind, pos, ext, ima, asleep_before, s_kind, s_a, s_b, pairs, count, gravity, slop, ledger,
                        sk._int(SETTLE_ROUNDS), sk._int(SETTLE_MPRGP), sk._int(SETTLE_APGD))  # fmt: skip
    return lists[0], lists[1], lists[2], contacts, memory, memory_lam, rows_i, rows_f, events
