"""What a Forward Euler run keeps between calls, and the one call that advances it.

Both fronts of the engine, :class:`~collisionlab.engine.world.World` (scenarios) and
:class:`~collisionlab.particles.ParticleWorld` (gases), step through an :class:`EulerStepper`:
the state arrays, the grid's scratch space, the pairs in contact (carried from step to step so an
impact is reported once), and buffers the kernel grows when it must.
"""

from __future__ import annotations

from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import event_rows, step_kernels
from .params import WorldParams
from .state import BodyArrays, StaticArrays

__all__ = ["CELLS_PER_BODY", "EulerStepper", "EventRows", "max_cells", "near_pairs", "stencil"]

#: Rows of the event buffer kept between calls; a larger one (after a burst) is let go.
_EVENT_ROWS_KEPT = 4096

#: Grid cells per body at most (plus a constant); beyond it the cells are widened. At an area
#: fraction of 0.2 a one-diameter grid needs about 4 cells per disc, so 6 leaves room.
CELLS_PER_BODY = 6


def stencil(dims: int) -> NDArray[np.int64]:
    """Cell offsets of a cell and the half of its neighbours after it in (z, y, x) order, so that
    every unordered pair of neighbouring cells is visited once (Ericson 7.1.2).

    >>> stencil(2).tolist()
    [[0, 0, 0], [1, 0, 0], [-1, 1, 0], [0, 1, 0], [1, 1, 0]]
    >>> len(stencil(3))
    14
    """
    rows = [(0, 0, 0)]
    span = (-1, 0, 1)
    for dz in span if dims == 3 else (0,):
        for dy in span:
            for dx in span:
                if (dz, dy, dx) > (0, 0, 0):
                    rows.append((dx, dy, dz))
    return np.asarray(rows, np.int64)


def max_cells(n: int) -> int:
    """The grid's cell budget for ``n`` bodies."""
    return CELLS_PER_BODY * n + 64


class EventRows:
    """The event buffer a stepper's kernel fills (``event_rows.EVENT_COLUMNS`` columns, grown
    by the kernel in a burst) and its count, read by the world after each call."""

    def __init__(self) -> None:
        self._events = np.zeros((16, event_rows.EVENT_COLUMNS))
        self._event_count = np.zeros(2, np.int64)

    def events(self) -> NDArray[np.float64]:
        """The event rows of the last :meth:`advance` (``event_rows.EVENT_COLUMNS`` columns)."""
        return self._events[: int(self._event_count[0])]

    def release_events(self) -> None:
        """Let go of an event buffer grown by a burst (the rows have been read)."""
        if self._events.shape[0] > _EVENT_ROWS_KEPT:
            self._events = np.zeros((16, event_rows.EVENT_COLUMNS))


class EulerStepper(EventRows):
    """Advances ``bodies`` among ``statics`` with :func:`~collisionlab.engine.step_kernels.run_steps`.

    ``gravity`` has three components (z = 0 in 2D). The ledger of the last call is
    :attr:`ledger` (``step_kernels.LEDGER_SIZE`` sums); its events are :meth:`events`.
    """

    def __init__(
        self,
        bodies: BodyArrays,
        statics: StaticArrays,
        dims: int,
        gravity: NDArray[np.float64],
        params: WorldParams,
        record_events: bool = True,
    ) -> None:
        super().__init__()
        n = bodies.n
        self.bodies, self.statics, self.dims, self.params = bodies, statics, dims, params
        self.gravity = np.asarray(gravity, np.float64)
        self.record_events = record_events
        self.stencil = stencil(dims)
        self.min_cell = 2.0 * float(bodies.ext[:, :dims].max()) + params.contact_margin
        self.max_cells = max_cells(n)
        self._scratch_f = np.zeros((n, 11))
        self._scratch_i = np.zeros((n, 2), np.int64)
        self._cell_start = np.zeros(self.max_cells + 2, np.int64)
        self._dest = np.zeros(n, np.int64)
        self._touch_keys = np.zeros(16, np.int64)
        self._touch_count = np.zeros(1, np.int64)
        capacity = max(16, n // 4)  # contacts: grown by the kernel when a step has more
        self._contacts = (np.zeros(capacity, np.int64), np.zeros(capacity, np.int64), np.zeros(capacity))
        self.ledger = np.zeros(step_kernels.LEDGER_SIZE)

    def advance(self, kernels: ModuleType, dt: float, restitution: float, first_step: int, steps: int) -> None:
        """Run ``steps`` steps of ``dt`` from step number ``first_step``, with ``kernels`` the
        step kernels' Python or compiled form. Resets the events first; :attr:`ledger` keeps the
        totals since the stepper was made (one running sum whatever the chunks: bit-reproducible)."""
        b, s, p = self.bodies, self.statics, self.params
        self._event_count[0] = 0
        self.release_events()
        ca, cb, cd = self._contacts
        self._touch_keys, ca, cb, cd, self._events = kernels.run_steps(
            b.kind,
            b.pos,
            b.vel,
            b.ext,
            b.ima,
            b.eb,
            b.ids,
            self._scratch_f,
            self._scratch_i,
            self._cell_start,
            self._dest,
            self.stencil,
            s.kind,
            s.a,
            s.b,
            s.e,
            self.gravity,
            self.dims,
            dt,
            restitution,
            p.slop,
            p.solver_margin,
            p.contact_margin,
            p.rest_speed if self.gravity.any() else 0.0,  # without gravity nothing rests
            p.passes,
            p.settle_passes,
            first_step,
            steps,
            self.record_events,
            self._touch_keys,
            self._touch_count,
            ca,
            cb,
            cd,
            self._events,
            self._event_count,
            self.ledger,
        )
        self._contacts = (ca, cb, cd)

    def nbytes(self) -> int:
        """Bytes of every array held: state, statics, scratch and buffers."""
        s = self.statics
        arrays: list[Any] = [s.kind, s.a, s.b, s.e, self._scratch_f, self._scratch_i, self._cell_start, self._dest]
        arrays += [self._touch_keys, *self._contacts, self._events, self.ledger]
        return self.bodies.nbytes() + sum(int(a.nbytes) for a in arrays)


def near_pairs(
    kernels: ModuleType, bodies: BodyArrays, statics: StaticArrays, dims: int, params: WorldParams, margin: float
) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Pairs of ``bodies`` (and ``statics``) closer than ``margin`` now, as rows ``(A, B)`` of ids
    (a static is ``-1 - s``), and their depths; ``kernels`` the step kernels' Python or compiled
    form. The state is not changed (the grid works on sorted copies)."""
    min_cell = 2.0 * float(bodies.ext[:, :dims].max()) + params.contact_margin
    b, s = bodies, statics
    pairs, depths = kernels.find_near(
        b.kind, b.pos, b.ext, b.ids, s.kind, s.a, s.b, stencil(dims), dims, min_cell, max_cells(b.n), margin
    )
    return np.asarray(pairs, np.int64), np.asarray(depths, np.float64)
