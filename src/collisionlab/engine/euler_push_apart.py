"""Forward Euler's push-apart (phase 6 of :mod:`.step_kernels`; the exact stepper's end of step
too): in the contacts' order, from current positions, a pair still overlapping moves apart to a
gap of ``slop``, shared in inverse proportion to mass (:func:`_push_apart`), swept again looking
only at the contacts one of whose bodies moved since they were last looked at (:func:`_push_sweep`).

It imports only :mod:`.pair_separation`; it must not import the clamps (:mod:`.euler_clamps`) or
any stepper's loop.
"""

from __future__ import annotations

from typing import Any

if "_PAIR_SEPARATION" in globals():  # the compiled copy: the kernels it calls are compiled too
    ps: Any = globals()["_PAIR_SEPARATION"]
else:
    from . import pair_separation as ps

__all__: list[str] = []  # helpers of the steppers' loops: nothing here is public


def _push_apart(
    kind: Any,
    pos: Any,
    ext: Any,
    ima: Any,
    s_kind: Any,
    s_a: Any,
    s_b: Any,
    ca: Any,
    cb: Any,
    cd: Any,
    order: Any,
    gravity: Any,
    slop: float,
    solver_margin: float,
    ledger: Any,
) -> int:
    """One pass of positional correction in ``order``, from current positions: a pair overlapping
    by ``d > 0`` moves apart to a gap of ``slop``, in inverse proportion to mass. The potential
    energy this changes goes to ``ledger[2]``, the deepest overlap to ``ledger[4]``. Returns how
    many moves were made."""
    moves = 0
    for t in range(order.shape[0]):
        c = order[t]
        if cd[c] < -solver_margin:
            continue
        a = ca[c]
        b = cb[c]
        ima_a = ima[a] if a >= 0 else 0.0
        inv_sum = ima_a + ima[b]
        if inv_sum == 0.0:
            continue
        sep = ps._contact_separation(kind, pos, ext, s_kind, s_a, s_b, a, b)
        if sep[0] >= 0.0:  # touching is not overlapping: nothing to undo
            continue
        ledger[4] = max(ledger[4], -sep[0])
        push = slop - sep[0]
        sa = push * ima_a / inv_sum
        sb = push * ima[b] / inv_sum
        change = 0.0
        for k in range(3):
            if a >= 0 and ima_a > 0.0:
                pos[a, k] = pos[a, k] - sep[1 + k] * sa
                change += gravity[k] * sep[1 + k] * sa / ima_a
            pos[b, k] = pos[b, k] + sep[1 + k] * sb
            if ima[b] > 0.0:
                change -= gravity[k] * sep[1 + k] * sb / ima[b]
        ledger[2] += change
        moves += 1
    return moves


def _push_sweep(
    kind: Any,
    pos: Any,
    ext: Any,
    ima: Any,
    s_kind: Any,
    s_a: Any,
    s_b: Any,
    ca: Any,
    cb: Any,
    cd: Any,
    cn: Any,
    order: Any,
    seen: Any,
    moved: Any,
    found: int,
    clock: int,
    first_pass: bool,
    gravity: Any,
    slop: float,
    solver_margin: float,
    ledger: Any,
) -> int:
    """:func:`_push_apart`'s pass over the contacts ``order[0], order[1], ...`` (the Forward
    Euler stepper stores them in the order they are resolved: ``order`` is ``0, 1, ...``; the
    exact stepper orders a subset), looking at a contact only when it could move something: in
    the first pass every contact; after it only those one of whose bodies moved since the
    contact was last looked at (``moved[body]`` against ``seen[c]``, ticks as in
    :func:`_impulses`: the contact at ``order[u]`` looks at tick ``clock + u``). A contact neither
    of whose bodies moved since tick ``found`` (when ``cd`` and the normals ``cn`` were measured)
    takes its separation from there. Either way the same numbers as :func:`_push_apart`.
    Returns the moves."""
    moves = 0
    for u in range(order.shape[0]):
        c = order[u]
        if cd[c] < -solver_margin:
            continue
        a = ca[c]
        b = cb[c]
        ima_a = ima[a] if a >= 0 else 0.0
        inv_sum = ima_a + ima[b]
        if inv_sum == 0.0:
            continue
        last = moved[b]
        if a >= 0 and moved[a] > last:
            last = moved[a]
        if not first_pass and last < seen[c]:
            continue  # neither body moved since this contact was last looked at
        tick = clock + u
        seen[c] = tick
        if last < found:  # where it was found: the separation is the one found then
            gap = -cd[c]
            nx = cn[c, 0]
            ny = cn[c, 1]
            nz = cn[c, 2]
        else:
            if a >= 0:
                sep = ps._pair_sep(
                    kind[a],
                    pos[a, 0],
                    pos[a, 1],
                    pos[a, 2],
                    ext[a, 0],
                    ext[a, 1],
                    ext[a, 2],
                    kind[b],
                    pos[b, 0],
                    pos[b, 1],
                    pos[b, 2],
                    ext[b, 0],
                    ext[b, 1],
                    ext[b, 2],
                )
            else:
                sep = ps._static_sep(
                    s_kind[-1 - a],
                    s_a[-1 - a, 0],
                    s_a[-1 - a, 1],
                    s_a[-1 - a, 2],
                    s_b[-1 - a, 0],
                    s_b[-1 - a, 1],
                    s_b[-1 - a, 2],
                    kind[b],
                    pos[b, 0],
                    pos[b, 1],
                    pos[b, 2],
                    ext[b, 0],
                    ext[b, 1],
                    ext[b, 2],
                )
            gap = sep[0]
            nx = sep[1]
            ny = sep[2]
            nz = sep[3]
        if gap >= 0.0:  # touching is not overlapping: nothing to undo
            continue
        # As _push_apart, written out.
        ledger[4] = max(ledger[4], -gap)
        push = slop - gap
        sa = push * ima_a / inv_sum
        sb = push * ima[b] / inv_sum
        change = 0.0
        if a >= 0 and ima_a > 0.0:
            pos[a, 0] = pos[a, 0] - nx * sa
            change += gravity[0] * nx * sa / ima_a
        pos[b, 0] = pos[b, 0] + nx * sb
        if ima[b] > 0.0:
            change -= gravity[0] * nx * sb / ima[b]
        if a >= 0 and ima_a > 0.0:
            pos[a, 1] = pos[a, 1] - ny * sa
            change += gravity[1] * ny * sa / ima_a
        pos[b, 1] = pos[b, 1] + ny * sb
        if ima[b] > 0.0:
            change -= gravity[1] * ny * sb / ima[b]
        if a >= 0 and ima_a > 0.0:
            pos[a, 2] = pos[a, 2] - nz * sa
            change += gravity[2] * nz * sa / ima_a
        pos[b, 2] = pos[b, 2] + nz * sb
        if ima[b] > 0.0:
            change -= gravity[2] * nz * sb / ima[b]
        ledger[2] += change
        if a >= 0:
            moved[a] = tick
        moved[b] = tick
        moves += 1
    return moves
