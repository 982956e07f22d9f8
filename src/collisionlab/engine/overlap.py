"""Bodies that overlap at the start, found in NumPy before any kernel is compiled.

The search is the kernels' uniform grid (``broad_phase_grid.AXIS_CELLS`` and its cell keys):
all but the widest bodies are binned in cells as wide as the widest of them and meet the bodies
in their own and the neighbouring cells; the few wide ones meet, by a sweep along x, the bodies
whose extent meets theirs. Bodies spread out cost about ``n log n`` (the sorts). Candidate pairs
are formed and measured a chunk at a time
(memory stays bounded); a search asked only whether anything overlaps stops at the first chunk
that holds an overlap, so even a thousand bodies at one point are refused at once.

Depths are the narrow phase's (:mod:`.geometry_kernels`): two balls and two boxes are measured
as arrays, a ball and a box by the scalar kernel (few such pairs touch).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidInputError
from ..model import Scenario
from ..tolerances import CONTACT_SLOP
from . import broad_phase_grid as bg
from . import pair_separation as ps
from .state import BodyArrays, StaticArrays, bodies_of, static_names, statics_of
from .stepper import stencil

__all__ = ["InitialOverlapError", "Overlaps", "find_overlaps", "overlap_message", "refuse_overlaps"]

#: Candidate pairs measured at once: large enough that NumPy's per-call cost is lost in the work,
#: small enough that the arrays of one chunk (a few tens of bytes a pair) stay a few megabytes.
_CHUNK_PAIRS = 1 << 16

#: A grid cell's key: its coordinates (each below ``AXIS_CELLS``) packed as the kernels' keys.
_KEY_SCALE = np.array([1, bg._KEY_Y, bg._KEY_Z], np.int64)

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


class InitialOverlapError(InvalidInputError):
    """Two bodies (or a body and an obstacle) overlap at the start; :attr:`pair` names the two
    that overlap deepest (when the refusal was made by :func:`refuse_overlaps`)."""

    pair: tuple[str, str] = ("", "")


@dataclass
class Overlaps:
    """What :func:`find_overlaps` found: ``count`` pairs deeper than the slop, the deepest of them
    ``pair`` (ids, a static as ``-1 - s``) by ``depth`` metres, and whether every pair was looked
    at (``complete``; else ``count`` is a lower bound)."""

    count: int = 0
    pair: tuple[int, int] = (0, 0)
    depth: float = 0.0
    complete: bool = True

    def add(self, a: IntArray, b: IntArray, depths: FloatArray, slop: float) -> None:
        """Count the pairs ``(a, b)`` deeper than ``slop``; keep the deepest."""
        deep = depths > slop
        if not np.any(deep):
            return
        self.count += int(np.count_nonzero(deep))
        worst = int(np.argmax(depths))
        if depths[worst] > self.depth:
            self.depth = float(depths[worst])
            self.pair = (int(a[worst]), int(b[worst]))


def overlap_message(found: Overlaps, name_a: str, name_b: str) -> str:
    """The refusal of :class:`InitialOverlapError` for ``found`` (named ``name_a``, ``name_b``)."""
    others = found.count - 1
    s = "s" if others > 1 else ""
    if not found.complete:
        more = f" (and at least {others} more pair{s})" if others else ""
    else:
        more = f" (and {others} more pair{s})" if others else ""
    return (
        f"'{name_a}' and '{name_b}' overlap by {found.depth:.6g} m at the start{more}; move them apart, "
        "or set allow_initial_overlap = true to have the first step push them apart"
    )


def find_overlaps(bodies: BodyArrays, statics: StaticArrays, dims: int, slop: float, every: bool) -> Overlaps:
    """The pairs of ``bodies`` (and of a body and one of ``statics``) that overlap by more than
    ``slop`` now. ``every``: count them all (for the warning of an overlap allowed); else stop at
    the first chunk of candidates that holds one (for a refusal)."""
    found = Overlaps()
    _static_overlaps(bodies, statics, slop, found)
    if found.count and not every:
        found.complete = False
        return found
    _body_overlaps(bodies, dims, slop, every, found)
    return found


def refuse_overlaps(scenario: Scenario, slop: float = CONTACT_SLOP) -> None:
    """Raise :class:`InitialOverlapError` if ``scenario``'s bodies overlap by more than ``slop``
    and it does not allow it: what :class:`~.world.World` checks, for a caller (reading a file)
    that wants the refusal before a world is built."""
    if scenario.allow_initial_overlap:
        return
    found = find_overlaps(bodies_of(scenario), statics_of(scenario), scenario.dims, slop, every=False)
    if found.count:
        a, b = found.pair
        bodies = scenario.bodies.names()
        name_a = static_names(scenario)[-1 - a] if a < 0 else bodies[a]
        error = InitialOverlapError("body", overlap_message(found, name_a, bodies[b]))
        error.pair = (name_a, bodies[b])
        raise error


def _static_overlaps(bodies: BodyArrays, statics: StaticArrays, slop: float, found: Overlaps) -> None:
    """Each static against every body: the kernel's cheap reject as arrays, then the depth of
    what is left by the scalar kernel (the bodies touching a static)."""
    pos, ext = bodies.pos, bodies.ext
    for s in range(statics.m):
        a, b = statics.a[s], statics.b[s]
        if statics.kind[s] == ps.STATIC_BOX:
            near = np.all((pos + ext >= a) & (pos - ext <= b), axis=1)
        else:  # a line, plane or one-sided wall: the centre's side against the body's reach
            side = (pos - a) @ b
            reach = ext @ np.abs(b)
            near = (np.abs(side) if statics.kind[s] == ps.STATIC_BOUNDARY else side) <= reach
        rows = np.flatnonzero(near)
        depths = np.array(
            [
                -ps._static_separation(statics.kind, statics.a, statics.b, s, bodies.kind, pos, ext, int(i))[0]
                for i in rows
            ],
            dtype=np.float64,
        )
        found.add(np.full(rows.shape[0], -1 - s, np.int64), bodies.ids[rows], depths, slop)


def _body_overlaps(bodies: BodyArrays, dims: int, slop: float, every: bool, found: Overlaps) -> None:
    """Every pair of bodies: the grid's (the module's docstring), then the wide bodies against
    the bodies whose extent along x meets theirs, then the wide ones among themselves."""
    n = bodies.n
    if n < 2:
        return
    ext = bodies.ext[:, :dims]
    widths = 2.0 * ext.max(axis=1)
    # As the kernels' grid: all but the widest n // LARGE_SHARE bodies are at most ``width`` wide.
    width = float(np.sort(widths)[n - 1 - min(n // bg.LARGE_SHARE, n - 1)])
    small = np.flatnonzero(widths <= width)
    large = np.flatnonzero(widths > width)
    # Two bodies at most ``slop`` wide cannot overlap by more than ``slop``: no grid is needed.
    if width > slop and not _grid_pairs(bodies, dims, small, width, slop, every, found):
        return
    if large.size == 0:
        return
    pos = bodies.pos
    by_x = small[np.argsort(pos[small, 0] - ext[small, 0], kind="stable")]
    lo_x = pos[by_x, 0] - ext[by_x, 0]
    # A small body meeting a wide one begins at most ``width`` before it along x.
    first = np.searchsorted(lo_x, pos[large, 0] - ext[large, 0] - width, side="left")
    last = np.searchsorted(lo_x, pos[large, 0] + ext[large, 0], side="right")
    if not _range_pairs(bodies, dims, large, by_x, first, last - first, slop, every, found):
        return
    k = np.arange(large.size)
    _range_pairs(bodies, dims, large, large, k + 1, large.size - k - 1, slop, every, found)


def _grid_pairs(
    bodies: BodyArrays, dims: int, rows: IntArray, width: float, slop: float, every: bool, found: Overlaps
) -> bool:
    """The pairs of the bodies ``rows`` (each at most ``width`` wide) in the same or neighbouring
    cells of a grid of cells ``width`` wide; False when the search is to stop."""
    pos = bodies.pos[rows, :dims]
    low = pos.min(axis=0)
    h = width
    # As the kernels' grid: cells are widened while an axis would have too many for its key.
    while float((pos.max(axis=0) - low).max()) / h >= bg.AXIS_CELLS - 2:
        h *= 2.0
    cells = np.zeros((rows.size, 3), np.int64)
    cells[:, :dims] = np.floor((pos - low) / h).astype(np.int64) + 1  # + 1: a neighbour's is >= 0
    keys = cells @ _KEY_SCALE
    order = np.argsort(keys, kind="stable")
    keys = keys[order]
    sorted_rows = rows[order]
    cell_keys, cell_first, cell_count = np.unique(keys, return_index=True, return_counts=True)
    place = np.arange(rows.size)
    for offset in stencil(dims):
        if not offset.any():  # its own cell: the bodies after it there
            own = np.searchsorted(cell_keys, keys)
            first = place + 1
            count = cell_first[own] + cell_count[own] - first
        else:
            wanted = keys + int(offset @ _KEY_SCALE)
            at = np.minimum(np.searchsorted(cell_keys, wanted), cell_keys.size - 1)
            there = cell_keys[at] == wanted
            first = np.where(there, cell_first[at], 0)
            count = np.where(there, cell_count[at], 0)
        if not _range_pairs(bodies, dims, sorted_rows, sorted_rows, first, count, slop, every, found):
            return False
    return True


def _range_pairs(
    bodies: BodyArrays,
    dims: int,
    owners: IntArray,
    partners: IntArray,
    first: IntArray,
    count: IntArray,
    slop: float,
    every: bool,
    found: Overlaps,
) -> bool:
    """The pairs of each ``owners[k]`` with ``partners[first[k] : first[k] + count[k]]``, measured
    about ``_CHUNK_PAIRS`` at a time; False (and ``found`` incomplete) when an overlap was found
    and ``every`` is not asked."""
    count = np.maximum(count, 0)
    before = np.concatenate(([0], np.cumsum(count)))
    lo = bodies.pos - bodies.ext
    hi = bodies.pos + bodies.ext
    start, n = 0, owners.size
    while start < n:
        # Owners start .. stop - 1: about _CHUNK_PAIRS candidates (at least one owner's).
        stop = max(int(np.searchsorted(before, before[start] + _CHUNK_PAIRS, side="right")) - 1, start + 1)
        total = int(before[stop] - before[start])
        if total:
            k = np.repeat(np.arange(start, stop), count[start:stop])
            shift = np.repeat(first[start:stop] - (before[start:stop] - before[start]), count[start:stop])
            a, b = owners[k], partners[shift + np.arange(total)]
            # Only pairs whose bounding boxes overlap on every axis are measured.
            meet = np.all((lo[a, :dims] <= hi[b, :dims]) & (lo[b, :dims] <= hi[a, :dims]), axis=1)
            a, b = a[meet], b[meet]
            _measure(bodies, dims, np.minimum(a, b), np.maximum(a, b), slop, found)
        start = stop
        if found.count and not every:
            found.complete = False
            return False
    return True


def _measure(bodies: BodyArrays, dims: int, a: IntArray, b: IntArray, slop: float, found: Overlaps) -> None:
    """The depths of the pairs of rows ``(a, b)``, added to ``found`` under the bodies' ids."""
    kind, pos, ext = bodies.kind, bodies.pos, bodies.ext
    ball_a, ball_b = kind[a] <= ps.BALL_3D, kind[b] <= ps.BALL_3D
    balls = ball_a & ball_b
    boxes = ~ball_a & ~ball_b
    mixed = ~balls & ~boxes
    for rows, depths in (
        (balls, _ball_depths(pos, ext, a[balls], b[balls])),
        (boxes, _box_depths(pos, ext, dims, a[boxes], b[boxes])),
        (
            mixed,
            np.array(
                [
                    -ps._body_separation(kind, pos, ext, int(p), int(q))[0]
                    for p, q in zip(a[mixed], b[mixed], strict=True)
                ]
            ),
        ),
    ):
        found.add(bodies.ids[a[rows]], bodies.ids[b[rows]], depths.astype(np.float64), slop)


def _ball_depths(pos: FloatArray, ext: FloatArray, a: IntArray, b: IntArray) -> FloatArray:
    """How far balls ``a`` and ``b`` overlap: the sum of the radii less the centres' distance."""
    depths: FloatArray = ext[a, 0] + ext[b, 0] - np.linalg.norm(pos[b] - pos[a], axis=1)
    return depths


def _box_depths(pos: FloatArray, ext: FloatArray, dims: int, a: IntArray, b: IntArray) -> FloatArray:
    """How far boxes ``a`` and ``b`` overlap: the least overlap over the axes (the narrow phase's
    depth, ``separation_box_box``)."""
    gaps = np.abs(pos[b, :dims] - pos[a, :dims]) - ext[a, :dims] - ext[b, :dims]
    depths: FloatArray = -gaps.max(axis=1)
    return depths
