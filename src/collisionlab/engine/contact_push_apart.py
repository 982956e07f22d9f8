"""The contact stepper's push-apart (phase 5 of :mod:`.contact_kernels`): overlaps deeper than
``slop`` left by the solve are undone all at once, velocities untouched, as the same quadratic
program as the solve's with gaps for velocities (:mod:`.contact_qp`); the energy it changes goes
to the ledger's push-apart column.

Owns the push-apart (:func:`_push_apart`) and its rounds and iterations, each step
(``PUSH_ROUNDS``, ``PUSH_MPRGP``, ``PUSH_APGD``) and over an island as it falls asleep
(``SETTLE_ROUNDS``, ``SETTLE_MPRGP``, ``SETTLE_APGD``). It imports :mod:`.non_literal`,
:mod:`.contact_time_of_impact` (a pair's gap) and :mod:`.contact_qp`; it must not import the
candidates, impacts, solve, islands or the loop.
"""

from __future__ import annotations

from typing import Any

import numpy as np

if "_NON_LITERAL" in globals():  # the compiled copy: the kernels it calls are compiled too
    nl: Any = globals()["_NON_LITERAL"]
    ct: Any = globals()["_CONTACT_TIME_OF_IMPACT"]
    qp: Any = globals()["_CONTACT_QP"]
else:
    from . import contact_qp as qp
    from . import contact_time_of_impact as ct
    from . import non_literal as nl

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


def _push_apart(
    kind: Any, pos: Any, ext: Any, ima: Any, asleep: Any, s_kind: Any, s_a: Any, s_b: Any,
    pairs: Any, count: int, gravity: Any, slop: float, ledger: Any, rounds: int, first: int, then: int,
) -> None:  # fmt: skip
    """Pairs overlapping by more than ``slop`` are moved apart until they touch, velocities
    untouched (a sleeping body does not move). All at once: the displacements ``d = M^-1 J^T P``
    with ``P >= 0`` and every listed pair's gap ``+ J d >= 0``, the smallest in the mass norm,
    are the same quadratic program as the velocity solve's (:func:`.contact_qp._mprgp`, with gaps for
    velocities; the split impulse of Catto's and Bullet's solvers), so an overlap wedged in a
    pile is undone by moving the pile around it, not traded for a new one each step. Up to
    ``rounds`` rounds of at most ``first`` and ``then`` iterations each (:func:`.contact_qp._qp`), each from
    the gaps anew (a circle moved sideways along a neighbour ends a little into it). The energy
    this changes (``-m g.dx``) goes to ``ledger[2]``, the deepest overlap to ``ledger[4]``."""
    n = pos.shape[0]
    gaps = np.empty(count)
    for _ in range(rounds):
        deepest = 0.0
        for p in range(count):
            gaps[p] = ct._sep_now(kind, pos, ext, s_kind, s_a, s_b, pairs[p, 0], pairs[p, 1])[0]
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
        c = nl._int(0)
        for p in range(count):
            a = pairs[p, 0]
            b = pairs[p, 1]
            if gaps[p] >= deepest or weight[b] + (weight[a] if a >= 0 else 0.0) == 0.0:
                continue  # (a pair farther apart than the deepest overlap cannot be pushed into one)
            sep = ct._sep_now(kind, pos, ext, s_kind, s_a, s_b, a, b)
            ca[c] = a
            cb[c] = b
            for k in range(3):
                cf[c, k] = sep[1 + k]
            cf[c, 5] = gaps[p]
            c += 1
        shift = np.zeros((n, 3))
        scratch = np.zeros(qp.STATUS_SIZE, np.int64)
        qp._qp(ca, cb, cf, c, shift, weight, n, first, then, scratch)
        for i in range(n):
            if weight[i] > 0.0:
                for k in range(3):
                    pos[i, k] += shift[i, k]
                    ledger[2] -= gravity[k] * shift[i, k] / weight[i]
