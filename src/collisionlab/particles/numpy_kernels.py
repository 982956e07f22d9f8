"""The particle world's step in plain numpy: the path that works without numba.

It computes the same thing as :mod:`collisionlab.particles.kernels` with the same floating-point
operations in the same order (so the two agree bit for bit), vectorised instead of looped:

* the grid is a stable argsort of cell numbers instead of a counting sort, and the state is not
  re-sorted in memory;
* the sequential pass over contacts is cut into *levels*: a contact's level is one more than the
  highest level of any earlier contact sharing a body with it. Contacts of one level share no
  body, so applying a level at once gives exactly the sequential result.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..tolerances import CONTACT_SLOP, FALLBACK_NORMAL, SOLVER_MARGIN

__all__ = ["find_contacts", "find_pairs", "grid_geometry", "order_contacts", "run_steps"]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


def grid_geometry(pos: FloatArray, min_cell: float, max_cells: int) -> tuple[FloatArray, float, IntArray]:
    """``(lo, h, shape)`` exactly as ``kernels._grid_geometry`` computes them."""
    dim = pos.shape[1]
    lo = np.zeros(3)
    hi = np.zeros(3)
    lo[:dim] = pos.min(axis=0)
    hi[:dim] = pos.max(axis=0)
    h = min_cell
    while True:
        cells = 1.0
        for k in range(dim):
            cells *= math.floor((hi[k] - lo[k]) / h) + 1.0
        if cells <= max_cells:
            break
        h *= 1.5
    shape = np.ones(3, np.int64)
    for k in range(dim):
        shape[k] = int((hi[k] - lo[k]) / h) + 1
    return lo, h, shape


def _dot_rows(a: FloatArray, b: FloatArray) -> FloatArray:
    """Row-wise dot product summed left to right, as the compiled loops do (no pairwise sum)."""
    total = a[:, 0] * b[:, 0]
    for k in range(1, a.shape[1]):
        total = total + a[:, k] * b[:, k]
    return total


def _lex_less(p: FloatArray, q: FloatArray) -> NDArray[np.bool_]:
    """Row-wise: is ``p`` lexicographically before ``q``?"""
    less = np.zeros(p.shape[0], bool)
    equal = np.ones(p.shape[0], bool)
    for k in range(p.shape[1]):
        less |= equal & (p[:, k] < q[:, k])
        equal &= p[:, k] == q[:, k]
    return less


def _candidate_pairs(pos: FloatArray, min_cell: float, max_cells: int, stencil: IntArray) -> tuple[IntArray, IntArray]:
    """Pairs of bodies in the same or half-stencil neighbouring cells (each unordered pair once)."""
    n, dim = pos.shape
    lo, h, shape = grid_geometry(pos, min_cell, max_cells)
    coords = np.zeros((n, 3), np.int64)
    coords[:, :dim] = ((pos - lo[:dim]) / h).astype(np.int64)
    cell = coords[:, 0] + shape[0] * (coords[:, 1] + shape[1] * coords[:, 2])
    order = np.argsort(cell, kind="stable")
    start = np.zeros(int(shape.prod()) + 1, np.int64)
    np.cumsum(np.bincount(cell, minlength=start.shape[0] - 1), out=start[1:])
    sorted_coords = coords[order]
    firsts: list[IntArray] = []
    seconds: list[IntArray] = []
    slots = np.arange(n, dtype=np.int64)
    for s in range(stencil.shape[0]):
        near = sorted_coords + stencil[s]
        inside = np.all((near >= 0) & (near < shape), axis=1)
        near_cell = near[:, 0] + shape[0] * (near[:, 1] + shape[1] * near[:, 2])
        near_cell[~inside] = 0
        begin = slots + 1 if s == 0 else start[near_cell]
        end = start[near_cell + 1]
        counts = np.where(inside, np.maximum(end - begin, 0), 0)
        total = int(counts.sum())
        if total == 0:
            continue
        first = np.repeat(slots, counts)
        offsets = np.arange(total, dtype=np.int64) - np.repeat(np.cumsum(counts) - counts, counts)
        second = np.repeat(begin, counts) + offsets
        firsts.append(order[first])
        seconds.append(order[second])
    if not firsts:
        empty = np.empty(0, np.int64)
        return empty, empty
    return np.concatenate(firsts), np.concatenate(seconds)


def find_contacts(
    pos: FloatArray,
    rad: FloatArray,
    planes_n: FloatArray,
    planes_c: FloatArray,
    min_cell: float,
    max_cells: int,
    stencil: IntArray,
    margin: float = SOLVER_MARGIN,
) -> tuple[IntArray, IntArray, FloatArray]:
    """``(a, b, depth)`` of every contact, as ``kernels._find_contacts`` records them."""
    i, j = _candidate_pairs(pos, min_cell, max_cells, stencil)
    delta = pos[j] - pos[i]
    dist = np.sqrt(_dot_rows(delta, delta))
    reach = rad[i] + rad[j]
    hit = dist <= reach + margin
    i, j, dist, reach = i[hit], j[hit], dist[hit], reach[hit]
    j_first = _lex_less(pos[j], pos[i])
    a = np.where(j_first, j, i)
    b = np.where(j_first, i, j)
    cas = [a]
    cbs = [b]
    cds = [reach - dist]
    for w in range(planes_n.shape[0]):
        side = _dot_rows(pos, np.broadcast_to(planes_n[w], pos.shape)) - planes_c[w]
        touching = np.flatnonzero(side <= rad + margin)
        cas.append(touching.astype(np.int64))
        cbs.append(np.full(touching.shape[0], -1 - w, np.int64))
        cds.append(rad[touching] - side[touching])
    return np.concatenate(cas), np.concatenate(cbs), np.concatenate(cds)


def order_contacts(pos: FloatArray, ca: IntArray, cb: IntArray, cd: FloatArray) -> IntArray:
    """Deepest first; ties by first body's position, body pairs before walls, then the second
    body's position or the lower wall number (``kernels._order_contacts``)."""
    dim = pos.shape[1]
    is_wall = cb < 0
    second = np.where(is_wall, 0, cb)
    second_pos = np.where(is_wall[:, None], 0.0, pos[second])
    wall_number = np.where(is_wall, -1 - cb, 0)
    keys = [wall_number]
    keys += [second_pos[:, k] for k in reversed(range(dim))]
    keys.append(is_wall.astype(np.int64))
    keys += [pos[ca, k] for k in reversed(range(dim))]
    keys.append(-cd)
    return np.lexsort(keys).astype(np.int64)


def _levels(ca: IntArray, cb: IntArray, order: IntArray) -> IntArray:
    """Level of each contact in ``order`` (see the module docstring)."""
    last: dict[int, int] = {}
    levels = []
    for a, b in zip(ca[order].tolist(), cb[order].tolist(), strict=True):
        level = last.get(a, 0)
        if b >= 0:
            level = max(level, last.get(b, 0))
        level += 1
        last[a] = level
        if b >= 0:
            last[b] = level
        levels.append(level)
    return np.asarray(levels, np.int64)


def _pair_normals(pos: FloatArray, a: IntArray, b: IntArray) -> tuple[FloatArray, FloatArray]:
    delta = pos[b] - pos[a]
    dist = np.sqrt(_dot_rows(delta, delta))
    coincident = dist == 0.0
    normal = delta / np.where(coincident, 1.0, dist)[:, None]
    normal[coincident] = np.asarray(FALLBACK_NORMAL[: pos.shape[1]])
    return normal, dist


def _resolve_level(
    pos: FloatArray, vel: FloatArray, ima: FloatArray, planes_n: FloatArray, a: IntArray, b: IntArray, e: float
) -> tuple[int, int]:
    pair = b >= 0
    pa, pb = a[pair], b[pair]
    inv_sum = ima[pa] + ima[pb]
    movable = inv_sum != 0.0
    pa, pb, inv_sum = pa[movable], pb[movable], inv_sum[movable]
    normal, _ = _pair_normals(pos, pa, pb)
    vn = _dot_rows(vel[pb] - vel[pa], normal)
    hit = vn < 0.0
    pa, pb, inv_sum, normal, vn = pa[hit], pb[hit], inv_sum[hit], normal[hit], vn[hit]
    j = -(1.0 + e) * vn / inv_sum
    vel[pa] = vel[pa] - normal * (j * ima[pa])[:, None]
    vel[pb] = vel[pb] + normal * (j * ima[pb])[:, None]
    wa = a[~pair]
    walls = -1 - b[~pair]
    keep = ima[wa] != 0.0
    wa, walls = wa[keep], walls[keep]
    wn = planes_n[walls]
    vnw = _dot_rows(vel[wa], wn)
    bounce = vnw < 0.0
    wa, wn, vnw = wa[bounce], wn[bounce], vnw[bounce]
    vel[wa] = vel[wa] - wn * ((1.0 + e) * vnw)[:, None]
    return int(hit.sum()), int(bounce.sum())


def _push_level(
    pos: FloatArray,
    rad: FloatArray,
    ima: FloatArray,
    planes_n: FloatArray,
    planes_c: FloatArray,
    a: IntArray,
    b: IntArray,
) -> int:
    pair = b >= 0
    pa, pb = a[pair], b[pair]
    inv_sum = ima[pa] + ima[pb]
    movable = inv_sum != 0.0
    pa, pb, inv_sum = pa[movable], pb[movable], inv_sum[movable]
    normal, dist = _pair_normals(pos, pa, pb)
    depth = rad[pa] + rad[pb] - dist
    over = depth >= 0.0
    pa, pb, inv_sum, normal = pa[over], pb[over], inv_sum[over], normal[over]
    shift = depth[over] + CONTACT_SLOP
    pos[pa] = pos[pa] - normal * (shift * ima[pa] / inv_sum)[:, None]
    pos[pb] = pos[pb] + normal * (shift * ima[pb] / inv_sum)[:, None]
    wa = a[~pair]
    walls = -1 - b[~pair]
    keep = ima[wa] != 0.0
    wa, walls = wa[keep], walls[keep]
    wn = planes_n[walls]
    side = _dot_rows(wn, pos[wa]) - planes_c[walls]
    inside = side <= rad[wa]
    wa, wn, side = wa[inside], wn[inside], side[inside]
    pos[wa] = pos[wa] + wn * (rad[wa] - side + CONTACT_SLOP)[:, None]
    return int(over.sum() + inside.sum())


def _clamp(pos: FloatArray, rad: FloatArray, planes_n: FloatArray, planes_c: FloatArray, bodies: IntArray) -> None:
    for w in range(planes_n.shape[0]):
        side = _dot_rows(pos[bodies], np.broadcast_to(planes_n[w], (bodies.shape[0], pos.shape[1]))) - planes_c[w]
        inside = side <= rad[bodies]
        moved = bodies[inside]
        shift = rad[moved] - side[inside] + CONTACT_SLOP
        pos[moved] = pos[moved] + planes_n[w] * shift[:, None]


def run_steps(
    pos: FloatArray,
    vel: FloatArray,
    rad: FloatArray,
    ima: FloatArray,
    stencil: IntArray,
    planes_n: FloatArray,
    planes_c: FloatArray,
    gravity: FloatArray,
    dt: float,
    e: float,
    min_cell: float,
    max_cells: int,
    steps: int,
    passes: int,
    stats: IntArray,
) -> None:
    """``steps`` steps in place, in the order of ``kernels.run_steps``."""
    finite = ima > 0.0
    for _ in range(steps):
        pos += vel * dt
        vel[finite] = vel[finite] + gravity * dt
        ca, cb, cd = find_contacts(pos, rad, planes_n, planes_c, min_cell, max_cells, stencil)
        if ca.shape[0] == 0:
            continue
        order = order_contacts(pos, ca, cb, cd)
        ca, cb = ca[order], cb[order]
        levels = _levels(ca, cb, np.arange(ca.shape[0]))
        groups = [np.flatnonzero(levels == level) for level in range(1, int(levels.max()) + 1)]
        for _ in range(passes):
            applied = 0
            for group in groups:
                body_hits, wall_hits = _resolve_level(pos, vel, ima, planes_n, ca[group], cb[group], e)
                stats[0] += body_hits
                stats[1] += wall_hits
                applied += body_hits + wall_hits
            if applied == 0:
                break
        for _ in range(passes):
            moves = sum(_push_level(pos, rad, ima, planes_n, planes_c, ca[group], cb[group]) for group in groups)
            if moves == 0:
                break
        touched = np.unique(np.concatenate([ca, cb[cb >= 0]]))
        _clamp(pos, rad, planes_n, planes_c, touched[ima[touched] > 0.0])


def find_pairs(pos: FloatArray, rad: FloatArray, stencil: IntArray, min_cell: float, max_cells: int) -> IntArray:
    """Every pair ``(i, j)``, ``i < j``, with ``|x_j - x_i| <= r_i + r_j`` (unsorted)."""
    i, j = _candidate_pairs(pos, min_cell, max_cells, stencil)
    delta = pos[j] - pos[i]
    hit = np.sqrt(_dot_rows(delta, delta)) <= rad[i] + rad[j]
    i, j = i[hit], j[hit]
    return np.stack([np.minimum(i, j), np.maximum(i, j)], axis=1).astype(np.int64)
