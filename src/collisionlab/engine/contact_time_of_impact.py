"""A pair's separation and its first time of impact, for the contact stepper (phase 2 of
:mod:`.contact_kernels`): the engine's one time of impact of two bodies in flight
(:func:`~.pair_time_of_impact._time_of_impact`: conservative advancement along the separating
normal, Mirtich 1996; two balls in the same field of gravity in closed form, Ericson 4.4.3),
within ``TOI_GAP``; a pair touching slower than the rest speed has no impact (it is the solve's).

Owns a pair's separation at given positions or where the bodies are (:func:`_sep_of`,
:func:`_sep_now`: every other contact file asks it) and the contact stepper's call of the time
of impact (:func:`_pair_toi`). It imports :mod:`.pair_separation` and
:mod:`.pair_time_of_impact`; it must not import the candidates, impacts, solve, push-apart,
islands or the loop (which ask it, not the other way round).
"""

from __future__ import annotations

import math
from typing import Any

from ..tolerances import TOI_GAP

if "_PAIR_SEPARATION" in globals():  # the compiled copy: the kernels it calls are compiled too
    ps: Any = globals()["_PAIR_SEPARATION"]
    et: Any = globals()["_PAIR_TIME_OF_IMPACT"]
else:
    from . import pair_separation as ps
    from . import pair_time_of_impact as et

#: Helpers the compiled form inlines into their callers (:mod:`.compiled`).
INLINE = ("_sep_of", "_sep_now")


def _sep_of(
    kind: Any, ext: Any, s_kind: Any, s_a: Any, s_b: Any, a: int, b: int,
    ax: float, ay: float, az: float, bx: float, by: float, bz: float,
) -> Any:  # fmt: skip
    """Separation of pair ``(a, b)`` (``a < 0``: the static ``-1 - a``) with the bodies at the
    given positions, normal from a to b."""
    if a >= 0:
        return ps._pair_sep(
            kind[a], ax, ay, az, ext[a, 0], ext[a, 1], ext[a, 2], kind[b], bx, by, bz, ext[b, 0], ext[b, 1], ext[b, 2]
        )
    s = -1 - a
    return ps._static_sep(
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
    """When in ``[t, t_end)`` the pair ``(a, b)`` first touches (within ``TOI_GAP``) while
    approaching, or ``inf`` (phase 2 of :mod:`.contact_kernels`): the engine's one time of impact
    (:func:`~.pair_time_of_impact._time_of_impact`, conservative advancement). A pair that
    touches approaching slower than ``rest_speed`` gets ``inf``: that is no impact, but a resting
    contact (the solve's, until a kick predicts it again)."""
    return et._time_of_impact(  # type: ignore[no-any-return]
        kind, pos, vel, acc, tau, ext, s_kind, s_a, s_b, a, b, t, t_end, TOI_GAP, -math.inf, rest_speed
    )
