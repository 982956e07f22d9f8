"""The end of the exact stepper's step (phase 5 of :mod:`.exact_kernels`), before push-apart
(:mod:`.euler_push_apart`' ``_push_sweep``, as in Forward Euler): every candidate pair's depth at
the step's end, or a bound on it when its bodies cannot have come near enough to matter
(:func:`_end_separations`), and the pairs in contact remembered across the candidates' listings,
so a pair is reported once per impact (:func:`_save_touching`; a step cut by a kick lists them
again and remembers them first too).

It imports :mod:`.pair_separation`, :mod:`.touching_memory`'s pair keys and :mod:`.exact_sweeps`'
bound on how much nearer a listed pair can be; it must not import the other exact files (their
phases are over when this runs) or the loop, which calls it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

if "_PAIR_SEPARATION" in globals():  # the compiled copy: the kernels it calls are compiled too
    ps: Any = globals()["_PAIR_SEPARATION"]
    tm: Any = globals()["_TOUCHING_MEMORY"]
    es: Any = globals()["_EXACT_SWEEPS"]
else:
    from . import exact_sweeps as es
    from . import pair_separation as ps
    from . import touching_memory as tm

#: The phase here that allocates nothing, compiled without numba's reference counts
#: (:mod:`.compiled`).
NO_REFCOUNT = ("_end_separations",)


def _save_touching(
    ca: Any, cb: Any, ids: Any, n: int, count: int, touching: Any, near: Any, touch_keys: Any, touch_count: Any
) -> Any:
    """Remember the pairs in contact (touching and within the contact margin) across re-sorts, in
    no order (as :func:`~collisionlab.engine.step_kernels.run_steps`; looked up through a hash
    table, :func:`~collisionlab.engine.touching_memory._mark_touching`)."""
    if count > touch_keys.shape[0]:
        touch_keys = np.zeros(2 * count, np.int64)
    kept = 0
    for c in range(count):
        if touching[c] == 1 and near[c] == 1:
            touch_keys[kept] = tm._pair_key(ca, cb, ids, n, c)
            kept += 1
    touch_count[0] = kept
    return touch_keys


def _end_separations(
    kind: Any,
    pos: Any,
    ext: Any,
    s_kind: Any,
    s_a: Any,
    s_b: Any,
    ca: Any,
    cb: Any,
    cd: Any,
    cn: Any,
    count: int,
    near_idx: Any,
    elapsed: float,
    u_bound: float,
    v_bound: float,
    a_bound: float,
    contact_margin: float,
    gap: float,
    solver_margin: float,
) -> Any:
    """Phase 5's look at every candidate, its bodies at the step's end (``elapsed`` after the
    listing): ``cd`` gets its depth (or a bound on it, enough for a pair neither pushed apart nor
    in contact) and ``cn`` its normal; ``near_idx`` gets the pairs push-apart looks at, in their
    order. Returns how many, and whether any overlaps."""
    n_push = 0
    overlap = False
    for c in range(count):
        closing = es._closing(ca[c], elapsed, u_bound, v_bound, a_bound)
        if -cd[c] - closing > contact_margin + gap:
            cd[c] -= closing  # a bound is enough: neither pushed apart nor in contact
            continue
        sep = ps._contact_separation(kind, pos, ext, s_kind, s_a, s_b, ca[c], cb[c])
        cd[c] = -sep[0]
        for k in range(3):  # push-apart's first look at the pair, until a body moves
            cn[c, k] = sep[1 + k]
        if cd[c] >= -solver_margin:  # the pairs push-apart looks at, in its order
            near_idx[n_push] = c
            n_push += 1
            overlap = overlap or cd[c] > 0.0
    return n_push, overlap
