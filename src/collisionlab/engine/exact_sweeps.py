"""How far the exact stepper's bodies can move in what is left of a step (phase 1 of
:mod:`.exact_kernels`): the bounds the candidate pairs are listed for. Speeds are measured in the
frame of the middle velocity (a heap sliding as one is slow in it); each body is listed for
``SWEEP_GROWTH`` times its own speed, at least ``SWEEP_FLOOR`` of the fastest's, and
accelerations up to ``ACCELERATION_HEADROOM |g|``. A body that outruns its bound (phase 2, or a
kick in phase 4) has the candidates listed again.

Owns those constants and ``SWEEP_PAUSE``, the bounds (:func:`_velocity_bounds`, :func:`_sweeps`),
the checks against them (:func:`_speed_beyond`, :func:`_outrun`) and how much nearer a listed pair
can be since (:func:`_closing`). It imports no other file of the engine, and must not: the
impacts and the loop read the bounds, nothing here reads a contact.
"""

from __future__ import annotations

import math
from typing import Any

#: The candidates are listed for accelerations up to this many times ``|g|``: a support passes
#: the pressing of what rests on it along (a body low in a heap is pushed down the slope by those
#: above it), so a body's acceleration may exceed ``|g|``; listing for more makes a second listing
#: (when phase 2 finds a larger one) rare, at the cost of a sweep wider by ``|g| T^2 / 2``.
ACCELERATION_HEADROOM = 2.0
#: Each body's candidates are listed for a speed (relative to the heap's frame) up to this many
#: times its own, and at least ``SWEEP_FLOOR`` of the fastest body's (never more than that):
#: a body kicked past its bound has the candidates listed again (phase 4's restart), so the
#: bounds trade the sweep's width (candidates to predict and look at again) against restarts.
SWEEP_GROWTH = 2.0
SWEEP_FLOOR = 0.5
#: After a step cut by a kick past a body's own bound, this many steps list every body for the
#: fastest's speed (as if ``SWEEP_FLOOR`` were 1): while bodies land on others, a restart (a
#: listing more) would follow in most steps, costing more than the narrower sweeps save.
SWEEP_PAUSE = 50

#: Helpers the compiled form inlines into their callers (:mod:`.compiled`): the small ones, and
#: those the loop calls for every pair it looks at, which take arrays (a call costs a reference
#: count taken and given back for each array it passes; inlined into a ``NO_REFCOUNT`` phase,
#: none at all).
INLINE = (
    "_speed_beyond",
    "_closing",
)

#: The loop's phases here that allocate nothing, compiled without numba's reference counts
#: (:mod:`.compiled`).
NO_REFCOUNT = (
    "_outrun",
    "_sweeps",
)


def _velocity_bounds(vel: Any, v_ref: Any) -> Any:
    """``(v_bound, u_bound)``: the largest speed of a body, and the largest relative to
    ``v_ref``, which is set to the middle of the velocities' bounding box (a heap sliding down a
    slope moves fast, but hardly relative to itself).

    >>> import numpy as np
    >>> v_ref = np.zeros(3)
    >>> _velocity_bounds(np.array([[3.0, 0, 0], [5.0, 0, 0]]), v_ref), v_ref.tolist()
    ((5.0, 1.0), [4.0, 0.0, 0.0])
    """
    n = vel.shape[0]
    for k in range(3):
        low = math.inf
        high = -math.inf
        for i in range(n):
            low = min(low, vel[i, k])
            high = max(high, vel[i, k])
        v_ref[k] = 0.5 * (low + high) if n > 0 else 0.0
    v_bound = 0.0
    u_bound = 0.0
    for i in range(n):
        v_bound = max(v_bound, math.sqrt(vel[i, 0] ** 2 + vel[i, 1] ** 2 + vel[i, 2] ** 2))
        ux = vel[i, 0] - v_ref[0]
        uy = vel[i, 1] - v_ref[1]
        uz = vel[i, 2] - v_ref[2]
        u_bound = max(u_bound, math.sqrt(ux * ux + uy * uy + uz * uz))
    return v_bound, u_bound


def _speed_beyond(vel: Any, i: int, v_ref: Any, v_bound: float, u_bound: float) -> bool:
    """Whether body ``i`` is faster than ``v_bound``, or than ``u_bound`` relative to ``v_ref``."""
    ux = vel[i, 0] - v_ref[0]
    uy = vel[i, 1] - v_ref[1]
    uz = vel[i, 2] - v_ref[2]
    return bool(
        math.sqrt(vel[i, 0] ** 2 + vel[i, 1] ** 2 + vel[i, 2] ** 2) > v_bound
        or math.sqrt(ux * ux + uy * uy + uz * uz) > u_bound
    )


def _closing(a: int, elapsed: float, u_bound: float, v_bound: float, a_bound: float) -> float:
    """How much nearer than when listed a candidate pair (``a < 0``: a static's) can be
    ``elapsed`` later, its bodies within the bounds the candidates were listed for (phase 1)."""
    drift = 0.5 * a_bound * elapsed * elapsed
    if a >= 0:
        return 2.0 * (u_bound * elapsed + drift)
    return v_bound * elapsed + drift


def _outrun(acc: Any, vel: Any, v_ref: Any, v_bound: float, bound: Any, a_bound: float) -> Any:
    """Whether phase 2 left a body faster or more accelerated than the candidates were listed
    for (``bound[i]``: body ``i``'s speed relative to ``v_ref``), and the largest acceleration
    (at least ``a_bound``)."""
    grown = False
    for i in range(acc.shape[0]):
        size = math.sqrt(acc[i, 0] ** 2 + acc[i, 1] ** 2 + acc[i, 2] ** 2)
        if size > a_bound:
            a_bound = size
            grown = True
        if _speed_beyond(vel, i, v_ref, v_bound, bound[i]):
            grown = True
    return grown, a_bound


def _sweeps(
    vel: Any, v_ref: Any, u_bound: float, floor: float, remaining: float, drift: float, bound: Any, reach: Any
) -> None:
    """Each body's speed bound relative to ``v_ref`` for the listing (``SWEEP_GROWTH`` times its
    own, at least ``floor`` times ``u_bound``, the fastest's, at most that) in ``bound``, and how
    far it can move in that frame in the ``remaining`` time, ``bound T + drift``, in ``reach``:
    a pair of bodies is listed within the contact margin and both reaches.

    >>> import numpy as np
    >>> bound, reach = np.zeros(2), np.zeros(2)
    >>> _sweeps(np.array([[0.5, 0, 0], [4.0, 0, 0]]), np.zeros(3), 4.0, 0.5, 0.5, 0.25, bound, reach)
    >>> bound.tolist(), reach.tolist()  # max(2 x 0.5, 2) = 2, min(8, 4) = 4; 2 x 0.5 + 0.25, 4 x 0.5 + 0.25
    ([2.0, 4.0], [1.25, 2.25])
    >>> _sweeps(np.array([[0.5, 0, 0], [4.0, 0, 0]]), np.zeros(3), 4.0, 1.0, 0.5, 0.25, bound, reach)
    >>> bound.tolist()  # floor 1: every body listed for the fastest's speed
    [4.0, 4.0]
    """
    for i in range(vel.shape[0]):
        ux = vel[i, 0] - v_ref[0]
        uy = vel[i, 1] - v_ref[1]
        uz = vel[i, 2] - v_ref[2]
        own = SWEEP_GROWTH * math.sqrt(ux * ux + uy * uy + uz * uz)
        bound[i] = min(u_bound, max(own, floor * u_bound))
        reach[i] = bound[i] * remaining + drift
