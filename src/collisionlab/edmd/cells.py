"""Cell lists and neighbour lists of the event-driven engine.

Each body keeps a list of the bodies whose list centres were within ``P_CUT`` (the shell, 1.4
to 2 diameters, see ``tuning.shell_for``; Smallenburg's ``1 + alpha``) of its own when its list
was last built, and an event to rebuild it when it has drifted ``P_SKIN = (P_CUT - sigma) / 2`` from its centre.
Two bodies not on each other's lists are then always more than ``P_CUT - 2 P_SKIN = sigma``
apart: they cannot collide, and only neighbours are ever tested. In a mixture each body's skin
is ``P_CUT / 2 - r_i``: two bodies off each other's lists stay ``r_i + r_j`` apart, whatever
their sizes (``P_CUT`` exceeds the largest contact distance, the sum of the two largest radii).

Building one list looks through the 3^dim cells around the body's centre (cells at least
``P_CUT`` wide), so it costs O(1) per body; the lists are kept symmetric (``j`` on ``i``'s list
iff ``i`` on ``j``'s). With periodic walls, distances are taken to the nearest image; the box is
required to be at least four diameters wide so that the nearest image is unique for every
neighbour.

A cell is one row of ``CI`` (int32, shape ``(cells, slots, 4)``): slot 0 holds the number of
bodies in it, slots ``1 .. count`` one body each, its list centre as three float32 (read through
``CF``, a float32 view of the same memory) and its index. Looking through a cell thus reads a
few consecutive bytes, not one row of ``F`` per body, and no chain of links (with a million
bodies each of those was a cache miss, one after the other). The float32 centres are rounded,
by less than a margin (``P_REACH - P_CUT``): a distance within the margin of ``P_CUT`` is taken
again from the float64 centres of ``F``, so a list holds exactly the bodies within ``P_CUT``.
"""

from __future__ import annotations

from typing import Any

from .compile import flag, jit, jit_call, jit_inline, prefetch
from .layout import CELL, EDGE, NNB, P_CUT, P_INV_H, P_L, P_REACH, Q_DIM, Q_NC, Q_PERIODIC, C, X

__all__ = ["CELL_FULL", "LIST_FULL", "build_all_lists", "fetch_cells", "nearest_image", "rebuild_list"]

#: Status of a (re)build: a neighbour list is full (the caller widens ``NB``), a cell is full
#: (the caller widens ``CI``); both then build every list again. 0: done.
LIST_FULL = 3
CELL_FULL = 4
#: The slot that begins a cell's second cache line (slots of 16 bytes in rows of 64-byte lines).
_SECOND_LINE = 4


@jit_call
def nearest_image(d: float, side: float) -> float:
    """``d`` shifted by a box side into ``[-side/2, side/2]`` (for ``|d| < 3/2 side``).

    >>> nearest_image(9.0, 10.0), nearest_image(-6.0, 10.0), nearest_image(2.0, 10.0)
    (-1.0, 4.0, 2.0)
    """
    if d > 0.5 * side:
        return d - side
    if d < -0.5 * side:
        return d + side
    return d


@jit_call
def _axis_of(x: float, inv_h: float, nc: int) -> int:
    c = int(x * inv_h)
    if c < 0:
        return 0
    if c >= nc:
        return nc - 1
    return c


@jit_call
def _cell_of(F: Any, P: Any, Q: Any, i: int) -> int:
    cell = 0
    stride = 1
    for k in range(Q[Q_DIM]):
        nc = Q[Q_NC + k]
        cell += _axis_of(F[i, C + k], P[P_INV_H + k], nc) * stride
        stride *= nc
    return cell


@jit_call
def _axis_cell(c: int, o: int, nc: int, periodic: bool) -> int:
    """Cell ``o - 1`` steps from ``c`` along an axis of ``nc`` cells, or -1 (outside, or a cell
    already visited when fewer than three wrap round)."""
    if periodic:
        if nc >= 3:
            c2 = c + o - 1
            if c2 < 0:
                return c2 + nc
            if c2 >= nc:
                return c2 - nc
            return c2
        return o if o < nc else -1
    c2 = c + o - 1
    return c2 if 0 <= c2 < nc else -1


@jit_call
def _on_edge(P: Any, Q: Any, cell: int) -> int:
    """1 if ``cell`` lies on a face of a periodic box (its neighbours may be across it)."""
    if Q[Q_PERIODIC] == 0:
        return 0
    rest = cell
    for k in range(Q[Q_DIM]):
        nc = Q[Q_NC + k]
        c = rest % nc
        rest //= nc
        if c == 0 or c == nc - 1:
            return 1
    return 0


@jit_call
def _put_in_cell(F: Any, IX: Any, P: Any, Q: Any, CI: Any, CF: Any, i: int) -> bool:
    """Body ``i`` into the cell of its centre (False if that cell is full)."""
    cell = _cell_of(F, P, Q, i)
    count = CI[cell, 0, 0] + 1
    if count >= CI.shape[1]:
        return False
    CI[cell, 0, 0] = count
    CF[cell, count, 0] = F[i, C]
    CF[cell, count, 1] = F[i, C + 1]
    CF[cell, count, 2] = F[i, C + 2]
    CI[cell, count, 3] = i
    IX[i, CELL] = cell
    IX[i, EDGE] = _on_edge(P, Q, cell)
    return True


@jit_call
def _take_from_cell(IX: Any, CI: Any, i: int) -> None:
    """Body ``i`` out of its cell: the cell's last body takes its slot."""
    cell = IX[i, CELL]
    last = CI[cell, 0, 0]
    for s in range(1, last + 1):
        if CI[cell, s, 3] == i:
            for k in range(4):
                CI[cell, s, k] = CI[cell, last, k]
            break
    CI[cell, 0, 0] = last - 1


@jit_call
def _into_box(x: float, side: float) -> float:
    if x >= side:
        return x - side
    if x < 0.0:
        return x + side
    return x


@jit_call
def _set_centre(F: Any, P: Any, Q: Any, i: int) -> None:
    """The body's list centre becomes its position, put back into the box first (periodic)."""
    for k in range(Q[Q_DIM]):
        x = F[i, X + k]
        if Q[Q_PERIODIC] != 0:
            x = _into_box(x, P[P_L + k])
            F[i, X + k] = x
        F[i, C + k] = x


@jit_inline
def fetch_cells(P: Any, Q: Any, CI: Any, x: float, y: float, z: float) -> None:
    """Prefetch the first two lines of each cell around the point ``(x, y, z)`` (its count and
    first 7 bodies): where a body about to rebuild its list will look (see ``loop._fetch_ahead``,
    and :func:`_link_neighbours` itself, which asks for all the cells before it reads the first:
    their misses then run side by side instead of one after another, a count at a time)."""
    periodic = Q[Q_PERIODIC] != 0
    nc0 = Q[Q_NC]
    nc1 = Q[Q_NC + 1]
    nc2 = Q[Q_NC + 2]
    if periodic:
        x = _into_box(x, P[P_L])
        y = _into_box(y, P[P_L + 1])
        z = _into_box(z, P[P_L + 2])
    c0 = _axis_of(x, P[P_INV_H], nc0)
    c1 = _axis_of(y, P[P_INV_H + 1], nc1)
    c2 = _axis_of(z, P[P_INV_H + 2], nc2)
    for o2 in range(3):
        a2 = _axis_cell(c2, o2, nc2, periodic)
        if a2 < 0:
            continue
        for o1 in range(3):
            a1 = _axis_cell(c1, o1, nc1, periodic)
            if a1 < 0:
                continue
            for o0 in range(3):
                a0 = _axis_cell(c0, o0, nc0, periodic)
                if a0 >= 0:
                    cell = CI[a0 + nc0 * (a1 + nc1 * a2)]
                    prefetch(cell, 0, 0)
                    prefetch(cell, _SECOND_LINE, 0)


@jit_call
def _faces(x: float, c: int, inv_h: float, nc: int, periodic: bool) -> tuple[float, float]:
    """The squared distances from ``x`` (in cell ``c`` of ``nc`` along an axis of cell side
    ``1 / inv_h``) to the cells below and above it; ``(0, 0)`` where fewer than three cells wrap
    round (the cells looked through are then not those below and above) or the axis has none
    (``inv_h`` 0: a 2D world's z).

    >>> _faces(2.5, 1, 0.5, 5, False)   # cells [0, 2), [2, 4), [4, 6): 0.5 to the one below, 1.5 above
    (0.25, 2.25)
    >>> _faces(2.5, 1, 0.5, 2, True), _faces(0.0, 0, 0.0, 1, False)
    ((0.0, 0.0), (0.0, 0.0))
    """
    if inv_h <= 0.0 or (periodic and nc < 3):
        return 0.0, 0.0
    low = max(x - c / inv_h, 0.0)
    high = max((c + 1) / inv_h - x, 0.0)
    return low * low, high * high


@jit_call
def _exact_distance2(F: Any, P: Any, wrap: bool, dim: int, i: int, j: int) -> float:
    """The squared distance of ``i``'s and ``j``'s list centres, from ``F`` (float64)."""
    dx: float = F[i, C] - F[j, C]
    dy: float = F[i, C + 1] - F[j, C + 1]
    dz: float = F[i, C + 2] - F[j, C + 2]
    if wrap:
        dx = nearest_image(dx, P[P_L])
        dy = nearest_image(dy, P[P_L + 1])
        if dim == 3:
            dz = nearest_image(dz, P[P_L + 2])
    return dx * dx + dy * dy + dz * dz


@jit
def _link_neighbours(F: Any, IX: Any, NB: Any, P: Any, Q: Any, CI: Any, CF: Any, i: int, later_only: bool) -> int:
    """Put on ``i``'s list (and ``i`` on theirs) every body within the reach of its centre;
    ``later_only``: only bodies ``j > i`` (building every list at once). 0, or ``LIST_FULL``."""
    dim = Q[Q_DIM]
    wrap = Q[Q_PERIODIC] != 0 and IX[i, EDGE] != 0
    periodic = Q[Q_PERIODIC] != 0
    reach2 = P[P_REACH] * P[P_REACH]
    cut2 = P[P_CUT] * P[P_CUT]
    band = 2.0 * P[P_CUT] - P[P_REACH]
    band2 = band * band
    cap = NB.shape[1]
    nc0 = Q[Q_NC]
    nc1 = Q[Q_NC + 1]
    nc2 = Q[Q_NC + 2]
    cell = IX[i, CELL]
    c0 = cell % nc0
    c1 = (cell // nc0) % nc1
    c2 = cell // (nc0 * nc1)
    xi = F[i, C]
    yi = F[i, C + 1]
    zi = F[i, C + 2]
    lx = P[P_L]
    ly = P[P_L + 1]
    lz = P[P_L + 2]
    first = i if later_only else -1
    start = IX[i, NNB]
    fetch_cells(P, Q, CI, xi, yi, zi)
    # How far the centre is from the cells below and above its own along each axis, squared: a
    # neighbouring cell no nearer than the reach holds no neighbour, and is not looked through
    # (about a quarter of the 27 cells, those across an edge or a corner; the list is the same)
    low0, high0 = _faces(xi, c0, P[P_INV_H], nc0, periodic)
    low1, high1 = _faces(yi, c1, P[P_INV_H + 1], nc1, periodic)
    low2, high2 = _faces(zi, c2, P[P_INV_H + 2], nc2, periodic)
    n = start
    for o2 in range(3):
        a2 = _axis_cell(c2, o2, nc2, periodic)
        if a2 < 0:
            continue
        e2 = low2 if o2 == 0 else (high2 if o2 == 2 else 0.0)
        for o1 in range(3):
            a1 = _axis_cell(c1, o1, nc1, periodic)
            if a1 < 0:
                continue
            e1 = e2 + (low1 if o1 == 0 else (high1 if o1 == 2 else 0.0))
            if e1 >= reach2:
                continue
            for o0 in range(3):
                a0 = _axis_cell(c0, o0, nc0, periodic)
                if a0 < 0 or e1 + (low0 if o0 == 0 else (high0 if o0 == 2 else 0.0)) >= reach2:
                    continue
                other = a0 + nc0 * (a1 + nc1 * a2)
                for s in range(1, CI[other, 0, 0] + 1):
                    j = CI[other, s, 3]
                    dx = xi - float(CF[other, s, 0])
                    dy = yi - float(CF[other, s, 1])
                    dz = zi - float(CF[other, s, 2])
                    if wrap:
                        dx = nearest_image(dx, lx)
                        dy = nearest_image(dy, ly)
                        if dim == 3:
                            dz = nearest_image(dz, lz)
                    d2 = dx * dx + dy * dy + dz * dz
                    if band2 < d2 < reach2:  # too close to the reach to tell from the rounded centres
                        d2 = _exact_distance2(F, P, wrap, dim, i, j)
                        if d2 >= cut2:
                            d2 = reach2
                    inside = (d2 < reach2) & (j > first) & (j != i)
                    # written whether or not it is a neighbour (no branch to mispredict), kept if so
                    if n < cap:
                        NB[i, n] = j
                        n += int(inside)
                    elif inside:
                        return LIST_FULL
    IX[i, NNB] = n
    for m in range(start, n):
        j = NB[i, m]
        nj = IX[j, NNB]
        if nj >= cap:
            return LIST_FULL
        NB[j, nj] = i
        IX[j, NNB] = nj + 1
    return 0


@jit
def rebuild_list(F: Any, IX: Any, NB: Any, P: Any, Q: Any, CI: Any, CF: Any, i: int) -> int:
    """New list for body ``i`` (already moved to the present) centred on where it is now.
    0, or ``LIST_FULL`` / ``CELL_FULL`` (the caller widens ``NB`` or ``CI`` and builds every
    list again)."""
    for m in range(IX[i, NNB]):
        j = NB[i, m]
        last = IX[j, NNB] - 1
        for s in range(last + 1):
            if NB[j, s] == i:
                NB[j, s] = NB[j, last]
                IX[j, NNB] = last
                break
    IX[i, NNB] = 0
    _take_from_cell(IX, CI, i)
    _set_centre(F, P, Q, i)
    if not _put_in_cell(F, IX, P, Q, CI, CF, i):
        return CELL_FULL
    return _link_neighbours(F, IX, NB, P, Q, CI, CF, i, flag(False))


@jit
def build_all_lists(F: Any, IX: Any, NB: Any, P: Any, Q: Any, CI: Any, CF: Any) -> int:
    """Every cell and neighbour list from scratch, centred on the present positions (all bodies
    must hold at the same time). 0, or ``LIST_FULL`` / ``CELL_FULL``."""
    n = F.shape[0]
    for c in range(CI.shape[0]):
        CI[c, 0, 0] = 0
    for i in range(n):
        IX[i, NNB] = 0
        _set_centre(F, P, Q, i)
        if not _put_in_cell(F, IX, P, Q, CI, CF, i):
            return CELL_FULL
    for i in range(n):
        status = _link_neighbours(F, IX, NB, P, Q, CI, CF, i, flag(True))
        if status != 0:
            return status
    return 0
