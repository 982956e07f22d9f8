"""Compiled loops of the particle world (numba, ``cache=True`` so a compile happens once per machine).

This module imports numba at the top: :mod:`collisionlab.particles.backend` imports it only when
numba is installed and falls back to :mod:`collisionlab.particles.numpy_kernels` otherwise. Both
modules evaluate every formula with the same floating-point operations in the same order, so the
two backends agree to the last bit on the same input (tested).

One step, in the world's documented order (see :class:`~collisionlab.particles.ParticleWorld`):

1. forward Euler: ``x += v dt``, then ``v += g dt`` (bodies of finite mass);
2. uniform grid of cells at least one diameter wide, bodies sorted into it by a counting sort
   (Ericson, *Real-Time Collision Detection*, 7.1.1-7.1.3); the state arrays are stored in cell
   order, so the pair search reads memory in sequence;
3. narrow phase over the cell and its half-stencil of neighbours (each unordered pair of cells
   once): a contact when ``|x_b - x_a| <= r_a + r_b`` (inclusive), a wall contact when
   ``n . x - c <= r`` (Ericson 5.2.2);
4. contacts ordered by depth, deepest first, ties broken by positions (never by storage index);
5. impulses in that order, each from the current velocities (sequential, so each impulse with
   ``e = 1`` conserves kinetic energy exactly up to rounding), swept again while a sweep still
   applies one (at most ``passes`` sweeps);
6. push-apart in that order, swept the same way, then the bodies touched are put back inside
   every wall.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, TypeVar, cast

import numba
import numpy as np

from ..tolerances import CONTACT_SLOP, FALLBACK_NORMAL, SOLVER_MARGIN

__all__ = ["find_pairs", "run_steps"]

_F = TypeVar("_F", bound=Callable[..., Any])

# Module globals are frozen into the compiled code as constants.
_SLOP = CONTACT_SLOP
_MARGIN = SOLVER_MARGIN
_FALLBACK = FALLBACK_NORMAL


def _jit(function: _F) -> _F:
    # error_model="numpy": a division by zero gives inf/nan instead of a Python exception check in
    # every division (there is none on the paths that run; the check only costs time).
    return cast(_F, numba.njit(cache=True, error_model="numpy")(function))


@_jit
def _grid_geometry(pos: Any, min_cell: float, max_cells: int, lo: Any, shape: Any) -> float:
    """Fill ``lo`` (lowest corner) and ``shape`` (cells per axis, 1 for a missing axis) and return
    the cell side ``h >= min_cell``, widened by 1.5x until at most ``max_cells`` cells (so a sparse
    or very long scene cannot ask for a huge grid)."""
    n, dim = pos.shape
    hi = np.empty(3)
    for k in range(3):
        lo[k] = 0.0
        hi[k] = 0.0
    for k in range(dim):
        lo[k] = pos[0, k]
        hi[k] = pos[0, k]
    for i in range(1, n):
        for k in range(dim):
            x = pos[i, k]
            if x < lo[k]:
                lo[k] = x
            elif x > hi[k]:
                hi[k] = x
    h = min_cell
    while True:
        cells = 1.0
        for k in range(dim):
            cells *= math.floor((hi[k] - lo[k]) / h) + 1.0
        if cells <= max_cells:
            break
        h *= 1.5
    for k in range(3):
        shape[k] = int((hi[k] - lo[k]) / h) + 1 if k < dim else 1
    return h


@_jit
def _counting_sort(pos: Any, lo: Any, h: float, shape: Any, cell_start: Any, dest: Any) -> None:
    """Counting sort by cell: ``dest[i]`` is body i's new slot; afterwards the bodies of cell c
    are slots ``cell_start[c] : cell_start[c + 1]``. Counts go two places ahead so that the
    scatter cursor ends as the next cell's start (no shifting pass)."""
    n, dim = pos.shape
    nx = shape[0]
    ny = shape[1]
    ncell = nx * ny * shape[2]
    for c in range(ncell + 2):
        cell_start[c] = 0
    for i in range(n):
        c = _cell_of(pos, i, dim, lo, h, nx, ny)
        cell_start[c + 2] += 1
    for c in range(2, ncell + 2):
        cell_start[c] += cell_start[c - 1]
    for i in range(n):
        c = _cell_of(pos, i, dim, lo, h, nx, ny)
        dest[i] = cell_start[c + 1]
        cell_start[c + 1] += 1


@_jit
def _cell_of(pos: Any, i: int, dim: int, lo: Any, h: float, nx: int, ny: int) -> int:
    cx = int((pos[i, 0] - lo[0]) / h)
    cy = int((pos[i, 1] - lo[1]) / h)
    cz = int((pos[i, 2] - lo[2]) / h) if dim == 3 else 0
    return cx + nx * (cy + ny * cz)


@_jit
def _scatter_rows(src: Any, dst: Any, dest: Any) -> None:
    for i in range(src.shape[0]):
        d = dest[i]
        for k in range(src.shape[1]):
            dst[d, k] = src[i, k]


@_jit
def _scatter(src: Any, dst: Any, dest: Any) -> None:
    for i in range(src.shape[0]):
        dst[dest[i]] = src[i]


@_jit
def _lex_cmp(pos: Any, i: int, j: int) -> int:
    """-1, 0 or 1 as ``pos[i]`` is lexicographically before, equal to or after ``pos[j]``."""
    for k in range(pos.shape[1]):
        if pos[i, k] < pos[j, k]:
            return -1
        if pos[i, k] > pos[j, k]:
            return 1
    return 0


@_jit
def _find_contacts(
    pos: Any,
    rad: Any,
    planes_n: Any,
    planes_c: Any,
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
    """Every contact of bodies stored in cell order; returns how many there are (which may exceed
    the capacity of ``ca``/``cb``/``cd``, in which case the caller grows them and asks again).
    ``margin`` widens the test (``SOLVER_MARGIN`` when stepping, 0 for plain queries).

    A body pair is written with ``a`` the body whose position is lexicographically first, so
    the record does not depend on storage order; a wall contact is ``(i, -1 - w)``. ``cd`` is the
    depth: ``r_a + r_b - |x_b - x_a| >= -margin`` or ``r - (n . x - c) >= -margin``.
    """
    n, dim = pos.shape
    cap = ca.shape[0]
    nx = shape[0]
    ny = shape[1]
    nz = shape[2]
    count = 0
    for i in range(n):
        cx = int((pos[i, 0] - lo[0]) / h)
        cy = int((pos[i, 1] - lo[1]) / h)
        cz = int((pos[i, 2] - lo[2]) / h) if dim == 3 else 0
        ri = rad[i]
        for s in range(stencil.shape[0]):
            x2 = cx + stencil[s, 0]
            y2 = cy + stencil[s, 1]
            z2 = cz + stencil[s, 2]
            if x2 < 0 or x2 >= nx or y2 < 0 or y2 >= ny or z2 < 0 or z2 >= nz:
                continue
            c2 = x2 + nx * (y2 + ny * z2)
            j0 = i + 1 if s == 0 else cell_start[c2]
            j1 = cell_start[c2 + 1]
            for j in range(j0, j1):
                dx = pos[j, 0] - pos[i, 0]
                dy = pos[j, 1] - pos[i, 1]
                d2 = dx * dx + dy * dy
                if dim == 3:
                    dz = pos[j, 2] - pos[i, 2]
                    d2 += dz * dz
                reach = ri + rad[j]
                dist = math.sqrt(d2)  # the touching test is on the distance itself, as in the core
                if dist <= reach + margin:
                    if count < cap:
                        if _lex_cmp(pos, j, i) < 0:
                            ca[count] = j
                            cb[count] = i
                        else:
                            ca[count] = i
                            cb[count] = j
                        cd[count] = reach - dist
                    count += 1
        for w in range(planes_n.shape[0]):
            side = 0.0
            for k in range(dim):
                side += planes_n[w, k] * pos[i, k]
            side -= planes_c[w]
            if side <= ri + margin:
                if count < cap:
                    ca[count] = i
                    cb[count] = -1 - w
                    cd[count] = ri - side
                count += 1
    return count


@_jit
def _contact_cmp(pos: Any, ca: Any, cb: Any, p: int, q: int) -> int:
    """Tie-break of two contacts of equal depth, from geometry only: first body's position,
    then body pairs before wall contacts, then the second body's position or the wall's number."""
    c = _lex_cmp(pos, ca[p], ca[q])
    if c != 0:
        return c
    bp = cb[p]
    bq = cb[q]
    if bp >= 0 and bq >= 0:
        return _lex_cmp(pos, bp, bq)
    if bp >= 0:
        return -1
    if bq >= 0:
        return 1
    if bp > bq:  # walls: -1 - w, so the larger code is the lower wall number
        return -1
    if bp < bq:
        return 1
    return 0


@_jit
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


@_jit
def _pair_normal(pos: Any, a: int, b: int, normal: Any) -> float:
    """Unit normal from a to b into ``normal``; returns the centre distance."""
    dim = pos.shape[1]
    d2 = 0.0
    for k in range(dim):
        normal[k] = pos[b, k] - pos[a, k]
        d2 += normal[k] * normal[k]
    dist = math.sqrt(d2)
    if dist > 0.0:
        for k in range(dim):
            normal[k] = normal[k] / dist
    else:
        for k in range(dim):
            normal[k] = _FALLBACK[k]
    return dist


@_jit
def _resolve(pos: Any, vel: Any, ima: Any, planes_n: Any, ca: Any, cb: Any, order: Any, e: float, stats: Any) -> int:
    """One pass of impulses, contact after contact in ``order``, each from the current
    velocities; returns how many were applied."""
    dim = pos.shape[1]
    normal = np.empty(dim)
    applied = 0
    for t in range(order.shape[0]):
        c = order[t]
        a = ca[c]
        b = cb[c]
        if b >= 0:
            inv_sum = ima[a] + ima[b]
            if inv_sum == 0.0:
                continue
            _pair_normal(pos, a, b, normal)
            vn = 0.0
            for k in range(dim):
                vn += (vel[b, k] - vel[a, k]) * normal[k]
            if vn < 0.0:
                j = -(1.0 + e) * vn / inv_sum
                ja = j * ima[a]
                jb = j * ima[b]
                for k in range(dim):
                    vel[a, k] = vel[a, k] - normal[k] * ja
                    vel[b, k] = vel[b, k] + normal[k] * jb
                stats[0] += 1
                applied += 1
        else:
            if ima[a] == 0.0:
                continue
            w = -1 - b
            vn = 0.0
            for k in range(dim):
                vn += vel[a, k] * planes_n[w, k]
            if vn < 0.0:
                f = (1.0 + e) * vn
                for k in range(dim):
                    vel[a, k] = vel[a, k] - planes_n[w, k] * f
                stats[1] += 1
                applied += 1
    return applied


@_jit
def _clamp(pos: Any, rad: Any, planes_n: Any, planes_c: Any, i: int) -> None:
    """Put body i back inside every wall, a gap ``CONTACT_SLOP`` clear of it."""
    dim = pos.shape[1]
    for w in range(planes_n.shape[0]):
        side = 0.0
        for k in range(dim):
            side += planes_n[w, k] * pos[i, k]
        side -= planes_c[w]
        if side <= rad[i]:
            shift = rad[i] - side + _SLOP
            for k in range(dim):
                pos[i, k] = pos[i, k] + planes_n[w, k] * shift


@_jit
def _push_apart(pos: Any, rad: Any, ima: Any, planes_n: Any, planes_c: Any, ca: Any, cb: Any, order: Any) -> int:
    """One pass of positional correction in ``order``, from current positions (a pair pushed
    earlier in the pass is measured again): a pair overlapping by ``d >= 0`` moves apart by
    ``d + CONTACT_SLOP`` in inverse proportion to mass, a ball touching a wall moves out to
    ``CONTACT_SLOP`` clear of it. Returns how many moves were made."""
    dim = pos.shape[1]
    normal = np.empty(dim)
    moves = 0
    for t in range(order.shape[0]):
        c = order[t]
        a = ca[c]
        b = cb[c]
        if b < 0:
            if ima[a] == 0.0:
                continue
            w = -1 - b
            side = 0.0
            for k in range(dim):
                side += planes_n[w, k] * pos[a, k]
            side -= planes_c[w]
            if side <= rad[a]:
                shift = rad[a] - side + _SLOP
                for k in range(dim):
                    pos[a, k] = pos[a, k] + planes_n[w, k] * shift
                moves += 1
            continue
        inv_sum = ima[a] + ima[b]
        if inv_sum == 0.0:
            continue
        dist = _pair_normal(pos, a, b, normal)
        depth = rad[a] + rad[b] - dist
        if depth < 0.0:
            continue
        shift = depth + _SLOP
        sa = shift * ima[a] / inv_sum
        sb = shift * ima[b] / inv_sum
        for k in range(dim):
            pos[a, k] = pos[a, k] - normal[k] * sa
            pos[b, k] = pos[b, k] + normal[k] * sb
        moves += 1
    return moves


@_jit
def _clamp_touched(
    pos: Any,
    rad: Any,
    ima: Any,
    planes_n: Any,
    planes_c: Any,
    ca: Any,
    cb: Any,
    order: Any,
    mark: Any,
    stamp: int,
) -> None:
    """Every body touched by a contact (once, marked by ``stamp``) put back inside every wall, so
    no body ends a step outside them whatever the pushes did."""
    for t in range(order.shape[0]):
        c = order[t]
        for body in (ca[c], cb[c]):
            if body >= 0 and ima[body] > 0.0 and mark[body] != stamp:
                mark[body] = stamp
                _clamp(pos, rad, planes_n, planes_c, body)


@_jit
def _integrate(pos: Any, vel: Any, ima: Any, gravity: Any, dt: float) -> None:
    """Forward Euler, position first: ``x += v dt`` then ``v += g dt`` (static bodies keep v)."""
    n, dim = pos.shape
    for i in range(n):
        for k in range(dim):
            pos[i, k] = pos[i, k] + vel[i, k] * dt
        if ima[i] > 0.0:
            for k in range(dim):
                vel[i, k] = vel[i, k] + gravity[k] * dt


@_jit
def run_steps(
    pos: Any,
    vel: Any,
    rad: Any,
    ima: Any,
    ids: Any,
    pos2: Any,
    vel2: Any,
    rad2: Any,
    ima2: Any,
    ids2: Any,
    cell_start: Any,
    dest: Any,
    mark: Any,
    stencil: Any,
    planes_n: Any,
    planes_c: Any,
    gravity: Any,
    dt: float,
    e: float,
    min_cell: float,
    steps: int,
    passes: int,
    first_stamp: int,
    ca: Any,
    cb: Any,
    cd: Any,
    stats: Any,
) -> Any:
    """Advance ``steps`` steps in place (state re-sorted by cell each step; ``ids`` follows the
    bodies). Impulses and push-apart each sweep the contacts up to ``passes`` times, stopping at
    a sweep that changes nothing. The ``*2`` arrays are scratch space of the same shapes. ``stats`` accumulates
    ``[body impulses, wall impulses]``. Returns the contact buffers, grown if they had to be."""
    max_cells = cell_start.shape[0] - 2
    lo = np.empty(3)
    shape = np.empty(3, np.int64)
    swapped = False
    for step in range(steps):
        _integrate(pos, vel, ima, gravity, dt)
        h = _grid_geometry(pos, min_cell, max_cells, lo, shape)
        _counting_sort(pos, lo, h, shape, cell_start, dest)
        _scatter_rows(pos, pos2, dest)
        _scatter_rows(vel, vel2, dest)
        _scatter(rad, rad2, dest)
        _scatter(ima, ima2, dest)
        _scatter(ids, ids2, dest)
        pos, pos2 = pos2, pos
        vel, vel2 = vel2, vel
        rad, rad2 = rad2, rad
        ima, ima2 = ima2, ima
        ids, ids2 = ids2, ids
        swapped = not swapped
        count = _find_contacts(pos, rad, planes_n, planes_c, lo, h, shape, cell_start, stencil, ca, cb, cd, _MARGIN)
        if count > ca.shape[0]:
            ca = np.empty(2 * count, np.int64)
            cb = np.empty(2 * count, np.int64)
            cd = np.empty(2 * count)
            _find_contacts(pos, rad, planes_n, planes_c, lo, h, shape, cell_start, stencil, ca, cb, cd, _MARGIN)
        if count == 0:
            continue
        order = _order_contacts(pos, ca, cb, cd, count)
        for _ in range(passes):
            if _resolve(pos, vel, ima, planes_n, ca, cb, order, e, stats) == 0:
                break
        for _ in range(passes):
            if _push_apart(pos, rad, ima, planes_n, planes_c, ca, cb, order) == 0:
                break
        _clamp_touched(pos, rad, ima, planes_n, planes_c, ca, cb, order, mark, first_stamp + step)
    if swapped:  # the current state is in the caller's scratch arrays: copy it home
        pos2[:, :] = pos
        vel2[:, :] = vel
        rad2[:] = rad
        ima2[:] = ima
        ids2[:] = ids
    return ca, cb, cd


@_jit
def find_pairs(pos: Any, rad: Any, stencil: Any, min_cell: float, max_cells: int) -> Any:
    """Every pair ``(i, j)``, ``i < j`` in input order, with ``|x_j - x_i| <= r_i + r_j`` (unsorted)."""
    n, dim = pos.shape
    lo = np.empty(3)
    shape = np.empty(3, np.int64)
    h = _grid_geometry(pos, min_cell, max_cells, lo, shape)
    cell_start = np.empty(max_cells + 2, np.int64)
    dest = np.empty(n, np.int64)
    _counting_sort(pos, lo, h, shape, cell_start, dest)
    spos = np.empty_like(pos)
    srad = np.empty_like(rad)
    ids = np.empty(n, np.int64)
    _scatter_rows(pos, spos, dest)
    _scatter(rad, srad, dest)
    for i in range(n):
        ids[dest[i]] = i
    no_planes_n = np.empty((0, dim))
    no_planes_c = np.empty(0)
    ca = np.empty(max(16, n), np.int64)
    cb = np.empty(max(16, n), np.int64)
    cd = np.empty(max(16, n))
    count = _find_contacts(spos, srad, no_planes_n, no_planes_c, lo, h, shape, cell_start, stencil, ca, cb, cd, 0.0)
    if count > ca.shape[0]:
        ca = np.empty(count, np.int64)
        cb = np.empty(count, np.int64)
        cd = np.empty(count)
        _find_contacts(spos, srad, no_planes_n, no_planes_c, lo, h, shape, cell_start, stencil, ca, cb, cd, 0.0)
    pairs = np.empty((count, 2), np.int64)
    for t in range(count):
        a = ids[ca[t]]
        b = ids[cb[t]]
        pairs[t, 0] = min(a, b)
        pairs[t, 1] = max(a, b)
    return pairs
