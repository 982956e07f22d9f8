"""The contacts' quadratic program, shared by the contact stepper's solve
(:mod:`.contact_solver`) and its push-apart (:mod:`.contact_push_apart`): impulses ``P >= 0``
that minimise ``P.A P / 2 + P.(v_n - target)``, ``A = J M^-1 J^T`` (the Delassus operator), over
dense contact rows (bodies ``ca``, ``cb``; normal, target, inverse mass sum, the acceleration's
share, impulse in ``cf``). By MPRGP (Dostal 2009) and then, where the pushing set keeps changing,
APGD (Mazhar et al. 2015).

Owns ``STATUS_SIZE`` (the stepper's counters: its solvers count their iterations in the last),
the program (:func:`_qp`), its two solvers (:func:`_mprgp`, :func:`_apgd`) and their passes over
the rows (:func:`_gradient`, :func:`_product`, :func:`_move`, :func:`_bound`, :func:`_kick`). It
imports only the contact law's velocity update (:mod:`.contact_law`'s ``pushed_velocity``)
and no other file of the engine: it must stay so (it knows rows, not pairs, shapes or bodies'
flight).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..tolerances import SOLVER_TOLERANCE

if "_CONTACT_LAW" in globals():  # the compiled copy: the kernels it calls are compiled too
    cl: Any = globals()["_CONTACT_LAW"]
else:
    from . import contact_law as cl

#: Counters returned to the world: flights that hit MAX_IMPACTS_PER_STEP, impacts, solves that
#: hit their cap, listings, bodies asleep now, iterations of the solves.
STATUS_SIZE = 6

#: Helpers the compiled form inlines into their callers (:mod:`.compiled`).
INLINE = ("_kick",)


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


def _kick(vel: Any, ima: Any, a: int, b: int, cf: Any, q: int, impulse: float) -> None:
    """:func:`.contact_solver._apply` on a dense contact row ``q`` (normal in ``cf[q, :3]``)."""
    for k in range(3):
        vel[b, k] = cl.pushed_velocity(vel[b, k], impulse, ima[b], cf[q, k])
        if a >= 0:
            vel[a, k] = cl.pushed_velocity(vel[a, k], -impulse, ima[a], cf[q, k])
