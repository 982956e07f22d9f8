"""What a run of the contact solver keeps between calls, and the one call that advances it.

:func:`~collisionlab.engine.contact_kernels.run_contact_steps` steps the state; this keeps what
it needs from step to step: the candidate pairs' order, the contact memory (each pair's last
impulse, for the warm start), who sleeps in which island, what the sleeping islands' supports
carry, each static's total impulse, and the event buffer.
"""

from __future__ import annotations

import math
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..tolerances import REST_SPEED
from . import contact_kernels, step_kernels
from .params import WorldParams
from .state import BodyArrays, StaticArrays
from .stepper import EventRows

__all__ = ["ContactStepper", "rest_speed"]


def rest_speed(gravity: NDArray[np.float64], dt: float, floor: float = REST_SPEED) -> float:
    """The one restitution threshold ``v_rest``: an approach slower than this is a resting
    contact (solved, e = 0, no event), a faster one an impact with e. It is the speed gravity
    gives in one step, ``|g| dt``, and never below ``floor`` (:data:`~collisionlab.tolerances.REST_SPEED`,
    which is all there is without gravity): a body resting on a support approaches it at up to
    ``|g| dt / 2`` within a step, and a bounce slower than ``|g| dt`` would rise less than a
    step of fall (``|g| dt^2 / 2``).

    >>> rest_speed(np.array([0.0, -10.0, 0.0]), 0.01)   # 10 m/s^2 for 0.01 s
    0.1
    >>> rest_speed(np.zeros(3), 0.01)
    0.001
    """
    return max(floor, math.sqrt(float(np.dot(gravity, gravity))) * dt)


class ContactStepper(EventRows):
    """Advances ``bodies`` among ``statics`` with the contact solver. The bodies stay in the order
    given. :attr:`ledger` holds ``step_kernels.LEDGER_SIZE`` running sums, :attr:`static_impulse`
    ``(m, 3)`` each static's impulse on the bodies so far, :attr:`status` the kernel's counters
    (``contact_kernels.STATUS_SIZE``)."""

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
        self._tau = np.zeros(n)
        self._acc = np.zeros((n, 3))
        self._asleep = np.zeros(n, np.int64)
        self._still = np.zeros(n)
        self._island = np.zeros(n, np.int64)
        self._parent = np.zeros(n, np.int64)
        self._order = np.arange(n, dtype=np.int64)
        self._lo = np.zeros(n)
        self._start = np.zeros(n + 1, np.int64)
        capacity = 4 * n + 16
        self._pairs = np.zeros((capacity, 2), np.int64)
        self._pf = np.zeros((capacity, contact_kernels.PAIR_COLUMNS))
        self._adj = np.zeros(2 * capacity, np.int64)
        self._contacts = np.zeros(capacity, np.int64)
        self._memory = np.zeros(0, np.int64)
        self._memory_lam = np.zeros(0)
        self._memory_count = np.zeros(1, np.int64)
        self._rows_i = np.zeros((16, 2), np.int64)
        self._rows_f = np.zeros((16, 3))
        self._row_count = np.zeros(1, np.int64)
        self.ledger = np.zeros(step_kernels.LEDGER_SIZE)
        self.static_impulse = np.zeros((statics.m, 3))
        self.status = np.zeros(contact_kernels.STATUS_SIZE, np.int64)

    def advance(self, kernels: ModuleType, dt: float, restitution: float, first_step: int, steps: int) -> None:
        """Run ``steps`` steps of ``dt`` from step number ``first_step`` with ``kernels``, the
        contact kernels' Python or compiled form. Resets the events first."""
        b, s, p = self.bodies, self.statics, self.params
        self._event_count[0] = 0
        self.release_events()
        (
            self._pairs, self._pf, self._adj, self._contacts, self._memory, self._memory_lam,
            self._rows_i, self._rows_f, self._events,
        ) = kernels.run_contact_steps(
            b.kind, b.pos, b.vel, b.ext, b.ima, b.eb, b.ids,
            s.kind, s.a, s.b, s.e, self.gravity, self.dims, dt, restitution,
            rest_speed(self.gravity, dt), p.slop, p.contact_margin, first_step, steps, self.record_events,
            self._tau, self._acc, self._asleep, self._still, self._island, self._parent, self._order, self._lo,
            self._start, self._pairs, self._pf, self._adj, self._contacts, self._memory, self._memory_lam,
            self._memory_count, self._rows_i, self._rows_f, self._row_count,
            self._events, self._event_count, self.ledger, self.static_impulse, self.status,
        )  # fmt: skip

    @property
    def asleep(self) -> int:
        """How many bodies sleep now."""
        return int(self._asleep.sum())

    def nbytes(self) -> int:
        """Bytes of every array held: state, statics, memory and buffers."""
        s = self.statics
        arrays: list[Any] = [s.kind, s.a, s.b, s.e, self.static_impulse, self.status, self.ledger, self._events]
        arrays += [self._tau, self._acc, self._asleep, self._still, self._island, self._parent, self._order]
        arrays += [self._lo, self._start, self._pairs, self._pf, self._adj, self._contacts, self._memory]
        arrays += [self._memory_lam, self._rows_i, self._rows_f]
        return self.bodies.nbytes() + sum(int(a.nbytes) for a in arrays)
