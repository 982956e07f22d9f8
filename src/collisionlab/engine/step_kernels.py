"""The Forward Euler stepper over arrays, written once: it runs as Python for small worlds and
compiled by numba (:mod:`collisionlab.engine.compiled`) for large ones, the same source both ways.

One step, in this fixed order (the lab's part VI, for any number of bodies):

1. **Integrate** with Forward Euler: ``x += v dt``, then ``v += g dt`` (bodies of finite mass).
2. **Broad phase**: a uniform grid of cells at least one body wide; bodies are sorted into it by
   a counting sort and stored in cell order; each cell meets itself and half its neighbours, so
   every unordered pair of cells is visited once (Ericson, *Real-Time Collision Detection*,
   7.1-7.1.3). Statics (lines, planes, walls, fixed boxes) meet every body.
3. **Narrow phase**: each candidate pair's separation from
   :mod:`collisionlab.engine.geometry_kernels` (one kernel per pair of features). Pairs closer
   than ``contact_margin`` are "near"; those closer than ``solver_margin`` are contacts.
4. **Order**: contacts deepest first; ties broken by geometry (the positions of the two bodies,
   lexicographically, lower first), never by storage, so permuting the bodies permutes the
   result exactly; body pairs before static contacts, statics by their number.
5. **Impulses**, contact after contact in that order, each from the current velocities
   (sequential impulses): ``v_n = (v_b - v_a) . n``; nothing if ``v_n >= 0``; else
   ``j = -(1 + e) v_n / (1/m_a + 1/m_b)``, ``v_a -= (j/m_a) n``,
   ``v_b += (j/m_b) n`` (lab eqs. 12, 15, 24). Swept again while a sweep applies one, at most
   ``passes`` times. A pair gets an impulse when it touches or overlaps, or, if it was already in
   contact, when it is within ``solver_margin`` (so a resting stack stays supported). An impulse
   on a pair that was not already in contact is a collision event, unless it rests on a support
   that does not fall (a static or a kinematic body): an approach no faster than
   ``rest_speed + |g . n| dt`` (what gravity alone adds in one step) is a body pressed onto its
   support, and gets no event; and e = 0 below ``rest_speed + 2 |g . n| dt / e^2``,
   where the bounce would not rise above the depth one step of approach makes. So a ball on a
   floor or an incline stays on it and slides without hops or events, and a dropped ball comes
   to rest after a few bounces instead of hopping forever.
6. **Push apart**, in the same order, from current positions: a pair still overlapping by ``d``
   moves apart to a gap of ``slop``, shared in inverse proportion to mass; swept the same way.
   Finally every body past a one-sided wall is put back inside it (walls are hard).

Each body pair is oriented as the scenario orders pairs: A is the body given first (a ball-box
pair is computed ball first and its normal negated, as the scalar API mirrors it); a static is
always A. Negation is exact, so the orientation never changes a number.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..tolerances import BROADPHASE_WIDEN

if "_GEOMETRY" in globals():  # the compiled copy: the geometry kernels are compiled too
    gk: Any = globals()["_GEOMETRY"]
else:
    from . import geometry_kernels as gk

__all__ = [
    "BALL_2D",
    "BALL_3D",
    "BOX_2D",
    "BOX_3D",
    "EVENT_BELOW_REST",
    "EVENT_COLUMNS",
    "EVENT_IMPACT",
    "EVENT_SKIPPED",
    "LEDGER_SIZE",
    "STATIC_BOUNDARY",
    "STATIC_BOX",
    "STATIC_WALL",
    "find_near",
    "run_steps",
]

# Body kinds: circles and spheres, 2D and 3D boxes.
BALL_2D = 0
BALL_3D = 1
BOX_2D = 2
BOX_3D = 3
# Static kinds: a two-sided line or plane, a one-sided wall, a fixed box.
STATIC_BOUNDARY = 0
STATIC_WALL = 1
STATIC_BOX = 2

#: Helpers the compiled form inlines into their callers: they take arrays, and a call that passes
#: several numba arrays (each a struct of seven fields) costs more than the work inside.
INLINE = (
    "_pair_e",
    "_body_separation",
    "_static_separation",
    "_contact_separation",
    "_cell_of",
    "_lex_cmp",
    "_orient",
    "_static_bounds_meet",
    "_pair_key",
    "_contains",
    "_move_apart",
)

#: An event row's kind: an impact; a contact skipped as separating; an impact whose e was set to 0
#: because its approach was below the rest threshold (``below_rest_threshold`` of the event).
EVENT_IMPACT = 0
EVENT_SKIPPED = 1
EVENT_BELOW_REST = 2
#: Columns of an event row: kind (``EVENT_*``), step, time, id of A (a
#: static is ``-1 - s``), id of B, normal (3), point (3), v_n, j, e, v_a before (3), v_b before (3),
#: v_a after (3), v_b after (3). (A slow approach is a resting contact, never an event.)
EVENT_COLUMNS = 26
#: Ledger accumulators: integrator energy change, collisions' energy change, push-apart's,
#: the collisions' predicted loss sum (1 - e^2)/2 mu v_n^2, the deepest overlap undone,
#: body impulses applied, static impulses applied.
LEDGER_SIZE = 7


_WIDEN = 1.0 + BROADPHASE_WIDEN


# --- state helpers ------------------------------------------------------------------------------
def _pair_e(e_a: float, e_b: float, e_default: float) -> float:
    """A pair's restitution: the larger of the two overrides if any (NaN means none), else the
    scenario's default (Box2D mixes by max)."""
    if e_a != e_a and e_b != e_b:
        return e_default
    if e_a != e_a:
        return e_b
    if e_b != e_b:
        return e_a
    return max(e_a, e_b)


def _body_separation(kind: Any, pos: Any, ext: Any, a: int, b: int) -> Any:
    """Separation of bodies ``a`` and ``b``, normal from a to b."""
    ka = kind[a]
    kb = kind[b]
    if ka <= BALL_3D and kb <= BALL_3D:
        return gk.separation_ball_ball(
            pos[a, 0], pos[a, 1], pos[a, 2], ext[a, 0], pos[b, 0], pos[b, 1], pos[b, 2], ext[b, 0]
        )
    if ka <= BALL_3D or kb <= BALL_3D:
        ball = a if ka <= BALL_3D else b
        box = b if ka <= BALL_3D else a
        s = gk.separation_ball_box(
            pos[ball, 0],
            pos[ball, 1],
            pos[ball, 2],
            ext[ball, 0],
            pos[box, 0] - ext[box, 0],
            pos[box, 1] - ext[box, 1],
            pos[box, 2] - ext[box, 2],
            pos[box, 0] + ext[box, 0],
            pos[box, 1] + ext[box, 1],
            pos[box, 2] + ext[box, 2],
            2 if kind[ball] == BALL_2D else 3,
        )
        if ball == a:
            return s
        return (s[0], -s[1], -s[2], -s[3], s[4], s[5], s[6])
    return gk.separation_box_box(
        pos[a, 0] - ext[a, 0],
        pos[a, 1] - ext[a, 1],
        pos[a, 2] - ext[a, 2],
        pos[a, 0] + ext[a, 0],
        pos[a, 1] + ext[a, 1],
        pos[a, 2] + ext[a, 2],
        pos[b, 0] - ext[b, 0],
        pos[b, 1] - ext[b, 1],
        pos[b, 2] - ext[b, 2],
        pos[b, 0] + ext[b, 0],
        pos[b, 1] + ext[b, 1],
        pos[b, 2] + ext[b, 2],
        2 if ka == BOX_2D else 3,
    )


def _static_separation(s_kind: Any, s_a: Any, s_b: Any, s: int, kind: Any, pos: Any, ext: Any, b: int) -> Any:
    """Separation of static ``s`` and body ``b``, normal from the static to the body."""
    sk = s_kind[s]
    ball = kind[b] <= BALL_3D
    if sk == STATIC_BOX:
        if ball:
            r = gk.separation_ball_box(
                pos[b, 0],
                pos[b, 1],
                pos[b, 2],
                ext[b, 0],
                s_a[s, 0],
                s_a[s, 1],
                s_a[s, 2],
                s_b[s, 0],
                s_b[s, 1],
                s_b[s, 2],
                2 if kind[b] == BALL_2D else 3,
            )
            return (r[0], -r[1], -r[2], -r[3], r[4], r[5], r[6])
        return gk.separation_box_box(
            s_a[s, 0],
            s_a[s, 1],
            s_a[s, 2],
            s_b[s, 0],
            s_b[s, 1],
            s_b[s, 2],
            pos[b, 0] - ext[b, 0],
            pos[b, 1] - ext[b, 1],
            pos[b, 2] - ext[b, 2],
            pos[b, 0] + ext[b, 0],
            pos[b, 1] + ext[b, 1],
            pos[b, 2] + ext[b, 2],
            2 if kind[b] == BOX_2D else 3,
        )
    if ball:
        if sk == STATIC_WALL:
            return gk.separation_wall_ball(
                s_a[s, 0],
                s_a[s, 1],
                s_a[s, 2],
                s_b[s, 0],
                s_b[s, 1],
                s_b[s, 2],
                pos[b, 0],
                pos[b, 1],
                pos[b, 2],
                ext[b, 0],
            )
        return gk.separation_boundary_ball(
            s_a[s, 0], s_a[s, 1], s_a[s, 2], s_b[s, 0], s_b[s, 1], s_b[s, 2], pos[b, 0], pos[b, 1], pos[b, 2], ext[b, 0]
        )
    lox = pos[b, 0] - ext[b, 0]
    loy = pos[b, 1] - ext[b, 1]
    loz = pos[b, 2] - ext[b, 2]
    hix = pos[b, 0] + ext[b, 0]
    hiy = pos[b, 1] + ext[b, 1]
    hiz = pos[b, 2] + ext[b, 2]
    if sk == STATIC_WALL:
        return gk.separation_wall_box(
            s_a[s, 0], s_a[s, 1], s_a[s, 2], s_b[s, 0], s_b[s, 1], s_b[s, 2], lox, loy, loz, hix, hiy, hiz
        )
    return gk.separation_boundary_box(
        s_a[s, 0], s_a[s, 1], s_a[s, 2], s_b[s, 0], s_b[s, 1], s_b[s, 2], lox, loy, loz, hix, hiy, hiz
    )


def _contact_separation(kind: Any, pos: Any, ext: Any, s_kind: Any, s_a: Any, s_b: Any, a: int, b: int) -> Any:
    """Separation of a contact ``(a, b)``: ``a >= 0`` a body, ``a < 0`` the static ``-1 - a``."""
    if a >= 0:
        return _body_separation(kind, pos, ext, a, b)
    return _static_separation(s_kind, s_a, s_b, -1 - a, kind, pos, ext, b)


# --- phase 1: integrate -------------------------------------------------------------------------
def _integrate(pos: Any, vel: Any, ima: Any, gravity: Any, dt: float, ledger: Any) -> None:
    """Forward Euler, position first: ``x += v dt`` then ``v += g dt`` (static bodies keep v).
    The energy this changes (kinetic plus ``-m g.x``) goes to ``ledger[0]``."""
    n = pos.shape[0]
    gx = gravity[0]
    gy = gravity[1]
    gz = gravity[2]
    change = 0.0
    for i in range(n):
        vx = vel[i, 0]
        vy = vel[i, 1]
        vz = vel[i, 2]
        pos[i, 0] = pos[i, 0] + vx * dt
        pos[i, 1] = pos[i, 1] + vy * dt
        pos[i, 2] = pos[i, 2] + vz * dt
        if ima[i] > 0.0:
            wx = vx + gx * dt
            wy = vy + gy * dt
            wz = vz + gz * dt
            vel[i, 0] = wx
            vel[i, 1] = wy
            vel[i, 2] = wz
            kinetic = 0.5 * ((wx * wx + wy * wy + wz * wz) - (vx * vx + vy * vy + vz * vz))
            potential = -(gx * vx + gy * vy + gz * vz) * dt
            change += (kinetic + potential) / ima[i]
    ledger[0] += change


# --- phase 2: the grid --------------------------------------------------------------------------
def _grid_geometry(pos: Any, dims: int, min_cell: float, max_cells: int, lo: Any, shape: Any) -> float:
    """Fill ``lo`` (lowest corner) and ``shape`` (cells per axis, 1 for a missing axis) and return
    the cell side ``h >= min_cell``, widened by 1.5x until at most ``max_cells`` cells (so a sparse
    or very long scene cannot ask for a huge grid)."""
    n = pos.shape[0]
    hi = np.zeros(3)
    for k in range(3):
        lo[k] = 0.0
    for k in range(dims):
        lo[k] = pos[0, k]
        hi[k] = pos[0, k]
    for i in range(1, n):
        for k in range(dims):
            x = pos[i, k]
            if x < lo[k]:
                lo[k] = x
            elif x > hi[k]:
                hi[k] = x
    h = min_cell
    while True:
        cells = 1.0
        for k in range(dims):
            cells *= math.floor((hi[k] - lo[k]) / h) + 1.0
        if cells <= max_cells:
            break
        h *= 1.5
    for k in range(3):
        shape[k] = int((hi[k] - lo[k]) / h) + 1 if k < dims else 1
    return h


def _cell_of(pos: Any, i: int, dims: int, lo: Any, h: float, nx: int, ny: int) -> int:
    cx = int((pos[i, 0] - lo[0]) / h)
    cy = int((pos[i, 1] - lo[1]) / h)
    cz = int((pos[i, 2] - lo[2]) / h) if dims == 3 else 0
    return cx + nx * (cy + ny * cz)


def _counting_sort(pos: Any, dims: int, lo: Any, h: float, shape: Any, cell_start: Any, dest: Any) -> None:
    """Counting sort by cell: ``dest[i]`` is body i's new slot; afterwards the bodies of cell c
    are slots ``cell_start[c] : cell_start[c + 1]``. Counts go two places ahead so that the
    scatter cursor ends as the next cell's start (no shifting pass)."""
    n = pos.shape[0]
    nx = shape[0]
    ny = shape[1]
    ncell = nx * ny * shape[2]
    for c in range(ncell + 2):
        cell_start[c] = 0
    for i in range(n):
        c = _cell_of(pos, i, dims, lo, h, nx, ny)
        cell_start[c + 2] += 1
    for c in range(2, ncell + 2):
        cell_start[c] += cell_start[c - 1]
    for i in range(n):
        c = _cell_of(pos, i, dims, lo, h, nx, ny)
        dest[i] = cell_start[c + 1]
        cell_start[c + 1] += 1


def _scatter_rows(src: Any, dst: Any, dest: Any) -> None:
    for i in range(src.shape[0]):
        d = dest[i]
        for k in range(src.shape[1]):
            dst[d, k] = src[i, k]


def _scatter(src: Any, dst: Any, dest: Any) -> None:
    for i in range(src.shape[0]):
        dst[dest[i]] = src[i]


def _store_in_cell_order(
    kind: Any, pos: Any, vel: Any, ext: Any, ima: Any, eb: Any, ids: Any, scratch_f: Any, scratch_i: Any, dest: Any
) -> None:
    """Move every body to its slot ``dest[i]`` (through the scratch arrays ``(n, 11)`` and
    ``(n, 2)``), so that the pair search reads memory in sequence (Ericson 7.1.3)."""
    n = pos.shape[0]
    for i in range(n):
        d = dest[i]
        for k in range(3):
            scratch_f[d, k] = pos[i, k]
            scratch_f[d, 3 + k] = vel[i, k]
            scratch_f[d, 6 + k] = ext[i, k]
        scratch_f[d, 9] = ima[i]
        scratch_f[d, 10] = eb[i]
        scratch_i[d, 0] = kind[i]
        scratch_i[d, 1] = ids[i]
    for i in range(n):
        for k in range(3):
            pos[i, k] = scratch_f[i, k]
            vel[i, k] = scratch_f[i, 3 + k]
            ext[i, k] = scratch_f[i, 6 + k]
        ima[i] = scratch_f[i, 9]
        eb[i] = scratch_f[i, 10]
        kind[i] = scratch_i[i, 0]
        ids[i] = scratch_i[i, 1]


# --- phase 3: contacts --------------------------------------------------------------------------
def _lex_cmp(pos: Any, i: int, j: int) -> int:
    """-1, 0 or 1 as ``pos[i]`` is lexicographically before, equal to or after ``pos[j]``."""
    for k in range(3):
        if pos[i, k] < pos[j, k]:
            return -1
        if pos[i, k] > pos[j, k]:
            return 1
    return 0


def _orient(ids: Any, i: int, j: int) -> bool:
    """Whether the body pair ``(i, j)`` is A-B as the scenario orders pairs: the body given first
    is A (a ball-box pair is computed ball first and flipped, exactly, as the scalar API does)."""
    return bool(ids[i] < ids[j])


def _static_bounds_meet(s_kind: Any, s_a: Any, s_b: Any, s: int, pos: Any, ext: Any, b: int, margin: float) -> bool:
    """A cheap test that body ``b`` may be within ``margin`` of static ``s``: bounding boxes for a
    fixed box; for a line, plane or wall the centre's distance against the body's projected
    radius ``sum_k |u_k| e_k`` (Ericson 5.2.3), which is its reach along the normal."""
    if s_kind[s] == STATIC_BOX:
        for k in range(3):
            if pos[b, k] + ext[b, k] + margin < s_a[s, k] or pos[b, k] - ext[b, k] - margin > s_b[s, k]:
                return False
        return True
    side = 0.0
    reach = 0.0
    for k in range(3):
        side += s_b[s, k] * (pos[b, k] - s_a[s, k])
        reach += abs(s_b[s, k]) * ext[b, k]
    if s_kind[s] == STATIC_BOUNDARY:
        side = abs(side)
    return bool(side <= reach + margin)


def _find_contacts(
    kind: Any,
    pos: Any,
    ext: Any,
    ids: Any,
    s_kind: Any,
    s_a: Any,
    s_b: Any,
    dims: int,
    lo: Any,
    h: float,
    shape: Any,
    cell_start: Any,
    stencil: Any,
    ca: Any,
    cb: Any,
    cd: Any,
    margin: float,
) -> int:
    """Every pair closer than ``margin``, bodies stored in cell order; returns how many (which may
    exceed the buffers' capacity: the caller grows them and asks again). ``cd`` is the depth
    (minus the separation)."""
    return _find_pairs(
        kind,
        pos,
        ext,
        ids,
        s_kind,
        s_a,
        s_b,
        dims,
        lo,
        h,
        shape,
        cell_start,
        stencil,
        ca,
        cb,
        cd,
        np.zeros((0, 3)),
        margin,
    )


def _find_pairs(
    kind: Any,
    pos: Any,
    ext: Any,
    ids: Any,
    s_kind: Any,
    s_a: Any,
    s_b: Any,
    dims: int,
    lo: Any,
    h: float,
    shape: Any,
    cell_start: Any,
    stencil: Any,
    ca: Any,
    cb: Any,
    cd: Any,
    cn: Any,
    margin: float,
) -> int:
    """:func:`_find_contacts`, also keeping each contact's unit normal in ``cn`` (rows of three)
    while ``cn`` has room: the positions do not change until push-apart, so the impulse sweeps
    read it there instead of computing the separation again."""
    n = pos.shape[0]
    cap = ca.shape[0]
    cap_n = cn.shape[0]
    nx = shape[0]
    ny = shape[1]
    nz = shape[2]
    count = 0
    for i in range(n):
        cx = int((pos[i, 0] - lo[0]) / h)
        cy = int((pos[i, 1] - lo[1]) / h)
        cz = int((pos[i, 2] - lo[2]) / h) if dims == 3 else 0
        for t in range(stencil.shape[0]):
            x2 = cx + stencil[t, 0]
            y2 = cy + stencil[t, 1]
            z2 = cz + stencil[t, 2]
            if x2 < 0 or x2 >= nx or y2 < 0 or y2 >= ny or z2 < 0 or z2 >= nz:
                continue
            c2 = x2 + nx * (y2 + ny * z2)
            j0 = i + 1 if t == 0 else cell_start[c2]
            j1 = cell_start[c2 + 1]
            for j in range(j0, j1):
                # The cheap reject, written out here (it runs for every candidate pair): the
                # bounding boxes, then for two balls the squared distance of the centres.
                dx = pos[j, 0] - pos[i, 0]
                dy = pos[j, 1] - pos[i, 1]
                dz = pos[j, 2] - pos[i, 2]
                if (
                    abs(dx) > ext[i, 0] + ext[j, 0] + margin
                    or abs(dy) > ext[i, 1] + ext[j, 1] + margin
                    or abs(dz) > ext[i, 2] + ext[j, 2] + margin
                ):
                    continue
                if kind[i] <= BALL_3D and kind[j] <= BALL_3D:
                    reach = ext[i, 0] + ext[j, 0] + margin
                    if dx * dx + dy * dy + dz * dz > reach * reach * _WIDEN:
                        continue
                a = i
                b = j
                if not _orient(ids, i, j):
                    a = j
                    b = i
                sep = _body_separation(kind, pos, ext, a, b)
                if sep[0] <= margin:
                    if count < cap:
                        ca[count] = a
                        cb[count] = b
                        cd[count] = -sep[0]
                    if count < cap_n:
                        cn[count, 0] = sep[1]
                        cn[count, 1] = sep[2]
                        cn[count, 2] = sep[3]
                    count += 1
        for s in range(s_kind.shape[0]):
            if s_kind[s] != STATIC_BOX:  # a line, plane or wall: the centre's side, written out
                side = (
                    s_b[s, 0] * (pos[i, 0] - s_a[s, 0])
                    + s_b[s, 1] * (pos[i, 1] - s_a[s, 1])
                    + s_b[s, 2] * (pos[i, 2] - s_a[s, 2])
                )
                reach = abs(s_b[s, 0]) * ext[i, 0] + abs(s_b[s, 1]) * ext[i, 1] + abs(s_b[s, 2]) * ext[i, 2]
                if (abs(side) if s_kind[s] == STATIC_BOUNDARY else side) > reach + margin:
                    continue
            elif not _static_bounds_meet(s_kind, s_a, s_b, s, pos, ext, i, margin):
                continue
            sep = _static_separation(s_kind, s_a, s_b, s, kind, pos, ext, i)
            if sep[0] <= margin:
                if count < cap:
                    ca[count] = -1 - s
                    cb[count] = i
                    cd[count] = -sep[0]
                if count < cap_n:
                    cn[count, 0] = sep[1]
                    cn[count, 1] = sep[2]
                    cn[count, 2] = sep[3]
                count += 1
    return count


# --- phase 4: order -----------------------------------------------------------------------------
def _contact_cmp(pos: Any, ca: Any, cb: Any, p: int, q: int) -> int:
    """Tie-break of two contacts of equal depth, from geometry only: body pairs before static
    contacts; body pairs by the lower then the higher position of their two bodies; static
    contacts by the body's position, then the static's number."""
    ap = ca[p]
    aq = ca[q]
    if ap >= 0 and aq < 0:
        return -1
    if ap < 0 and aq >= 0:
        return 1
    if ap < 0:
        c = _lex_cmp(pos, cb[p], cb[q])
        if c != 0:
            return c
        if ap > aq:  # statics are -1 - s: the larger code is the lower number
            return -1
        if ap < aq:
            return 1
        return 0
    lp, hp = (ap, cb[p]) if _lex_cmp(pos, ap, cb[p]) <= 0 else (cb[p], ap)
    lq, hq = (aq, cb[q]) if _lex_cmp(pos, aq, cb[q]) <= 0 else (cb[q], aq)
    c = _lex_cmp(pos, lp, lq)
    if c != 0:
        return c
    return _lex_cmp(pos, hp, hq)


def _order_contacts(pos: Any, ca: Any, cb: Any, cd: Any, count: int) -> Any:
    """Contacts deepest first; runs of equal depth sorted by :func:`_contact_cmp`."""
    order = np.argsort(-cd[:count], kind="mergesort")
    s = 0
    while s < count:
        t = s + 1
        while t < count and cd[order[t]] == cd[order[s]]:
            t += 1
        for u in range(s + 1, t):  # insertion sort: ties are rare and short
            key = order[u]
            v = u - 1
            while v >= s and _contact_cmp(pos, ca, cb, key, order[v]) < 0:
                order[v + 1] = order[v]
                v -= 1
            order[v + 1] = key
        s = t
    return order


# --- touching memory ----------------------------------------------------------------------------
def _pair_key(ca: Any, cb: Any, ids: Any, n: int, c: int) -> int:
    """A key for a contact that does not depend on storage: ids for bodies, ``n + s`` for statics."""
    a = ca[c]
    ka = ids[a] if a >= 0 else n + (-1 - a)
    kb = ids[cb[c]]
    low = min(ka, kb)
    high = max(ka, kb)
    return int(low) * (n + 1_000_000) + int(high)


def _contains(sorted_keys: Any, count: int, key: int) -> bool:
    lo = 0
    hi = count
    while lo < hi:
        mid = (lo + hi) // 2
        if sorted_keys[mid] < key:
            lo = mid + 1
        else:
            hi = mid
    return lo < count and sorted_keys[lo] == key


# --- phases 5 and 6: impulses and push-apart ----------------------------------------------------
def _write_event(
    events: Any,
    count: int,
    kind_code: int,
    step: int,
    time: float,
    id_a: int,
    id_b: int,
    sep: Any,
    vn: float,
    j: float,
    e: float,
    before: Any,
    vel: Any,
    a: int,
    b: int,
) -> Any:
    """Append an event row, growing the buffer when full; returns the buffer."""
    if count >= events.shape[0]:
        grown = np.zeros((2 * events.shape[0] + 16, events.shape[1]))
        grown[: events.shape[0]] = events
        events = grown
    row = events[count]
    row[0] = kind_code
    row[1] = step
    row[2] = time
    row[3] = id_a
    row[4] = id_b
    for k in range(6):
        row[5 + k] = sep[1 + k]
    row[11] = vn
    row[12] = j
    row[13] = e
    for k in range(6):
        row[14 + k] = before[k]
    for k in range(3):
        row[20 + k] = vel[a, k] if a >= 0 else 0.0
        row[23 + k] = vel[b, k]
    return events


def _impulses(
    kind: Any,
    pos: Any,
    vel: Any,
    ext: Any,
    ima: Any,
    eb: Any,
    ids: Any,
    s_kind: Any,
    s_a: Any,
    s_b: Any,
    s_e: Any,
    ca: Any,
    cb: Any,
    cd: Any,
    cn: Any,
    order: Any,
    touching: Any,
    seen: Any,
    changed: Any,
    clock: int,
    e_default: float,
    rest_speed: float,
    gravity: Any,
    dt: float,
    solver_margin: float,
    first_pass: bool,
    step: int,
    time: float,
    record: bool,
    events: Any,
    event_count: Any,
    ledger: Any,
) -> Any:
    """One pass of impulses over the contacts in ``order``, each along its normal ``cn`` (found
    with the contacts: positions do not change while impulses are applied); returns the event
    buffer (grown if it had to be). ``event_count[1]`` counts the impulses this pass applied.

    After the first pass a contact is looked at again only if the velocity of one of its bodies
    changed since it was last looked at: ``changed[body]`` is the tick of the body's last impulse,
    ``seen[c]`` that of the contact's last look, and the contact at place ``t`` of this pass looks
    at tick ``clock + t`` (ticks only grow). Its result could not differ from the last one, which
    applied nothing (an impulse changes the pair's own velocities), so skipping it changes no
    number."""
    before = np.zeros(6)
    for t in range(order.shape[0]):
        c = order[t]
        if cd[c] < 0.0 and (touching[c] == 0 or cd[c] < -solver_margin):
            # Apart: a new impact needs contact (lab eqs. 2, 7, 9); a pair already in contact
            # keeps its impulses within solver_margin, so a resting stack stays supported.
            continue
        a = ca[c]
        b = cb[c]
        ima_a = ima[a] if a >= 0 else 0.0
        inv_sum = ima_a + ima[b]
        if inv_sum == 0.0:
            continue
        if not first_pass and changed[b] < seen[c] and (a < 0 or changed[a] < seen[c]):
            continue  # neither velocity changed since this contact was last looked at
        tick = clock + t
        seen[c] = tick
        nx = cn[c, 0]
        ny = cn[c, 1]
        nz = cn[c, 2]
        vax = vel[a, 0] if a >= 0 else 0.0
        vay = vel[a, 1] if a >= 0 else 0.0
        vaz = vel[a, 2] if a >= 0 else 0.0
        vn = (vel[b, 0] - vax) * nx + (vel[b, 1] - vay) * ny + (vel[b, 2] - vaz) * nz
        id_a = ids[a] if a >= 0 else a
        if vn >= 0.0:
            if record and first_pass and touching[c] == 0 and cd[c] >= 0.0:
                for k in range(6):
                    before[k] = 0.0
                code = EVENT_SKIPPED
                sep = _contact_separation(kind, pos, ext, s_kind, s_a, s_b, a, b)
                events = _write_event(
                    events, event_count[0], code, step, time, id_a, ids[b], sep, vn, 0.0, 0.0, before, vel, a, b
                )
                event_count[0] += 1
            continue
        e_pair = _pair_e(eb[a] if a >= 0 else s_e[-1 - a], eb[b], e_default)
        # Resting: an approach no faster than gravity along n gives in one step (plus rest_speed)
        # is a body pressed onto its support, not an impact: no event. And a bounce is kept only
        # if it would rise above the depth one step of approach makes, e^2 v^2 / (2 g_n) >= v dt,
        # else e = 0: shorter hops are numerical (Forward Euler and push-apart feed them).
        # Only a support that does not fall (a static, a kinematic body) holds a body up: two free
        # bodies fall together, and gravity adds nothing to their approach.
        supported = a < 0 or ima[a] == 0.0 or ima[b] == 0.0
        g_dt = abs(gravity[0] * nx + gravity[1] * ny + gravity[2] * nz) * dt if supported else 0.0
        resting = rest_speed + g_dt
        squared = e_pair * e_pair
        if g_dt == 0.0:
            bounce_floor = rest_speed
        elif squared > 0.0:
            bounce_floor = rest_speed + 2.0 * g_dt / squared
        else:
            bounce_floor = math.inf
        e = gk.applied_restitution(vn, e_pair, bounce_floor)
        j = gk.impulse_magnitude(vn, inv_sum, e)
        ja = j * ima_a
        jb = j * ima[b]
        kinetic_before = 0.0
        kinetic_after = 0.0
        before[0] = vax
        before[1] = vay
        before[2] = vaz
        before[3] = vel[b, 0]
        before[4] = vel[b, 1]
        before[5] = vel[b, 2]
        if a >= 0 and ima_a > 0.0:
            kinetic_before += (vax * vax + vay * vay + vaz * vaz) / ima_a
            vel[a, 0] = vax - nx * ja
            vel[a, 1] = vay - ny * ja
            vel[a, 2] = vaz - nz * ja
            kinetic_after += (vel[a, 0] * vel[a, 0] + vel[a, 1] * vel[a, 1] + vel[a, 2] * vel[a, 2]) / ima_a
            changed[a] = tick
        if ima[b] > 0.0:
            kinetic_before += (before[3] * before[3] + before[4] * before[4] + before[5] * before[5]) / ima[b]
            vel[b, 0] = before[3] + nx * jb
            vel[b, 1] = before[4] + ny * jb
            vel[b, 2] = before[5] + nz * jb
            kinetic_after += (vel[b, 0] * vel[b, 0] + vel[b, 1] * vel[b, 1] + vel[b, 2] * vel[b, 2]) / ima[b]
            changed[b] = tick
        ledger[1] += 0.5 * (kinetic_after - kinetic_before)
        ledger[3] -= 0.5 * (1.0 - e * e) * vn * vn / inv_sum
        if a >= 0:
            ledger[5] += 1.0
        else:
            ledger[6] += 1.0
        event_count[1] += 1
        if touching[c] == 0:
            touching[c] = 1
            if record and -vn >= resting:
                sep = _contact_separation(kind, pos, ext, s_kind, s_a, s_b, a, b)
                events = _write_event(
                    events,
                    event_count[0],
                    EVENT_BELOW_REST if -vn < bounce_floor else EVENT_IMPACT,
                    step,
                    time,
                    id_a,
                    ids[b],
                    sep,
                    vn,
                    j,
                    e,
                    before,
                    vel,
                    a,
                    b,
                )
                event_count[0] += 1
    return events


def _move_apart(
    pos: Any,
    ima: Any,
    a: int,
    b: int,
    sep0: float,
    nx: float,
    ny: float,
    nz: float,
    slop: float,
    gravity: Any,
    ledger: Any,
) -> None:
    """Move the pair ``(a, b)``, overlapping by ``-sep0`` along the normal ``n``, apart to a gap of
    ``slop``, in inverse proportion to mass (``a < 0``: a static, which stays). The potential
    energy this changes goes to ``ledger[2]``, the overlap to ``ledger[4]`` if it is the deepest."""
    ima_a = ima[a] if a >= 0 else 0.0
    inv_sum = ima_a + ima[b]
    ledger[4] = max(ledger[4], -sep0)
    push = slop - sep0
    sa = push * ima_a / inv_sum
    sb = push * ima[b] / inv_sum
    change = 0.0
    for k in range(3):
        n_k = nx if k == 0 else (ny if k == 1 else nz)
        if a >= 0 and ima_a > 0.0:
            pos[a, k] = pos[a, k] - n_k * sa
            change += gravity[k] * n_k * sa / ima_a
        pos[b, k] = pos[b, k] + n_k * sb
        if ima[b] > 0.0:
            change -= gravity[k] * n_k * sb / ima[b]
    ledger[2] += change


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
        sep = _contact_separation(kind, pos, ext, s_kind, s_a, s_b, a, b)
        if sep[0] >= 0.0:  # touching is not overlapping: nothing to undo
            continue
        _move_apart(pos, ima, a, b, sep[0], sep[1], sep[2], sep[3], slop, gravity, ledger)
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
    """:func:`_push_apart`'s pass, looking at a contact only when it could move something: in
    the first pass every contact; after it only those one of whose bodies moved since the contact
    was last looked at (``moved[body]`` against ``seen[c]``, ticks as in :func:`_impulses`; the
    contact at place ``t`` looks at tick ``clock + t``). A contact neither of whose bodies moved
    since tick ``found`` (when the contacts were found) takes its separation from there
    (``-cd``, ``cn``). Either way the same numbers as :func:`_push_apart`. Returns the moves."""
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
        last = moved[b]
        if a >= 0 and moved[a] > last:
            last = moved[a]
        if not first_pass and last < seen[c]:
            continue  # neither body moved since this contact was last looked at
        tick = clock + t
        seen[c] = tick
        if last < found:  # where it was found: the separation is the one found then
            if cd[c] <= 0.0:  # touching is not overlapping: nothing to undo
                continue
            _move_apart(pos, ima, a, b, -cd[c], cn[c, 0], cn[c, 1], cn[c, 2], slop, gravity, ledger)
        else:
            sep = _contact_separation(kind, pos, ext, s_kind, s_a, s_b, a, b)
            if sep[0] >= 0.0:
                continue
            _move_apart(pos, ima, a, b, sep[0], sep[1], sep[2], sep[3], slop, gravity, ledger)
        if a >= 0:
            moved[a] = tick
        moved[b] = tick
        moves += 1
    return moves


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
                if s_kind[s] != STATIC_WALL or not _static_bounds_meet(s_kind, s_a, s_b, s, pos, ext, b, 0.0):
                    continue
                sep = _static_separation(s_kind, s_a, s_b, s, kind, pos, ext, b)
                if sep[0] < 0.0:
                    ledger[4] = max(ledger[4], -sep[0])
                    push = slop - sep[0]
                    change = 0.0
                    for k in range(3):
                        pos[b, k] = pos[b, k] + sep[1 + k] * push
                        change -= gravity[k] * sep[1 + k] * push / ima[b]
                    ledger[2] += change


# --- the loop -----------------------------------------------------------------------------------
def run_steps(
    kind: Any,
    pos: Any,
    vel: Any,
    ext: Any,
    ima: Any,
    eb: Any,
    ids: Any,
    scratch_f: Any,
    scratch_i: Any,
    cell_start: Any,
    dest: Any,
    stencil: Any,
    s_kind: Any,
    s_a: Any,
    s_b: Any,
    s_e: Any,
    gravity: Any,
    dims: int,
    dt: float,
    e_default: float,
    slop: float,
    solver_margin: float,
    contact_margin: float,
    rest_speed: float,
    passes: int,
    min_cell: float,
    first_step: int,
    steps: int,
    record: bool,
    touch_keys: Any,
    touch_count: Any,
    ca: Any,
    cb: Any,
    cd: Any,
    events: Any,
    event_count: Any,
    ledger: Any,
) -> Any:
    """Advance ``steps`` steps in place (the module docstring's order). The state is re-sorted by
    cell each step and ``ids`` follows the bodies; ``scratch_f`` ``(n, 11)`` and ``scratch_i``
    ``(n, 2)`` are scratch space. ``touch_keys[:touch_count[0]]`` (sorted) are the pairs in
    contact, carried from step to step. Returns the buffers ``(touch_keys, ca, cb, cd, events)``,
    grown if they had to be; ``event_count[0]`` counts the event rows written."""
    n = pos.shape[0]
    max_cells = cell_start.shape[0] - 2
    lo = np.zeros(3)
    shape = np.zeros(3, np.int64)
    cn = np.zeros((ca.shape[0], 3))  # each contact's normal, kept while positions stay
    # Ticks of the sweeps (see _impulses): a body's last velocity change, its last move; they
    # only grow, so values from earlier steps (other bodies, after the re-sort) are all older.
    changed = np.full(n, -1, np.int64)
    moved = np.full(n, -1, np.int64)
    clock = 0
    for step in range(first_step, first_step + steps):
        time = (step + 1) * dt  # the time at the end of this step, when its contacts are resolved
        _integrate(pos, vel, ima, gravity, dt, ledger)
        # Sort the state by cell (Ericson 7.1.3): the pair search then reads memory in sequence.
        h = _grid_geometry(pos, dims, min_cell, max_cells, lo, shape)
        _counting_sort(pos, dims, lo, h, shape, cell_start, dest)
        _store_in_cell_order(kind, pos, vel, ext, ima, eb, ids, scratch_f, scratch_i, dest)
        count = _find_pairs(
            kind,
            pos,
            ext,
            ids,
            s_kind,
            s_a,
            s_b,
            dims,
            lo,
            h,
            shape,
            cell_start,
            stencil,
            ca,
            cb,
            cd,
            cn,
            contact_margin,
        )
        if count > ca.shape[0]:
            ca = np.zeros(2 * count, np.int64)
            cb = np.zeros(2 * count, np.int64)
            cd = np.zeros(2 * count)
            cn = np.zeros((2 * count, 3))
            _find_pairs(
                kind,
                pos,
                ext,
                ids,
                s_kind,
                s_a,
                s_b,
                dims,
                lo,
                h,
                shape,
                cell_start,
                stencil,
                ca,
                cb,
                cd,
                cn,
                contact_margin,
            )
        order = _order_contacts(pos, ca, cb, cd, count)
        touching = np.zeros(count, np.int8)
        for c in range(count):
            if _contains(touch_keys, touch_count[0], _pair_key(ca, cb, ids, n, c)):
                touching[c] = 1
        seen = np.empty(count, np.int64)
        for p in range(passes):
            event_count[1] = 0
            events = _impulses(
                kind,
                pos,
                vel,
                ext,
                ima,
                eb,
                ids,
                s_kind,
                s_a,
                s_b,
                s_e,
                ca,
                cb,
                cd,
                cn,
                order,
                touching,
                seen,
                changed,
                clock,
                e_default,
                rest_speed,
                gravity,
                dt,
                solver_margin,
                p == 0,
                step + 1,
                time,
                record,
                events,
                event_count,
                ledger,
            )
            clock += count
            if event_count[1] == 0:
                break
        found = clock
        for p in range(passes):
            moves = _push_sweep(
                kind,
                pos,
                ext,
                ima,
                s_kind,
                s_a,
                s_b,
                ca,
                cb,
                cd,
                cn,
                order,
                seen,
                moved,
                found,
                clock,
                p == 0,
                gravity,
                slop,
                solver_margin,
                ledger,
            )
            clock += count
            if moves == 0:
                break
        _clamp_to_walls(kind, pos, ext, ima, s_kind, s_a, s_b, ca, cb, count, gravity, slop, ledger)
        # The pairs now in contact: near this step and already touching, or newly hit.
        kept = 0
        if count > touch_keys.shape[0]:
            touch_keys = np.zeros(2 * count, np.int64)
        for c in range(count):
            if touching[c] == 1:
                touch_keys[kept] = _pair_key(ca, cb, ids, n, c)
                kept += 1
        touch_keys[:kept] = np.sort(touch_keys[:kept])
        touch_count[0] = kept
    return touch_keys, ca, cb, cd, events


def find_near(
    kind: Any,
    pos: Any,
    ext: Any,
    ids: Any,
    s_kind: Any,
    s_a: Any,
    s_b: Any,
    stencil: Any,
    dims: int,
    min_cell: float,
    max_cells: int,
    margin: float,
) -> Any:
    """Every pair closer than ``margin`` now, as rows ``(A, B)`` of ids (a static is ``-1 - s``)
    and their depths, without changing the state (the grid works on sorted copies)."""
    n = pos.shape[0]
    lo = np.zeros(3)
    shape = np.zeros(3, np.int64)
    h = _grid_geometry(pos, dims, min_cell, max_cells, lo, shape)
    cell_start = np.zeros(max_cells + 2, np.int64)
    dest = np.zeros(n, np.int64)
    _counting_sort(pos, dims, lo, h, shape, cell_start, dest)
    spos = np.zeros_like(pos)
    sext = np.zeros_like(ext)
    skind = np.zeros_like(kind)
    sids = np.zeros_like(ids)
    _scatter_rows(pos, spos, dest)
    _scatter_rows(ext, sext, dest)
    _scatter(kind, skind, dest)
    _scatter(ids, sids, dest)
    cap = max(16, n)
    ca = np.zeros(cap, np.int64)
    cb = np.zeros(cap, np.int64)
    cd = np.zeros(cap)
    count = _find_contacts(
        skind, spos, sext, sids, s_kind, s_a, s_b, dims, lo, h, shape, cell_start, stencil, ca, cb, cd, margin
    )
    if count > cap:
        ca = np.zeros(count, np.int64)
        cb = np.zeros(count, np.int64)
        cd = np.zeros(count)
        _find_contacts(
            skind, spos, sext, sids, s_kind, s_a, s_b, dims, lo, h, shape, cell_start, stencil, ca, cb, cd, margin
        )
    pairs = np.zeros((count, 2), np.int64)
    for t in range(count):
        pairs[t, 0] = sids[ca[t]] if ca[t] >= 0 else ca[t]
        pairs[t, 1] = sids[cb[t]]
    return pairs, cd[:count].copy()
