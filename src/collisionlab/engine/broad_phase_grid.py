"""The broad phase's uniform grid (phase 2 of :mod:`.step_kernels`; the exact stepper's candidates
too): cells as wide as the bodies they hold (plus ``contact_margin``), all but the widest
``n // LARGE_SHARE``, which meet the cells their boxes cover instead (:func:`_grid_width`,
:func:`_grid_plan`); bodies sorted into cells by a counting sort and stored in cell order
(:func:`_counting_sort`, :func:`_store_in_cell_order`), or, for a grid of more cells than its
budget, hashed into buckets (:func:`_bucket_sort`; Ericson, *Real-Time Collision Detection*,
7.1-7.1.3).

Owns ``LARGE_SHARE``, ``BUCKETS_PER_BODY``, ``AXIS_CELLS``, the cell keys and the hash's
multipliers. It imports no other file of the engine; it must not import the pairs' search
(:mod:`.broad_phase_pairs`), which reads its cells.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["AXIS_CELLS", "BUCKETS_PER_BODY", "LARGE_SHARE"]

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

#: Helpers the compiled form inlines into their callers (:mod:`.compiled`): they take arrays, and a
#: call that passes several numba arrays (each a struct of seven fields) costs more than the work inside.
INLINE = ("_cell_of", "_body_width", "_wider", "_bucket")


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
    # The kernels' one sort: numba compiles each of np.sort and np.argsort, for each dtype, apart.
    rank = np.argsort(widths)
    return float(widths[rank[n - 1 - min(n // LARGE_SHARE, n - 1)]])


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
