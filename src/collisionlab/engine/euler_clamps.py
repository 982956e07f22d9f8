"""Forward Euler's corrections of positions (phases 1 and 6 of :mod:`.step_kernels`; the exact
stepper clamps to walls too): a body past a one-sided wall is put back inside it
(:func:`_clamp_to_walls`); a body whose centre crossed a line or plane it started the step on one
side of is put back on that side (:func:`_sides`, :func:`_uncross`); a body a push left
overlapping a line or plane is put back clear of it (:func:`_clamp_to_sides`); and the potential
energy these corrections lifted a body by is paid from its kinetic energy
(:func:`_no_energy_from_corrections`): push-apart makes no energy.

It imports :mod:`.pair_separation` and :mod:`.broad_phase_pairs` (a wall's bounds); it must not
import the push-apart or any stepper's loop.
"""

from __future__ import annotations

import math
from typing import Any

if "_BROAD_PHASE_PAIRS" in globals():  # the compiled copy: the kernels it calls are compiled too
    bp: Any = globals()["_BROAD_PHASE_PAIRS"]
    ps: Any = globals()["_PAIR_SEPARATION"]
else:
    from . import broad_phase_pairs as bp
    from . import pair_separation as ps

__all__: list[str] = []  # helpers of the steppers' loops: nothing here is public

#: Helpers the compiled form inlines into their callers (:mod:`.compiled`): they take arrays, and a
#: call that passes several numba arrays (each a struct of seven fields) costs more than the work inside.
INLINE = ("_shift",)


def _clamp_to_walls(
    kind: Any,
    pos: Any,
    ext: Any,
    ima: Any,
    s_kind: Any,
    s_a: Any,
    s_b: Any,
    ca: Any,
    cb: Any,
    count: int,
    gravity: Any,
    slop: float,
    ledger: Any,
) -> None:
    """Walls are hard: a body of finite mass that the pushes of its neighbours left past a
    one-sided wall is put back inside, a gap ``slop`` clear of it (its potential energy change to
    ``ledger[2]``). Only bodies in a contact can have been pushed, and each is looked at once."""
    for c in range(count):
        for end in range(2):
            b = cb[c] if end == 0 else ca[c]
            if b < 0 or ima[b] == 0.0:
                continue
            for s in range(s_kind.shape[0]):
                if s_kind[s] != ps.STATIC_WALL or not bp._static_bounds_meet(s_kind, s_a, s_b, s, pos, ext, b, 0.0):
                    continue
                sep = ps._static_separation(s_kind, s_a, s_b, s, kind, pos, ext, b)
                if sep[0] < 0.0:
                    ledger[4] = max(ledger[4], -sep[0])
                    push = slop - sep[0]
                    change = 0.0
                    for k in range(3):
                        pos[b, k] = pos[b, k] + sep[1 + k] * push
                        change -= gravity[k] * sep[1 + k] * push / ima[b]
                    ledger[2] += change


def _sides(pos: Any, s_kind: Any, s_a: Any, s_b: Any, side: Any) -> bool:
    """``side[i, s]``: the side of line or plane ``s`` body ``i``'s centre is on, ``+1`` along its
    normal, ``-1`` against it, ``0`` on it (and for the other statics). Returns whether there is a
    line or plane at all."""
    any_line = False
    for s in range(s_kind.shape[0]):
        if s_kind[s] == ps.STATIC_BOUNDARY:
            any_line = True
    if not any_line:
        return False
    for i in range(pos.shape[0]):
        for s in range(s_kind.shape[0]):
            side[i, s] = 0.0
            if s_kind[s] != ps.STATIC_BOUNDARY:
                continue
            t = (
                s_b[s, 0] * (pos[i, 0] - s_a[s, 0])
                + s_b[s, 1] * (pos[i, 1] - s_a[s, 1])
                + s_b[s, 2] * (pos[i, 2] - s_a[s, 2])
            )
            if t > 0.0:
                side[i, s] = 1.0
            elif t < 0.0:
                side[i, s] = -1.0
    return True


def _reach(kind: Any, ext: Any, i: int, ux: float, uy: float, uz: float) -> float:
    """How far body ``i`` reaches from its centre along the unit normal ``u``: a ball's radius, a
    box's projected radius ``sum_k |u_k| e_k`` (Ericson 5.2.3)."""
    if kind[i] <= ps.BALL_3D:
        return float(ext[i, 0])
    return float(abs(ux) * ext[i, 0] + abs(uy) * ext[i, 1] + abs(uz) * ext[i, 2])


def _shift(pos: Any, ima: Any, i: int, ux: float, uy: float, uz: float, move: float, gravity: Any, ledger: Any) -> None:
    """Move body ``i`` by ``move`` along the unit ``u``, a positional correction: its potential
    energy change, ``-m g.u move``, goes to ``ledger[2]``."""
    pos[i, 0] = pos[i, 0] + ux * move
    pos[i, 1] = pos[i, 1] + uy * move
    pos[i, 2] = pos[i, 2] + uz * move
    ledger[2] -= (gravity[0] * ux + gravity[1] * uy + gravity[2] * uz) * move / ima[i]


def _uncross(
    kind: Any,
    pos: Any,
    ext: Any,
    ima: Any,
    s_kind: Any,
    s_a: Any,
    s_b: Any,
    side: Any,
    gravity: Any,
    slop: float,
    ledger: Any,
) -> None:
    """A body of finite mass whose centre Forward Euler carried onto or across a line or plane it
    started the step on one side of (``side``, :func:`_sides`) is put back on that side, in contact:
    overlapping it by ``slop``, so that the step's contacts find it and its impulse and push-apart
    act as on any contact (a two-sided boundary would otherwise see it from the far side, and push
    it on through). The move is a positional correction: its potential energy change goes to
    ``ledger[2]``, the depth undone to ``ledger[4]``. A body that stays on its side is not moved."""
    for i in range(pos.shape[0]):
        if ima[i] == 0.0:
            continue
        for s in range(s_kind.shape[0]):
            was = side[i, s]
            if was == 0.0:
                continue
            ux = s_b[s, 0]
            uy = s_b[s, 1]
            uz = s_b[s, 2]
            t = ux * (pos[i, 0] - s_a[s, 0]) + uy * (pos[i, 1] - s_a[s, 1]) + uz * (pos[i, 2] - s_a[s, 2])
            if t * was > 0.0:
                continue
            reach = _reach(kind, ext, i, ux, uy, uz)
            ledger[4] = max(ledger[4], reach - t * was)
            _shift(pos, ima, i, ux, uy, uz, was * (reach - slop) - t, gravity, ledger)


def _clamp_to_sides(
    kind: Any,
    pos: Any,
    ext: Any,
    ima: Any,
    s_kind: Any,
    s_a: Any,
    s_b: Any,
    side: Any,
    ca: Any,
    cb: Any,
    count: int,
    gravity: Any,
    slop: float,
    ledger: Any,
) -> None:
    """Lines and planes are hard on the side a body is on (``side``, taken after
    :func:`_uncross`), as walls are on their inside (:func:`_clamp_to_walls`): a body of finite
    mass that the pushes of its neighbours left overlapping one, or past it, is put back a gap
    ``slop`` clear of it on its own side (its potential energy change to ``ledger[2]``). Only
    bodies in a contact can have been pushed."""
    for c in range(count):
        for end in range(2):
            b = cb[c] if end == 0 else ca[c]
            if b < 0 or ima[b] == 0.0:
                continue
            for s in range(s_kind.shape[0]):
                was = side[b, s]
                if was == 0.0:
                    continue
                ux = was * s_b[s, 0]
                uy = was * s_b[s, 1]
                uz = was * s_b[s, 2]
                t = ux * (pos[b, 0] - s_a[s, 0]) + uy * (pos[b, 1] - s_a[s, 1]) + uz * (pos[b, 2] - s_a[s, 2])
                gap = t - _reach(kind, ext, b, ux, uy, uz)
                if gap >= 0.0:
                    continue
                ledger[4] = max(ledger[4], -gap)
                _shift(pos, ima, b, ux, uy, uz, slop - gap, gravity, ledger)


def _no_energy_from_corrections(
    pos: Any, vel: Any, ima: Any, start: Any, held: Any, driven: Any, gravity: Any, ledger: Any
) -> None:
    """Positional corrections (push-apart, the clamps) move bodies without a force that does work.
    One that leaves a body of finite mass higher (against gravity) than it was at the start of
    the step (``start``) has added that potential energy to the world, and in a pile such lifts,
    falling back, keep it boiling. So the rise the corrections made (from ``held``, the positions
    they started from), as far as the body ends above its start, comes out of its kinetic energy
    (its velocity scaled down, its direction kept), as far as it has any, and is booked with the
    corrections (``ledger[2]``). A body the corrections did not lift, or only back to where it
    started (out of the overlap its own fall made), keeps its velocity; so does one in contact
    with a kinematic body (``driven[i] == 1``), which may do work on it (a paddle)."""
    for i in range(pos.shape[0]):
        if ima[i] == 0.0 or driven[i] == 1:
            continue
        lift = -(
            gravity[0] * (pos[i, 0] - held[i, 0])
            + gravity[1] * (pos[i, 1] - held[i, 1])
            + gravity[2] * (pos[i, 2] - held[i, 2])
        )
        if lift <= 0.0:
            continue
        rise = -(
            gravity[0] * (pos[i, 0] - start[i, 0])
            + gravity[1] * (pos[i, 1] - start[i, 1])
            + gravity[2] * (pos[i, 2] - start[i, 2])
        )
        if rise <= 0.0:
            continue
        kinetic = 0.5 * (vel[i, 0] * vel[i, 0] + vel[i, 1] * vel[i, 1] + vel[i, 2] * vel[i, 2]) / ima[i]
        if kinetic == 0.0:
            continue
        taken = min(min(lift, rise) / ima[i], kinetic)
        scale = math.sqrt((kinetic - taken) / kinetic)
        vel[i, 0] = vel[i, 0] * scale
        vel[i, 1] = vel[i, 1] * scale
        vel[i, 2] = vel[i, 2] * scale
        ledger[2] -= taken
