"""The candidate pairs and their separations (phases 2 and 3 of :mod:`.step_kernels`; the exact
stepper's candidates too): each cell of the grid of :mod:`.broad_phase_grid` meets itself and half
its neighbours, each of the larger bodies meets the cells its box covers and the other larger
bodies, statics meet every body (:func:`_static_bounds_meet`); each candidate's separation
(:mod:`.pair_separation`) is kept if nearer than ``contact_margin`` (:func:`_find_pairs`).

It imports :mod:`.pair_separation` and :mod:`.broad_phase_grid`; it must not import the order,
the impulses, the push-apart or any stepper's loop.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..tolerances import BROADPHASE_WIDEN

if "_BROAD_PHASE_GRID" in globals():  # the compiled copy: the kernels it calls are compiled too
    bg: Any = globals()["_BROAD_PHASE_GRID"]
    ps: Any = globals()["_PAIR_SEPARATION"]
else:
    from . import broad_phase_grid as bg
    from . import pair_separation as ps

__all__: list[str] = []  # helpers of the steppers' loops: nothing here is public

_WIDEN = 1.0 + BROADPHASE_WIDEN

#: Helpers the compiled form inlines into their callers (:mod:`.compiled`): they take arrays, and a
#: call that passes several numba arrays (each a struct of seven fields) costs more than the work inside.
INLINE = ("_static_bounds_meet",)


def _static_bounds_meet(s_kind: Any, s_a: Any, s_b: Any, s: int, pos: Any, ext: Any, b: int, margin: float) -> bool:
    """A cheap test that body ``b`` may be within ``margin`` of static ``s``: bounding boxes for a
    fixed box; for a line, plane or wall the centre's distance against the body's projected
    radius ``sum_k |u_k| e_k`` (Ericson 5.2.3), which is its reach along the normal."""
    if s_kind[s] == ps.STATIC_BOX:
        for k in range(3):
            if pos[b, k] + ext[b, k] + margin < s_a[s, k] or pos[b, k] - ext[b, k] - margin > s_b[s, k]:
                return False
        return True
    side = 0.0
    reach = 0.0
    for k in range(3):
        side += s_b[s, k] * (pos[b, k] - s_a[s, k])
        reach += abs(s_b[s, k]) * ext[b, k]
    if s_kind[s] == ps.STATIC_BOUNDARY:
        side = abs(side)
    return bool(side <= reach + margin)


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
    """Every pair closer than ``margin`` (a static and a body: ``static_margin``), on the grid of
    :func:`_grid_plan` and :func:`_bucket_sort`; returns how many (which may exceed the buffers'
    capacity: the caller grows them and asks again), ``cd`` the depth (minus the separation). The
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
            key_a = xa + bg._KEY_Y * y2 + bg._KEY_Z * z2
            c = bg._bucket(xa, y2, z2, nx, ny, buckets)
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
        ball = kind[i] <= ps.BALL_3D
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
                if ball and kind[j] <= ps.BALL_3D:
                    apart = ex + ext[j, 0] + pair_margin
                    if dx * dx + dy * dy + dz * dz > apart * apart * _WIDEN:
                        continue
                a = i
                b = j
                if ids[i] >= ids[j]:  # the body given first is A
                    a = j
                    b = i
                sep = ps._pair_sep(
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
            if s_kind[s] != ps.STATIC_BOX:  # a line, plane or wall: the centre's side, written out
                side = (
                    s_b[s, 0] * (pos[i, 0] - s_a[s, 0])
                    + s_b[s, 1] * (pos[i, 1] - s_a[s, 1])
                    + s_b[s, 2] * (pos[i, 2] - s_a[s, 2])
                )
                reach = abs(s_b[s, 0]) * ext[i, 0] + abs(s_b[s, 1]) * ext[i, 1] + abs(s_b[s, 2]) * ext[i, 2]
                if (abs(side) if s_kind[s] == ps.STATIC_BOUNDARY else side) > reach + static_margin:
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
            sep = ps._static_sep(
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
