"""Islands and sleep, the end of the contact stepper's step (phase 5 of :mod:`.contact_kernels`):
bodies joined by the last solve's contacts form islands (union-find); an island that touches a
static, holds no kinematic body, and whose bodies all stayed slower than ``SLEEP_SPEED`` for
``SLEEP_TIME`` falls asleep, and its supports go on carrying exactly its weight, each along its own
normal. An impact on a sleeping body, or a contact of an awake body with it, wakes its island.

Owns ``SPAN_FRACTION``, the union-find root (:func:`_root`), waking an island (:func:`_wake`),
falling asleep (:func:`_sleep`), the sleeping supports' impulse each step (:func:`_carry`, with
:func:`_along_normals` and :func:`_solve_small`) and whether nothing can move
(:func:`_at_rest`). It imports :mod:`.non_literal`, :mod:`.contact_time_of_impact` (a support's
normal) and :mod:`.contact_candidates` (the rows grown when full); it must not import the
impacts, the solve, push-apart or the loop (which wake and put islands to sleep through it).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..tolerances import SLEEP_SPEED, SLEEP_TIME

if "_NON_LITERAL" in globals():  # the compiled copy: the kernels it calls are compiled too
    nl: Any = globals()["_NON_LITERAL"]
    ct: Any = globals()["_CONTACT_TIME_OF_IMPACT"]
    cc: Any = globals()["_CONTACT_CANDIDATES"]
else:
    from . import contact_candidates as cc
    from . import contact_time_of_impact as ct
    from . import non_literal as nl

#: An axis counts as spanned by a sleeping island's support normals when its diagonal entry of
#: ``sum P_w n_w n_w^T`` is more than this fraction of the trace (dimensionless): a 2D world's
#: z axis (exactly 0) never is, and a share along an axis no support pushes on is not booked.
SPAN_FRACTION = 1e-12


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
    woke = nl._int(0)
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
    count = nl._int(0)
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
    kept = nl._int(0)
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
    """Islands and sleep (phase 5 of :mod:`.contact_kernels`) over the last solve's contacts (the
    memory: keys and impulses); returns ``(rows_i, rows_f)``, the sleeping supports' impulse per
    step (static, body; impulse), grown when full. First the rows of islands still asleep are added
    to ``static_impulse`` (a woken island's are dropped)."""
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
            sep = ct._sep_of(kind, ext, s_kind, s_a, s_b, a, b, 0.0, 0.0, 0.0, pos[b, 0], pos[b, 1], pos[b, 2])
            if row_count[0] == rows_i.shape[0]:
                rows_i = cc._grown_int(rows_i)
                rows_f = cc._grown_float(rows_f, 2 * rows_f.shape[0] + 16)
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
    count = nl._int(0)
    for i in range(n):
        count += asleep[i]
    status[4] = count
    return rows_i, rows_f
