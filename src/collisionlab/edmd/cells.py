"""Cell lists and neighbour lists of the event-driven engine.

Each body keeps a list of the bodies whose list centres were within ``P_CUT`` (the shell, 1.4
to 2 diameters, see ``world.shell_for``; Smallenburg's ``1 + alpha``) of its own when its list
was last built, and an event to rebuild it when it has drifted ``P_SKIN = (P_CUT - sigma) / 2`` from its centre.
Two bodies not on each other's lists are then always more than ``P_CUT - 2 P_SKIN = sigma``
apart: they cannot collide, and only neighbours are ever tested.

Building one list looks through the 3^dim cells around the body's centre (cells at least
``P_CUT`` wide, each a doubly linked list of the bodies whose centre lies in it), so it costs
O(1) per body; the lists are kept symmetric (``j`` on ``i``'s list iff ``i`` on ``j``'s).
With periodic walls, distances are taken to the nearest image; the box is required to be at
least four diameters wide so that the nearest image is unique for every neighbour.
"""

from __future__ import annotations

from typing import Any

from .compile import jit, jit_inline
from .layout import CELL, CNEXT, CPREV, EDGE, NNB, P_CUT, P_INV_H, P_L, Q_DIM, Q_NC, Q_PERIODIC, C, X

__all__ = ["build_all_lists", "nearest_image", "rebuild_list"]


@jit_inline
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


@jit_inline
def _cell_of(F: Any, P: Any, Q: Any, i: int) -> int:
    cell = 0
    stride = 1
    for k in range(Q[Q_DIM]):
        nc = Q[Q_NC + k]
        c = int(F[i, C + k] * P[P_INV_H + k])
        if c < 0:
            c = 0
        elif c >= nc:
            c = nc - 1
        cell += c * stride
        stride *= nc
    return cell


@jit_inline
def _axis_cell(c: int, o: int, nc: int, periodic: bool) -> int:
    """Cell ``o - 1`` steps from ``c`` along an axis of ``nc`` cells, or -1 (outside, or a cell
    already visited when fewer than three wrap round)."""
    if periodic:
        if nc >= 3:
            return (c + o - 1 + nc) % nc
        return o if o < nc else -1
    c2 = c + o - 1
    return c2 if 0 <= c2 < nc else -1


@jit_inline
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


@jit_inline
def _put_in_cell(F: Any, IX: Any, P: Any, Q: Any, heads: Any, i: int) -> None:
    cell = _cell_of(F, P, Q, i)
    IX[i, EDGE] = _on_edge(P, Q, cell)
    head = heads[cell]
    IX[i, CELL] = cell
    IX[i, CNEXT] = head
    IX[i, CPREV] = -1
    if head >= 0:
        IX[head, CPREV] = i
    heads[cell] = i


@jit_inline
def _take_from_cell(IX: Any, heads: Any, i: int) -> None:
    prev = IX[i, CPREV]
    nxt = IX[i, CNEXT]
    if prev >= 0:
        IX[prev, CNEXT] = nxt
    else:
        heads[IX[i, CELL]] = nxt
    if nxt >= 0:
        IX[nxt, CPREV] = prev


@jit_inline
def _set_centre(F: Any, P: Any, Q: Any, i: int) -> None:
    """The body's list centre becomes its position, put back into the box first (periodic)."""
    for k in range(Q[Q_DIM]):
        x = F[i, X + k]
        if Q[Q_PERIODIC] != 0:
            side = P[P_L + k]
            if x >= side:
                x -= side
            elif x < 0.0:
                x += side
            F[i, X + k] = x
        F[i, C + k] = x


@jit
def _link_neighbours(F: Any, IX: Any, NB: Any, P: Any, Q: Any, heads: Any, i: int, later_only: bool) -> bool:
    """Put on ``i``'s list (and ``i`` on theirs) every body within the reach of its centre;
    ``later_only``: only bodies ``j > i`` (building every list at once). False if a list is full."""
    dim = Q[Q_DIM]
    periodic = Q[Q_PERIODIC] != 0
    cut2 = P[P_CUT] * P[P_CUT]
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
                if a0 < 0:
                    continue
                j = heads[a0 + nc0 * (a1 + nc1 * a2)]
                while j >= 0:
                    if j != i and (j > i or not later_only):
                        dx = xi - F[j, C]
                        dy = yi - F[j, C + 1]
                        dz = zi - F[j, C + 2]
                        if periodic:
                            dx = nearest_image(dx, P[P_L])
                            dy = nearest_image(dy, P[P_L + 1])
                            if dim == 3:
                                dz = nearest_image(dz, P[P_L + 2])
                        if dx * dx + dy * dy + dz * dz < cut2:
                            ni = IX[i, NNB]
                            nj = IX[j, NNB]
                            if ni >= cap or nj >= cap:
                                return False
                            NB[i, ni] = j
                            IX[i, NNB] = ni + 1
                            NB[j, nj] = i
                            IX[j, NNB] = nj + 1
                    j = IX[j, CNEXT]
    return True


@jit
def rebuild_list(F: Any, IX: Any, NB: Any, P: Any, Q: Any, heads: Any, i: int) -> bool:
    """New list for body ``i`` (already moved to the present) centred on where it is now.
    False if some list overflowed (the caller widens ``NB`` and builds every list again)."""
    for m in range(IX[i, NNB]):
        j = NB[i, m]
        last = IX[j, NNB] - 1
        for s in range(last + 1):
            if NB[j, s] == i:
                NB[j, s] = NB[j, last]
                IX[j, NNB] = last
                break
    IX[i, NNB] = 0
    _take_from_cell(IX, heads, i)
    _set_centre(F, P, Q, i)
    _put_in_cell(F, IX, P, Q, heads, i)
    return _link_neighbours(F, IX, NB, P, Q, heads, i, False)


@jit
def build_all_lists(F: Any, IX: Any, NB: Any, P: Any, Q: Any, heads: Any) -> bool:
    """Every cell and neighbour list from scratch, centred on the present positions (all bodies
    must hold at the same time). False if a list overflowed."""
    n = F.shape[0]
    for c in range(heads.shape[0]):
        heads[c] = -1
    for i in range(n):
        IX[i, NNB] = 0
        _set_centre(F, P, Q, i)
        _put_in_cell(F, IX, P, Q, heads, i)
    ok = True
    for i in range(n):
        ok = ok and _link_neighbours(F, IX, NB, P, Q, heads, i, True)
    return ok
