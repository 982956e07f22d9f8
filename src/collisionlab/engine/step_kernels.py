"""The Forward Euler stepper over arrays, written once: it runs as Python for small worlds and
compiled by numba (:mod:`collisionlab.engine.compiled`) for large ones, the same source both ways.

One step, in this fixed order (the lab's part VI, for any number of bodies):

1. **Integrate** with Forward Euler: ``x += v dt``, then ``v += g dt`` (bodies of finite mass).
   A body whose centre this carries onto or across a line or plane it started the step on one
   side of is put back on that side, ``slop`` into it (:func:`_uncross`): the contact found
   next bounces it there, so nothing ends on the far side of a line or plane.
2. **Broad phase**: a uniform grid of cells as wide as the bodies it holds (plus
   ``contact_margin``): all but the widest one in ``LARGE_SHARE``, so a few large boxes leave the
   cells small. Bodies are sorted into it by a counting sort and stored in cell order; each cell
   meets itself and half its neighbours, so every unordered pair of cells is visited once
   (Ericson, *Real-Time Collision Detection*, 7.1-7.1.3). A grid of more cells than its budget
   (a sparse or spread-out scene) is hashed into buckets instead of being coarsened (7.1.3). Each
   of the larger bodies meets the grid's bodies in the cells its box covers, and the other larger
   bodies. Statics (lines, planes, walls, fixed boxes) meet every body.
3. **Narrow phase**: each candidate pair's separation from
   :mod:`collisionlab.engine.geometry_kernels` (one kernel per pair of features). Pairs closer
   than ``contact_margin`` are "near"; those closer than ``solver_margin`` are contacts. Each
   contact's normal is kept: positions do not change until push-apart.
4. **Order**: contacts deepest first; ties broken by geometry (the positions of the two bodies,
   lexicographically, lower first), never by storage, so permuting the bodies permutes the
   result exactly; body pairs before static contacts, statics by their number. Only the
   contacts that share a body with another are sorted: a contact alone on its bodies (a ball
   touching only the floor) changes nothing in a sweep wherever it comes, so those come after
   the others, and each pass's events are then put back in the order of all of them.
5. **Impulses**, contact after contact in that order, each from the current velocities
   (sequential impulses): ``v_n = (v_b - v_a) . n``; nothing if ``v_n >= 0``; else
   ``j = -(1 + e) v_n / (1/m_a + 1/m_b)``, ``v_a -= (j/m_a) n``,
   ``v_b += (j/m_b) n`` (lab eqs. 12, 15, 24). Swept again while a sweep applies one, at most
   ``passes`` times (under gravity up to ``settle_passes`` while a sweep still changes some
   speed by more than ``rest_speed``, so a stack settles); a sweep after the first looks again
   only at the contacts one of whose bodies' velocity changed since they were last looked at
   (the others would give the same result: nothing). A pair gets an impulse when it touches or
   overlaps, or, if it was already in contact, when it is within ``solver_margin`` (so a
   resting stack stays supported). An impulse on a pair that was not already in contact is a
   collision event, unless it rests on a support that does not fall (a static or a kinematic
   body): an approach no faster than ``rest_speed + |g . n| dt`` (what gravity alone adds in
   one step) is a body pressed onto its support, and gets no event; and e = 0 below
   ``rest_speed + 2 |g . n| dt / e^2``, where the bounce would not rise above the depth one step
   of approach makes (the same for two bodies already touching: one holds the other up, as in
   a stack). So a ball on a floor or an incline stays on it and slides without hops or events,
   a stack does not bounce inside, and a dropped ball comes to rest after a few bounces instead
   of hopping forever.
6. **Push apart**, in the same order, from current positions: a pair still overlapping by ``d``
   moves apart to a gap of ``slop``, shared in inverse proportion to mass; swept the same way
   (after the first sweep only contacts one of whose bodies moved since they were last looked at).
   Finally every body past a one-sided wall is put back inside it (walls are hard), and every
   body a push left overlapping a line or plane, on the side it is on, is put back clear of it
   (:func:`_clamp_to_sides`). Under gravity, a body these corrections lifted above where it
   started the step pays that potential energy from its kinetic energy
   (:func:`_no_energy_from_corrections`): push-apart makes no energy.

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
    "_int",
    "_shift",
    "_bool",
    "_pair_e",
    "_pair_sep",
    "_body_separation",
    "_static_sep",
    "_static_separation",
    "_contact_separation",
    "_cell_of",
    "_lex_cmp",
    "_lex3",
    "_contact_cmp",
    "_orient",
    "_static_bounds_meet",
    "_pair_key",
    "_key_of",
    "_contains",
    "_body_width",
    "_wider",
    "_bucket",
    "_put_event",
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
#: Runs of contacts of equal depth up to this long are sorted by insertion, longer ones by their
#: first coordinate (bodies resting on a plane at the same depth make runs of hundreds).
_SHORT_RUN = 16
#: The grid's cells are as wide as all bodies but the widest ``n // LARGE_SHARE`` (those meet the
#: cells they cover instead), so a few large boxes among many small balls leave cells small.
LARGE_SHARE = 32
#: A hashed grid's buckets per body (at least; a power of two): a row of three cells then meets
#: about ``3 / BUCKETS_PER_BODY`` bodies of other cells sharing its buckets.
BUCKETS_PER_BODY = 8
#: Cells per axis below which a cell's coordinates are kept in one key ``x + KEY_Y y + KEY_Z z``.
AXIS_CELLS = 2**20
_KEY_Y = 2**21
_KEY_Z = 2**42
#: Multipliers of a hashed grid's bucket ``(x + HASH_Y y + HASH_Z z) mod buckets`` (large primes,
#: as Teschner et al. 2003; x stays in sequence, so a row of cells is a run of buckets).
_HASH_Y = 73856093
_HASH_Z = 19349663
#: Knuth's multiplicative hash of a pair's key (an odd constant near 2^62 / golden ratio), kept
#: to 62 bits so that the Python and compiled forms (unbounded and wrapping integers) agree.
_KEY_MIX = 0x278DDE6E5FD29F05
_LOW_62 = 2**62 - 1
#: The tick of a contact never looked at (later than any).
_NEVER = 2**62


# --- state helpers ------------------------------------------------------------------------------
def _int(value: int) -> int:
    """``value`` as an ordinary integer in the compiled form. numba types a variable that starts
    at a constant (``k = 0``) as that constant (``Literal[int](0)``) until its inference reaches
    the loop that changes it, and compiles each kernel the variable is passed to for both types:
    twice (the exact stepper's ``_impacts`` took two minutes more to compile). So a counter passed
    to a kernel that is not inlined starts at ``_int(0)``, and a constant argument is ``_int(1)``;
    ``tests/test_numba_cache.py`` checks that no kernel is compiled twice.

    >>> _int(0)
    0
    """
    return int(value)


def _bool(value: bool) -> bool:
    """``value`` as an ordinary bool in the compiled form (:func:`_int`: ``Literal[bool]``).

    >>> _bool(False)
    False
    """
    return bool(value)


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


def _pair_sep(
    ka: int,
    ax: float,
    ay: float,
    az: float,
    ea0: float,
    ea1: float,
    ea2: float,
    kb: int,
    bx: float,
    by: float,
    bz: float,
    eb0: float,
    eb1: float,
    eb2: float,
) -> Any:
    """Separation of a body of kind ``ka`` at ``a`` (half sizes ``ea``) and one of kind ``kb`` at
    ``b``, normal from a to b: :func:`_body_separation` on numbers (the hot loops call this; a
    helper taking arrays costs more than the work inside)."""
    if ka <= BALL_3D and kb <= BALL_3D:
        return gk.separation_ball_ball(ax, ay, az, ea0, bx, by, bz, eb0)
    if ka <= BALL_3D:
        return gk.separation_ball_box(
            ax, ay, az, ea0, bx - eb0, by - eb1, bz - eb2, bx + eb0, by + eb1, bz + eb2, 2 if ka == BALL_2D else 3
        )
    if kb <= BALL_3D:
        s = gk.separation_ball_box(
            bx, by, bz, eb0, ax - ea0, ay - ea1, az - ea2, ax + ea0, ay + ea1, az + ea2, 2 if kb == BALL_2D else 3
        )
        return (s[0], -s[1], -s[2], -s[3], s[4], s[5], s[6])
    return gk.separation_box_box(
        ax - ea0,
        ay - ea1,
        az - ea2,
        ax + ea0,
        ay + ea1,
        az + ea2,
        bx - eb0,
        by - eb1,
        bz - eb2,
        bx + eb0,
        by + eb1,
        bz + eb2,
        2 if ka == BOX_2D else 3,
    )


def _body_separation(kind: Any, pos: Any, ext: Any, a: int, b: int) -> Any:
    """Separation of bodies ``a`` and ``b``, normal from a to b."""
    return _pair_sep(
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


def _static_sep(
    sk: int,
    ox: float,
    oy: float,
    oz: float,
    ux: float,
    uy: float,
    uz: float,
    kb: int,
    bx: float,
    by: float,
    bz: float,
    e0: float,
    e1: float,
    e2: float,
) -> Any:
    """Separation of a static of kind ``sk`` (a point ``o`` and unit normal ``u``, or a fixed
    box's corners ``o``, ``u``) and a body of kind ``kb`` at ``b`` (half sizes ``e``), normal from
    the static to the body: :func:`_static_separation` on numbers."""
    ball = kb <= BALL_3D
    if sk == STATIC_BOX:
        if ball:
            r = gk.separation_ball_box(bx, by, bz, e0, ox, oy, oz, ux, uy, uz, 2 if kb == BALL_2D else 3)
            return (r[0], -r[1], -r[2], -r[3], r[4], r[5], r[6])
        return gk.separation_box_box(
            ox, oy, oz, ux, uy, uz, bx - e0, by - e1, bz - e2, bx + e0, by + e1, bz + e2, 2 if kb == BOX_2D else 3
        )
    if ball:
        if sk == STATIC_WALL:
            return gk.separation_wall_ball(ox, oy, oz, ux, uy, uz, bx, by, bz, e0)
        return gk.separation_boundary_ball(ox, oy, oz, ux, uy, uz, bx, by, bz, e0)
    if sk == STATIC_WALL:
        return gk.separation_wall_box(ox, oy, oz, ux, uy, uz, bx - e0, by - e1, bz - e2, bx + e0, by + e1, bz + e2)
    return gk.separation_boundary_box(ox, oy, oz, ux, uy, uz, bx - e0, by - e1, bz - e2, bx + e0, by + e1, bz + e2)


def _static_separation(s_kind: Any, s_a: Any, s_b: Any, s: int, kind: Any, pos: Any, ext: Any, b: int) -> Any:
    """Separation of static ``s`` and body ``b``, normal from the static to the body."""
    return _static_sep(
        s_kind[s],
        s_a[s, 0],
        s_a[s, 1],
        s_a[s, 2],
        s_b[s, 0],
        s_b[s, 1],
        s_b[s, 2],
        kind[b],
        pos[b, 0],
        pos[b, 1],
        pos[b, 2],
        ext[b, 0],
        ext[b, 1],
        ext[b, 2],
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


def _body_width(ext: Any, i: int, dims: int) -> float:
    """The widest side of body ``i``'s box: ``2 max_k e_k`` over the first ``dims`` axes."""
    w: float = ext[i, 0]
    for k in range(1, dims):
        w = max(w, ext[i, k])
    return 2.0 * w


def _wider(e0: float, e1: float, e2: float, dims: int, half: float) -> bool:
    """Whether a body of half sizes ``e`` is wider than ``2 half`` (``_body_width > 2 half``)."""
    return e0 > half or e1 > half or (dims == 3 and e2 > half)


def _grid_width(ext: Any, dims: int) -> float:
    """The widest body the grid holds: all but the widest ``n // LARGE_SHARE`` bodies (fewer
    when others are as wide) are at most this wide; the rest are met by the cells they cover."""
    n = ext.shape[0]
    widths = np.zeros(n)
    for i in range(n):
        widths[i] = _body_width(ext, i, dims)
    widths = np.sort(widths)
    return float(widths[n - 1 - min(n // LARGE_SHARE, n - 1)])


def _grid_plan(
    pos: Any, ext: Any, dims: int, width: float, h: float, max_cells: int, lo: Any, shape: Any
) -> tuple[float, int]:
    """Fill ``lo`` (lowest corner) and ``shape`` (cells per axis, 1 for a missing axis) of a grid
    of cell side ``h`` over the bodies at most ``width`` wide, and return ``(h, buckets)``: the
    cells themselves if there are fewer than ``max_cells`` (``buckets = 0``), else the cells
    hashed into ``buckets``, the power of two at least ``BUCKETS_PER_BODY`` per body (Ericson
    7.1.3): a sparse or spread-out scene keeps cells one body wide. ``h`` is doubled only while an axis would have
    ``AXIS_CELLS`` cells or more (a cell's coordinates then fit its key)."""
    n = pos.shape[0]
    hi = np.zeros(3)
    for k in range(3):
        lo[k] = math.inf
        hi[k] = -math.inf
    half = 0.5 * width
    for i in range(n):
        if _wider(ext[i, 0], ext[i, 1], ext[i, 2], dims, half):
            continue
        for k in range(dims):
            x = pos[i, k]
            lo[k] = min(lo[k], x)
            hi[k] = max(hi[k], x)
    for k in range(3):
        if k >= dims:
            lo[k] = 0.0
            hi[k] = 0.0
    while True:
        widest = 0.0
        for k in range(dims):
            widest = max(widest, (hi[k] - lo[k]) / h)
        if widest < AXIS_CELLS:
            break
        h *= 2.0
    cells = 1.0
    for k in range(3):
        shape[k] = int((hi[k] - lo[k]) / h) + 1 if k < dims else 1
        cells *= shape[k]
    if cells <= max_cells - 1:
        return h, 0
    buckets = 1
    while buckets < BUCKETS_PER_BODY * n:
        buckets *= 2
    return h, buckets


def _bucket(x: int, y: int, z: int, nx: int, ny: int, buckets: int) -> int:
    """The bucket of cell ``(x, y, z)``: the cell's number, or hashed if ``buckets > 0``."""
    if buckets == 0:
        return x + nx * (y + ny * z)
    return (x + _HASH_Y * y + _HASH_Z * z) & (buckets - 1)


def _bucket_sort(
    pos: Any,
    ext: Any,
    dims: int,
    lo: Any,
    h: float,
    shape: Any,
    width: float,
    buckets: int,
    cell_start: Any,
    dest: Any,
    key_of: Any,
    cell_key: Any,
) -> int:
    """:func:`_counting_sort` on the grid of :func:`_grid_plan`: by cell, or by bucket if
    ``buckets > 0`` (then ``cell_key[slot]`` is the cell of the body in that slot,
    ``x + KEY_Y y + KEY_Z z``); bodies wider than ``width`` go after all the others, in one more
    bucket. Returns how many bodies the grid holds (they come first)."""
    n = pos.shape[0]
    nx = shape[0]
    ny = shape[1]
    last = buckets if buckets > 0 else nx * ny * shape[2]
    for c in range(last + 3):
        cell_start[c] = 0
    half = 0.5 * width
    for i in range(n):
        if _wider(ext[i, 0], ext[i, 1], ext[i, 2], dims, half):
            c = last
        else:
            cx = int((pos[i, 0] - lo[0]) / h)
            cy = int((pos[i, 1] - lo[1]) / h)
            cz = int((pos[i, 2] - lo[2]) / h) if dims == 3 else 0
            c = _bucket(cx, cy, cz, nx, ny, buckets)
            key_of[i] = cx + _KEY_Y * cy + _KEY_Z * cz
        dest[i] = c
        cell_start[c + 2] += 1
    for c in range(2, last + 3):
        cell_start[c] += cell_start[c - 1]
    for i in range(n):
        c = dest[i]
        d = cell_start[c + 1]
        dest[i] = d
        cell_start[c + 1] += 1
        if buckets > 0:
            cell_key[d] = key_of[i]
    return int(cell_start[last])


# --- phase 3: contacts --------------------------------------------------------------------------
def _lex3(x0: float, y0: float, z0: float, x1: float, y1: float, z1: float) -> int:
    """-1, 0 or 1 as ``(x0, y0, z0)`` is lexicographically before, equal to or after ``(x1, y1, z1)``."""
    if x0 != x1:
        return -1 if x0 < x1 else 1
    if y0 != y1:
        return -1 if y0 < y1 else 1
    if z0 != z1:
        return -1 if z0 < z1 else 1
    return 0


def _lex_cmp(pos: Any, i: int, j: int) -> int:
    """-1, 0 or 1 as ``pos[i]`` is lexicographically before, equal to or after ``pos[j]``."""
    return _lex3(pos[i, 0], pos[i, 1], pos[i, 2], pos[j, 0], pos[j, 1], pos[j, 2])


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
    """Every pair closer than ``margin``, bodies stored in cell order (the grid of
    :func:`_grid_geometry` and :func:`_counting_sort`); returns how many (which may exceed the
    buffers' capacity: the caller grows them and asks again). ``cd`` is the depth (minus the
    separation)."""
    none = np.zeros(0, np.int64)
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
        0,
        pos.shape[0],
        cell_start,
        stencil,
        none,
        ca,
        cb,
        cd,
        np.zeros((0, 3)),
        margin,
        margin,
        np.zeros(0),
        0.0,
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
    buckets: int,
    n_small: int,
    cell_start: Any,
    stencil: Any,
    cell_key: Any,
    ca: Any,
    cb: Any,
    cd: Any,
    cn: Any,
    margin: float,
    static_margin: float,
    sweep: Any,
    base: float,
) -> int:
    """:func:`_find_contacts` on the grid of :func:`_grid_plan` and :func:`_bucket_sort`: the
    grid's cells (or, if ``buckets > 0``, its buckets, each body's cell in ``cell_key``) hold the
    bodies in slots ``0 : n_small``; each meets the bodies of its own cell after it and of the
    neighbour cells in ``stencil``, a row of consecutive cells (consecutive slots) at a time. The
    larger bodies after them each meet the grid's bodies in the cells their box, widened by 1.5
    cells, covers (all of them if there are fewer), then the larger bodies after it. Also keeps
    each contact's unit normal in ``cn`` (rows of three) while ``cn`` has room: the positions do
    not change until push-apart, so the impulse sweeps read it there instead of computing the
    separation again. A static is met within ``static_margin``; a pair of bodies within
    ``margin``, or, if ``sweep`` has a row per body, within ``base + sweep[a] + sweep[b]`` (each
    body's own sweep, at most ``margin - base`` together: the grid's cells are sized for
    ``margin``)."""
    n = pos.shape[0]
    cap = ca.shape[0]
    cap_n = cn.shape[0]
    per_body = sweep.shape[0] > 0
    nx = shape[0]
    ny = shape[1]
    nz = shape[2]
    # The stencil as rows: runs of entries at one (dy, dz) with dx rising by one.
    rows = np.zeros((stencil.shape[0], 4), np.int64)
    n_rows = 0
    for t in range(stencil.shape[0]):
        r = n_rows - 1
        if (
            n_rows > 0
            and stencil[t, 1] == rows[r, 2]
            and stencil[t, 2] == rows[r, 3]
            and stencil[t, 0] == rows[r, 1] + 1
        ):
            rows[r, 1] = stencil[t, 0]
        else:
            rows[n_rows, 0] = stencil[t, 0]
            rows[n_rows, 1] = stencil[t, 0]
            rows[n_rows, 2] = stencil[t, 1]
            rows[n_rows, 3] = stencil[t, 2]
            n_rows += 1
    # Body i's candidates: runs of slots (first, end), each with the range of cell keys it may
    # hold (hashed buckets also hold other cells' bodies; key_lo > key_hi: no filter).
    runs = np.zeros((2 * max(n_rows, n) + 2, 4), np.int64)
    count = 0
    for i in range(n):
        n_runs = 0
        cx = cy = cz = y_first = z_first = y_rows = 0
        x0 = x1 = 0.0
        if i < n_small:
            cx = int((pos[i, 0] - lo[0]) / h)
            cy = int((pos[i, 1] - lo[1]) / h)
            cz = int((pos[i, 2] - lo[2]) / h) if dims == 3 else 0
            r_end = n_rows
        else:
            # A larger body: a grid body within reach has its centre less than h - width / 2
            # from the box (h / 2 more is taken, for rounding); its rows of cells, or every
            # grid body.
            x0 = max((pos[i, 0] - ext[i, 0] - 1.5 * h - lo[0]) / h, 0.0)
            x1 = min((pos[i, 0] + ext[i, 0] + 1.5 * h - lo[0]) / h, nx - 1.0)
            y0 = max((pos[i, 1] - ext[i, 1] - 1.5 * h - lo[1]) / h, 0.0)
            y1 = min((pos[i, 1] + ext[i, 1] + 1.5 * h - lo[1]) / h, ny - 1.0)
            z0 = max((pos[i, 2] - ext[i, 2] - 1.5 * h - lo[2]) / h, 0.0) if dims == 3 else 0.0
            z1 = min((pos[i, 2] + ext[i, 2] + 1.5 * h - lo[2]) / h, nz - 1.0) if dims == 3 else 0.0
            r_end = 0
            if x0 <= x1 and y0 <= y1 and z0 <= z1:
                y_first = int(y0)
                z_first = int(z0)
                y_rows = int(y1) - y_first + 1
                r_end = y_rows * (int(z1) - z_first + 1)
                if r_end > n_small:  # more rows of cells than grid bodies: every grid body
                    runs[0, 0] = 0
                    runs[0, 1] = n_small
                    runs[0, 2] = 1
                    runs[0, 3] = 0
                    n_runs = 1
                    r_end = 0
            runs[n_runs, 0] = i + 1
            runs[n_runs, 1] = n
            runs[n_runs, 2] = 1
            runs[n_runs, 3] = 0
            n_runs += 1
        for r in range(r_end):
            first = -1
            if i < n_small:
                y2 = cy + rows[r, 2]
                z2 = cz + rows[r, 3]
                if y2 < 0 or y2 >= ny or z2 < 0 or z2 >= nz:
                    continue
                xa = max(cx + rows[r, 0], 0)
                xb = min(cx + rows[r, 1], nx - 1)
                if rows[r, 0] == 0 and rows[r, 2] == 0 and rows[r, 3] == 0:
                    first = i + 1  # i's own cell: the bodies after it
            else:
                y2 = y_first + r % y_rows
                z2 = z_first + r // y_rows
                xa = int(x0)
                xb = int(x1)
            if xa > xb:
                continue
            if buckets == 0:
                c = xa + nx * (y2 + ny * z2)
                runs[n_runs, 0] = first if first >= 0 else cell_start[c]
                runs[n_runs, 1] = cell_start[c + xb - xa + 1]
                runs[n_runs, 2] = 1
                runs[n_runs, 3] = 0
                n_runs += 1
                continue
            key_a = xa + _KEY_Y * y2 + _KEY_Z * z2
            c = _bucket(xa, y2, z2, nx, ny, buckets)
            end = c + xb - xa + 1
            if end > buckets:  # the row's buckets wrap around: the tail, then the head
                runs[n_runs, 0] = first if first >= 0 else cell_start[c]
                runs[n_runs, 1] = cell_start[buckets]
                runs[n_runs, 2] = key_a
                runs[n_runs, 3] = key_a + xb - xa
                n_runs += 1
                c = 0
                end -= buckets
                first = -1
            runs[n_runs, 0] = first if first >= 0 else cell_start[c]
            runs[n_runs, 1] = cell_start[end]
            runs[n_runs, 2] = key_a
            runs[n_runs, 3] = key_a + xb - xa
            n_runs += 1
        px = pos[i, 0]
        py = pos[i, 1]
        pz = pos[i, 2]
        ex = ext[i, 0]
        ey = ext[i, 1]
        ez = ext[i, 2]
        ball = kind[i] <= BALL_3D
        own = base + sweep[i] if per_body else margin
        for r in range(n_runs):
            key_lo = runs[r, 2]
            key_hi = runs[r, 3]
            for j in range(runs[r, 0], runs[r, 1]):
                if key_lo <= key_hi and (cell_key[j] < key_lo or cell_key[j] > key_hi):
                    continue
                pair_margin = own + sweep[j] if per_body else margin
                # The cheap reject, written out here (it runs for every candidate pair): the
                # bounding boxes, then for two balls the squared distance of the centres.
                dx = pos[j, 0] - px
                dy = pos[j, 1] - py
                dz = pos[j, 2] - pz
                if (
                    abs(dx) > ex + ext[j, 0] + pair_margin
                    or abs(dy) > ey + ext[j, 1] + pair_margin
                    or abs(dz) > ez + ext[j, 2] + pair_margin
                ):
                    continue
                if ball and kind[j] <= BALL_3D:
                    apart = ex + ext[j, 0] + pair_margin
                    if dx * dx + dy * dy + dz * dz > apart * apart * _WIDEN:
                        continue
                a = i
                b = j
                if ids[i] >= ids[j]:  # as _orient: the body given first is A
                    a = j
                    b = i
                sep = _pair_sep(
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
                if sep[0] <= pair_margin:
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
                if (abs(side) if s_kind[s] == STATIC_BOUNDARY else side) > reach + static_margin:
                    continue
            elif (  # a fixed box: the bounding boxes, as _static_bounds_meet
                pos[i, 0] + ext[i, 0] + static_margin < s_a[s, 0]
                or pos[i, 0] - ext[i, 0] - static_margin > s_b[s, 0]
                or pos[i, 1] + ext[i, 1] + static_margin < s_a[s, 1]
                or pos[i, 1] - ext[i, 1] - static_margin > s_b[s, 1]
                or pos[i, 2] + ext[i, 2] + static_margin < s_a[s, 2]
                or pos[i, 2] - ext[i, 2] - static_margin > s_b[s, 2]
            ):
                continue
            sep = _static_sep(
                s_kind[s],
                s_a[s, 0],
                s_a[s, 1],
                s_a[s, 2],
                s_b[s, 0],
                s_b[s, 1],
                s_b[s, 2],
                kind[i],
                pos[i, 0],
                pos[i, 1],
                pos[i, 2],
                ext[i, 0],
                ext[i, 1],
                ext[i, 2],
            )
            if sep[0] <= static_margin:
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
    bp = cb[p]
    bq = cb[q]
    if ap < 0:
        c = _lex3(pos[bp, 0], pos[bp, 1], pos[bp, 2], pos[bq, 0], pos[bq, 1], pos[bq, 2])
        if c != 0:
            return c
        if ap > aq:  # statics are -1 - s: the larger code is the lower number
            return -1
        if ap < aq:
            return 1
        return 0
    lp, hp = (
        (ap, bp) if _lex3(pos[ap, 0], pos[ap, 1], pos[ap, 2], pos[bp, 0], pos[bp, 1], pos[bp, 2]) <= 0 else (bp, ap)
    )
    lq, hq = (
        (aq, bq) if _lex3(pos[aq, 0], pos[aq, 1], pos[aq, 2], pos[bq, 0], pos[bq, 1], pos[bq, 2]) <= 0 else (bq, aq)
    )
    c = _lex3(pos[lp, 0], pos[lp, 1], pos[lp, 2], pos[lq, 0], pos[lq, 1], pos[lq, 2])
    if c != 0:
        return c
    return _lex3(pos[hp, 0], pos[hp, 1], pos[hp, 2], pos[hq, 0], pos[hq, 1], pos[hq, 2])


def _insertion_sort(pos: Any, ca: Any, cb: Any, order: Any, s: int, t: int) -> None:
    """Sort ``order[s:t]`` by :func:`_contact_cmp`, equal contacts by their storage index (so the
    order the run comes in does not matter)."""
    for u in range(s + 1, t):
        key = order[u]
        v = u - 1
        while v >= s:
            c = _contact_cmp(pos, ca, cb, key, order[v])
            if c > 0 or (c == 0 and key > order[v]):
                break
            order[v + 1] = order[v]
            v -= 1
        order[v + 1] = key


def _sort_run(pos: Any, ca: Any, cb: Any, order: Any, s: int, t: int, spare: Any) -> None:
    """:func:`_insertion_sort` for a long run, the same order: body pairs first, each part sorted
    by the first coordinate of the position :func:`_contact_cmp` compares first (the lower
    body's, or the body's), then the rare runs of equal first coordinates by
    :func:`_insertion_sort`."""
    k = s
    for u in range(s, t):
        if ca[order[u]] >= 0:
            spare[k] = order[u]
            k += 1
    middle = k
    for u in range(s, t):
        if ca[order[u]] < 0:
            spare[k] = order[u]
            k += 1
    for u in range(s, t):
        order[u] = spare[u]
    for part in range(2):
        u0 = s if part == 0 else middle
        u1 = middle if part == 0 else t
        if u1 - u0 < 2:
            continue
        first = np.empty(u1 - u0)
        for u in range(u0, u1):
            a = ca[order[u]]
            b = cb[order[u]]
            low = a if a >= 0 and _lex3(pos[a, 0], pos[a, 1], pos[a, 2], pos[b, 0], pos[b, 1], pos[b, 2]) <= 0 else b
            first[u - u0] = pos[low, 0]
        rank = np.argsort(first)
        for u in range(u0, u1):
            spare[u] = order[u0 + rank[u - u0]]
        for u in range(u0, u1):
            order[u] = spare[u]
        v = 0
        while v < u1 - u0:
            w = v + 1
            while w < u1 - u0 and first[rank[w]] == first[rank[v]]:
                w += 1
            if w - v > 1:
                _insertion_sort(pos, ca, cb, order, u0 + v, u0 + w)
            v = w


def _order_contacts(pos: Any, ca: Any, cb: Any, cd: Any, count: int) -> Any:
    """Contacts deepest first; runs of equal depth sorted by :func:`_contact_cmp`, then by storage
    index (as a stable sort of the depths would leave them): by insertion, or :func:`_sort_run`
    for runs longer than ``_SHORT_RUN``, as resting contacts make. Every step of it may sort
    unstably: the order is total."""
    order = np.argsort(-cd[:count])
    spare = np.empty(count, np.int64)
    s = _int(0)
    while s < count:
        t = s + 1
        while t < count and cd[order[t]] == cd[order[s]]:
            t += 1
        if t - s > _SHORT_RUN:
            _sort_run(pos, ca, cb, order, s, t, spare)
        elif t - s > 1:
            _insertion_sort(pos, ca, cb, order, s, t)
        s = t
    return order


#: Columns of a contact's tie-break key (:func:`_tie_key`): its group, then six coordinates.
TIE_KEY_SIZE = 7


def _tie_key(pos: Any, ca: Any, cb: Any, c: int, keys: Any, row: int) -> None:
    """Write into ``keys[row]`` what :func:`_contact_cmp` compares for contact ``c``, so that a
    sort compares rows of numbers instead of reading and ordering positions at every comparison:
    0 and the lower then the higher of its two bodies' positions for a body pair, 1, the body's
    position and minus the static's code for a static contact (the larger code, the lower number,
    comes first). Rows compare lexicographically as ``_contact_cmp`` compares the contacts."""
    a = ca[c]
    b = cb[c]
    if a < 0:
        keys[row, 0] = 1.0
        for k in range(3):
            keys[row, 1 + k] = pos[b, k]
        keys[row, 4] = float(-a)
        keys[row, 5] = 0.0
        keys[row, 6] = 0.0
        return
    low = a
    high = b
    if _lex3(pos[a, 0], pos[a, 1], pos[a, 2], pos[b, 0], pos[b, 1], pos[b, 2]) > 0:
        low = b
        high = a
    keys[row, 0] = 0.0
    for k in range(3):
        keys[row, 1 + k] = pos[low, k]
        keys[row, 4 + k] = pos[high, k]


def _key_before(keys: Any, order: Any, p: int, q: int) -> bool:
    """Whether the contact at ``order[p]`` comes before the one at ``order[q]`` (their rows of
    ``keys`` are rows ``p`` and ``q``): by the rows, then by number (as a stable sort of the
    depths leaves a tie)."""
    for k in range(TIE_KEY_SIZE):
        if keys[p, k] != keys[q, k]:
            return bool(keys[p, k] < keys[q, k])
    return bool(order[p] < order[q])


def _keyed_insertion_sort(keys: Any, order: Any, s: int, t: int, row: Any) -> None:
    """Sort ``order[s:t]`` and its rows of ``keys`` by :func:`_key_before` (``row``: room for
    one row)."""
    for u in range(s + 1, t):
        v = u
        while v > s and _key_before(keys, order, v, v - 1):
            c = order[v]
            order[v] = order[v - 1]
            order[v - 1] = c
            for k in range(TIE_KEY_SIZE):
                row[k] = keys[v, k]
                keys[v, k] = keys[v - 1, k]
                keys[v - 1, k] = row[k]
            v -= 1


def _keyed_run_sort(keys: Any, order: Any, s: int, t: int, spare: Any, spare_keys: Any, row: Any) -> None:
    """Sort a long run ``order[s:t]`` by :func:`_key_before`: by the first two columns (group,
    then first coordinate) with one ``argsort``, then the runs equal in both by insertion."""
    m = t - s
    first = np.empty(m)
    for u in range(m):
        first[u] = keys[s + u, 1]
    rank = np.argsort(first)  # then body pairs (group 0) before static contacts, each in rank order
    k = 0
    for group in range(2):
        for u in range(m):
            if keys[s + rank[u], 0] == group:
                spare[k] = order[s + rank[u]]
                for col in range(TIE_KEY_SIZE):
                    spare_keys[k, col] = keys[s + rank[u], col]
                k += 1
    for u in range(m):
        order[s + u] = spare[u]
        for col in range(TIE_KEY_SIZE):
            keys[s + u, col] = spare_keys[u, col]
    v = s
    while v < t:
        w = v + 1
        while w < t and keys[w, 0] == keys[v, 0] and keys[w, 1] == keys[v, 1]:
            w += 1
        if w - v > 1:
            _keyed_insertion_sort(keys, order, v, w, row)
        v = w


def _order_subset(pos: Any, ca: Any, cb: Any, cd: Any, idx: Any, m: int) -> Any:
    """The contacts ``idx[:m]`` (in any order) in the order :func:`_order_contacts` gives all of
    them: deepest first, runs of equal depth by geometry, then by number; a sort of these alone,
    so the others cost nothing. The order is total, so any sort gives it: the depths by an
    unstable ``argsort``, then each run of equal depth by the numbers :func:`_tie_key` writes for
    it once (resting contacts make hundreds of short runs, and comparing positions again at every
    step of their sorts cost more than the ``argsort``)."""
    sub = idx[:m]
    depth = np.empty(m)
    for u in range(m):
        depth[u] = -cd[sub[u]]
    order = sub[np.argsort(depth)]
    keys = np.empty((m, TIE_KEY_SIZE))
    spare = np.empty(m, np.int64)
    spare_keys = np.empty((m, TIE_KEY_SIZE))
    row = np.empty(TIE_KEY_SIZE)
    s = _int(0)
    while s < m:
        t = s + 1
        while t < m and cd[order[t]] == cd[order[s]]:
            t += 1
        if t - s > 1:
            for u in range(s, t):
                _tie_key(pos, ca, cb, order[u], keys, u)
            if t - s > _SHORT_RUN:
                _keyed_run_sort(keys, order, s, t, spare, spare_keys, row)
            else:
                _keyed_insertion_sort(keys, order, s, t, row)
        s = t
    return order


def _order_coupled(pos: Any, ca: Any, cb: Any, cd: Any, idx: Any, m: int, degree: Any) -> Any:
    """The contacts ``idx[:m]`` in the order a sweep through them (impulses, the resting passes,
    push-apart) takes: those that share a body with another of them in :func:`_order_subset`'s
    order, then those alone on their bodies, in increasing number. A sweep reads and writes only
    a contact's two bodies (a static never changes), so where a contact alone on its bodies comes
    in the sweep changes nothing it computes (sums into the ledger aside, to rounding); among
    the others, each group sharing bodies meets in the order of the whole. On a slope where most
    bodies touch only the floor this sorts a few contacts instead of all of them. ``degree``:
    one zero per body, left zero.

    >>> pos = np.array([[0.0, 0, 0], [1.0, 0, 0], [5.0, 0, 0]])
    >>> ca, cb = np.array([-1, -1, 0, -1]), np.array([0, 1, 1, 2])
    >>> cd = np.array([1e-9, 2e-9, 0.0, 3e-9])  # the deepest, floor-2, is alone on body 2
    >>> _order_coupled(pos, ca, cb, cd, np.arange(4), 4, np.zeros(3, np.int64)).tolist()
    [1, 0, 2, 3]
    """
    for u in range(m):
        c = idx[u]
        if ca[c] >= 0:
            degree[ca[c]] += 1
        degree[cb[c]] += 1
    shared = np.empty(m, np.int64)
    order = np.empty(m, np.int64)
    k = _int(0)
    alone = m
    for u in range(m - 1, -1, -1):  # from the end, so those alone keep their increasing numbers
        c = idx[u]
        if degree[cb[c]] > 1 or (ca[c] >= 0 and degree[ca[c]] > 1):
            shared[k] = c
            k += 1
        else:
            alone -= 1
            order[alone] = c
    for u in range(m):
        c = idx[u]
        if ca[c] >= 0:
            degree[ca[c]] = 0
        degree[cb[c]] = 0
    first = _order_subset(pos, ca, cb, cd, shared, k)  # a total order: any input order gives it
    for u in range(k):
        order[u] = first[u]
    return order


def _events_in_order(
    events: Any, first: int, end: int, event_of: Any, order: Any, pos: Any, ca: Any, cb: Any, cd: Any
) -> None:
    """Put event rows ``first:end`` of one pass of :func:`_impulses` (row ``first + k`` from
    contact ``order[event_of[k]]``) in the order of their contacts in :func:`_order_contacts`:
    the order they would have been resolved in had every contact been sorted."""
    m = end - first
    if m < 2:
        return
    of = np.empty(m, np.int64)
    for k in range(m):
        of[k] = order[event_of[k]]
    wanted = _order_subset(pos, ca, cb, cd, of, m)
    by_contact = np.argsort(of)
    rows = events[first:end].copy()
    sorted_of = of[by_contact]
    for q in range(m):
        k = by_contact[np.searchsorted(sorted_of, wanted[q])]
        for col in range(events.shape[1]):
            events[first + q, col] = rows[k, col]


# --- touching memory ----------------------------------------------------------------------------
def _key_of(ka: int, kb: int, n: int) -> int:
    """The key of the pair of ids (or ``n + s`` for static ``s``) ``ka`` and ``kb``."""
    low = min(ka, kb)
    high = max(ka, kb)
    return int(low) * (n + 1_000_000) + int(high)


def _pair_key(ca: Any, cb: Any, ids: Any, n: int, c: int) -> int:
    """A key for a contact that does not depend on storage: ids for bodies, ``n + s`` for statics."""
    a = ca[c]
    return _key_of(ids[a] if a >= 0 else n + (-1 - a), ids[cb[c]], n)


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


def _mark_touching(
    touch_keys: Any, kept: int, table: Any, ca: Any, cb: Any, ids: Any, n: int, count: int, touching: Any
) -> None:
    """``touching[c] = 1`` for each contact whose key (:func:`_pair_key`) is among
    ``touch_keys[:kept]`` (in any order): they go into the hash table ``table`` (open addressing,
    a power of two at least twice ``kept`` long, -1 where empty; Knuth's multiplicative hash),
    which each contact then looks up."""
    size = table.shape[0]
    shift = 62
    while (1 << (62 - shift)) < size:
        shift -= 1
    for u in range(size):
        table[u] = -1
    for u in range(kept):
        key = int(touch_keys[u])
        slot = ((key * _KEY_MIX) & _LOW_62) >> shift
        while table[slot] >= 0:
            slot = (slot + 1) & (size - 1)
        table[slot] = key
    for c in range(count):
        a = ca[c]
        key = _key_of(ids[a] if a >= 0 else n + (-1 - a), ids[cb[c]], n)
        slot = ((key * _KEY_MIX) & _LOW_62) >> shift
        while table[slot] >= 0 and table[slot] != key:
            slot = (slot + 1) & (size - 1)
        touching[c] = 1 if table[slot] == key else 0


# --- phases 5 and 6: impulses and push-apart ----------------------------------------------------
def _events_with_room(events: Any, used: int, room: int) -> Any:
    """``events`` if at least ``room`` rows past the first ``used`` are free, else a copy at least
    twice as large (and ``used + room`` rows) with the first rows kept."""
    if events.shape[0] - used >= room:
        return events
    grown = np.zeros((max(2 * events.shape[0] + 16, used + room), events.shape[1]))
    grown[: events.shape[0]] = events
    return grown


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
    events = _events_with_room(events, count, _int(1))
    _put_event(events, count, kind_code, step, time, id_a, id_b, sep, vn, j, e, before, vel, a, b)
    return events


def _put_event(
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
) -> None:
    """Write event row ``count`` (the buffer has room: :func:`_events_with_room`)."""
    events[count, 0] = kind_code
    events[count, 1] = step
    events[count, 2] = time
    events[count, 3] = id_a
    events[count, 4] = id_b
    for k in range(6):
        events[count, 5 + k] = sep[1 + k]
    events[count, 11] = vn
    events[count, 12] = j
    events[count, 13] = e
    for k in range(6):
        events[count, 14 + k] = before[k]
    for k in range(3):
        events[count, 20 + k] = vel[a, k] if a >= 0 else 0.0
        events[count, 23 + k] = vel[b, k]


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
    event_of: Any,
    largest: Any,
    ledger: Any,
) -> Any:
    """One pass of impulses over the contacts, stored in the order they are resolved, each along
    its normal ``cn`` (found with the contacts: positions do not change while impulses are
    applied); returns the event buffer (grown if it had to be). ``event_count[1]`` counts the
    impulses this pass applied; ``event_of[k]`` gets the contact of the pass's k-th event;
    ``largest[0]`` is raised to the largest change of a body's speed an impulse makes.

    After the first pass a contact is looked at again only if the velocity of one of its bodies
    changed since it was last looked at: ``changed[body]`` is the tick of the body's last impulse,
    ``seen[c]`` that of the contact's last look (``_NEVER`` if none), and contact ``c`` looks at
    tick ``clock + c`` in this pass (ticks only grow). Its result could not differ from the last
    one, which applied nothing (an impulse changes the pair's own velocities), so skipping it
    changes no number."""
    before = np.zeros(6)
    first_event = event_count[0]
    for c in range(cd.shape[0]):
        b = cb[c]
        if not first_pass and changed[b] < seen[c]:
            a = ca[c]
            if a < 0 or changed[a] < seen[c]:
                continue  # neither velocity changed since this contact was last looked at
        if cd[c] < 0.0 and (touching[c] == 0 or cd[c] < -solver_margin):
            # Apart: a new impact needs contact (lab eqs. 2, 7, 9); a pair already in contact
            # keeps its impulses within solver_margin, so a resting stack stays supported.
            continue
        a = ca[c]
        ima_a = ima[a] if a >= 0 else 0.0
        inv_sum = ima_a + ima[b]
        if inv_sum == 0.0:
            continue
        tick = clock + c
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
                code = _int(EVENT_SKIPPED)
                sep = _contact_separation(kind, pos, ext, s_kind, s_a, s_b, a, b)
                events = _write_event(
                    events, event_count[0], code, step, time, id_a, ids[b], sep, vn, 0.0, 0.0, before, vel, a, b
                )
                event_of[event_count[0] - first_event] = c
                event_count[0] += 1
            continue
        e_pair = _pair_e(eb[a] if a >= 0 else s_e[-1 - a], eb[b], e_default)
        # Resting: an approach no faster than gravity along n gives in one step (plus rest_speed)
        # is a body pressed onto its support, not an impact: no event. And a bounce is kept only
        # if it would rise above the depth one step of approach makes, e^2 v^2 / (2 g_n) >= v dt,
        # else e = 0: shorter hops are numerical (Forward Euler and push-apart feed them).
        # Only a support that does not fall (a static, a kinematic body) holds a body up: two free
        # bodies fall together, and gravity adds nothing to their approach. Unless they already
        # touch: then one is held up by what is under it (a stack, a pile), and the approach the
        # passes leave between them is at most what gravity gives in one step; bouncing it would
        # make a resting stack jitter.
        supported = a < 0 or ima[a] == 0.0 or ima[b] == 0.0 or touching[c] == 1
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
        largest[0] = max(largest[0], abs(ja), abs(jb))
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
                event_of[event_count[0] - first_event] = c
                event_count[0] += 1
    return events


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
                sep = _pair_sep(
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
                sep = _static_sep(
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


def _sides(pos: Any, s_kind: Any, s_a: Any, s_b: Any, side: Any) -> bool:
    """``side[i, s]``: the side of line or plane ``s`` body ``i``'s centre is on, ``+1`` along its
    normal, ``-1`` against it, ``0`` on it (and for the other statics). Returns whether there is a
    line or plane at all."""
    any_line = False
    for s in range(s_kind.shape[0]):
        if s_kind[s] == STATIC_BOUNDARY:
            any_line = True
    if not any_line:
        return False
    for i in range(pos.shape[0]):
        for s in range(s_kind.shape[0]):
            side[i, s] = 0.0
            if s_kind[s] != STATIC_BOUNDARY:
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
    if kind[i] <= BALL_3D:
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
    settle_passes: int,
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
    ``(n, 2)`` are scratch space. ``touch_keys[:touch_count[0]]`` (keys of :func:`_pair_key`, in
    no order) are the pairs in contact, carried from step to step. A hashed grid's buckets
    (``BUCKETS_PER_BODY`` per body) are held only while the call runs. Returns the buffers
    ``(touch_keys, ca, cb, cd, events)``, grown if they had to be; ``event_count[0]`` counts the
    event rows written."""
    n = pos.shape[0]
    max_cells = cell_start.shape[0] - 2
    lo = np.zeros(3)
    shape = np.zeros(3, np.int64)
    cn = np.zeros((ca.shape[0], 3))  # each contact's normal, kept while positions stay
    width = _grid_width(ext, dims)  # the widest body in the grid; wider ones are met apart
    key_of = np.zeros(n, np.int64)
    cell_key = np.zeros(n, np.int64)
    hashed = np.zeros(0, np.int64)  # a hashed grid's buckets, held while this call runs
    no_reach = np.zeros(0)  # one margin for every pair (_find_pairs)
    # Ticks of the sweeps (see _impulses): a body's last velocity change, its last move; they
    # only grow, so values from earlier steps (other bodies, after the re-sort) are all older.
    table = np.zeros(16, np.int64)  # a hash table of the pairs in contact (_mark_touching)
    changed = np.full(n, -1, np.int64)
    moved = np.full(n, -1, np.int64)
    clock = _int(0)
    degree = np.zeros(n, np.int64)  # _order_coupled's count of contacts per body
    largest = np.zeros(1)  # the largest change of speed of a sweep of impulses (_impulses)
    every = np.arange(ca.shape[0])  # every contact's number
    side = np.zeros((n, s_kind.shape[0]))  # each body's side of each line and plane (_sides)
    # Under gravity, each body's position at the start of the step, in the order then and in the
    # order of the grid (_no_energy_from_corrections).
    lifts = gravity[0] != 0.0 or gravity[1] != 0.0 or gravity[2] != 0.0
    start = np.zeros((n if lifts else 0, 3))
    start_sorted = np.zeros((n if lifts else 0, 3))
    held = np.zeros((n if lifts else 0, 3))
    driven = np.zeros(n if lifts else 0, np.int8)
    for step in range(first_step, first_step + steps):
        time = (step + 1) * dt  # the time at the end of this step, when its contacts are resolved
        lines = _sides(pos, s_kind, s_a, s_b, side)
        if lifts:
            for i in range(n):
                for k in range(3):
                    start[i, k] = pos[i, k]
        _integrate(pos, vel, ima, gravity, dt, ledger)
        if lines:
            _uncross(kind, pos, ext, ima, s_kind, s_a, s_b, side, gravity, slop, ledger)
        # Sort the state by cell (Ericson 7.1.3): the pair search then reads memory in sequence.
        h, buckets = _grid_plan(pos, ext, dims, width, width + contact_margin, max_cells, lo, shape)
        if buckets > 0 and hashed.shape[0] < buckets + 3:
            hashed = np.zeros(buckets + 3, np.int64)
        starts = hashed if buckets > 0 else cell_start
        n_small = _bucket_sort(pos, ext, dims, lo, h, shape, width, buckets, starts, dest, key_of, cell_key)
        _store_in_cell_order(kind, pos, vel, ext, ima, eb, ids, scratch_f, scratch_i, dest)
        if lines:
            _sides(pos, s_kind, s_a, s_b, side)  # in the new order
        if lifts:
            _scatter_rows(start, start_sorted, dest)
        while True:  # listed again, into arrays twice as large, when they were too small
            count = _find_pairs(
                kind, pos, ext, ids, s_kind, s_a, s_b, dims, lo, h, shape, buckets, n_small, starts, stencil,
                cell_key, ca, cb, cd, cn, contact_margin, contact_margin, no_reach, 0.0,
            )  # fmt: skip
            if count <= ca.shape[0]:
                break
            ca = np.zeros(2 * count, np.int64)
            cb = np.zeros(2 * count, np.int64)
            cd = np.zeros(2 * count)
            cn = np.zeros((2 * count, 3))
        # Only the contacts sharing a body with another need the order (_order_coupled); the
        # events are put back in the order of all of them after each pass (_events_in_order).
        if every.shape[0] < count:
            every = np.arange(2 * count)
        order = _order_coupled(pos, ca, cb, cd, every, count, degree)
        # The contacts in that order, so that the sweeps read them in sequence.
        oa = ca[order]
        ob = cb[order]
        od = cd[order]
        on = cn[order]
        touching = np.zeros(count, np.int8)
        while table.shape[0] < 2 * touch_count[0]:
            table = np.zeros(2 * table.shape[0], np.int64)
        _mark_touching(touch_keys, touch_count[0], table, oa, ob, ids, n, count, touching)
        seen = np.full(count, _NEVER, np.int64)
        event_of = np.empty(count, np.int64)
        for p in range(max(passes, settle_passes)):
            event_count[1] = 0
            largest[0] = 0.0
            first_event = event_count[0]
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
                oa,
                ob,
                od,
                on,
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
                event_of,
                largest,
                ledger,
            )
            _events_in_order(events, first_event, event_count[0], event_of, order, pos, ca, cb, cd)
            clock += count
            if event_count[1] == 0:
                break
            # Past ``passes``, only while a sweep still changes some velocity by more than
            # rest_speed (a world with gravity): a stack or pile then settles instead of sinking.
            if p + 1 >= passes and not (rest_speed > 0.0 and largest[0] > rest_speed):
                break
        found = clock
        if lifts:  # where the corrections start from, and who a kinematic body touches
            for i in range(n):
                driven[i] = 0
                for k in range(3):
                    held[i, k] = pos[i, k]
            for c in range(count):
                if oa[c] >= 0 and ima[oa[c]] == 0.0:
                    driven[ob[c]] = 1
                if oa[c] >= 0 and ima[ob[c]] == 0.0:
                    driven[oa[c]] = 1
        resolution_order = np.arange(od.shape[0])
        for p in range(passes):
            moves = _push_sweep(
                kind,
                pos,
                ext,
                ima,
                s_kind,
                s_a,
                s_b,
                oa,
                ob,
                od,
                on,
                resolution_order,
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
        _clamp_to_walls(kind, pos, ext, ima, s_kind, s_a, s_b, oa, ob, count, gravity, slop, ledger)
        if lines:
            _clamp_to_sides(kind, pos, ext, ima, s_kind, s_a, s_b, side, oa, ob, count, gravity, slop, ledger)
        if lifts:
            _no_energy_from_corrections(pos, vel, ima, start_sorted, held, driven, gravity, ledger)
        # The pairs now in contact: near this step and already touching, or newly hit.
        kept = 0
        if count > touch_keys.shape[0]:
            touch_keys = np.zeros(2 * count, np.int64)
        for c in range(count):
            if touching[c] == 1:
                a = oa[c]
                touch_keys[kept] = _key_of(ids[a] if a >= 0 else n + (-1 - a), ids[ob[c]], n)
                kept += 1
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
    and their depths, without changing the state (the grid of :func:`run_steps`, on sorted
    copies; cells of ``min_cell`` if the bodies have no size and ``margin`` is 0)."""
    n = pos.shape[0]
    lo = np.zeros(3)
    shape = np.zeros(3, np.int64)
    width = _grid_width(ext, dims)
    h, buckets = _grid_plan(
        pos, ext, dims, width, width + margin if width + margin > 0.0 else min_cell, max_cells, lo, shape
    )
    starts = np.zeros((buckets if buckets > 0 else max_cells) + 3, np.int64)
    dest = np.zeros(n, np.int64)
    key_of = np.zeros(n, np.int64)
    cell_key = np.zeros(n, np.int64)
    n_small = _bucket_sort(pos, ext, dims, lo, h, shape, width, buckets, starts, dest, key_of, cell_key)
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
    no_normals = np.zeros((0, 3))
    while True:  # listed again, into arrays large enough, when they were too small
        count = _find_pairs(
            skind, spos, sext, sids, s_kind, s_a, s_b, dims, lo, h, shape, buckets, n_small, starts, stencil,
            cell_key, ca, cb, cd, no_normals, margin, margin, np.zeros(0), 0.0,
        )  # fmt: skip
        if count <= ca.shape[0]:
            break
        ca = np.zeros(count, np.int64)
        cb = np.zeros(count, np.int64)
        cd = np.zeros(count)
    pairs = np.zeros((count, 2), np.int64)
    for t in range(count):
        pairs[t, 0] = sids[ca[t]] if ca[t] >= 0 else ca[t]
        pairs[t, 1] = sids[cb[t]]
    return pairs, cd[:count].copy()
