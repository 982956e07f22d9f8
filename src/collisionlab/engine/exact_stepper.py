"""What an exact run keeps between calls, and the one call that advances it.

The same state, scratch space and buffers as :class:`~collisionlab.engine.stepper.EulerStepper`
(so a world holds one or the other), stepped by
:func:`~collisionlab.engine.exact_kernels.run_exact_steps`: times of impact, earliest first.
"""

from __future__ import annotations

from types import ModuleType

import numpy as np
from numpy.typing import NDArray

from ..tolerances import TOI_GAP
from . import exact_kernels
from .params import WorldParams
from .state import BodyArrays, StaticArrays
from .stepper import EulerStepper

__all__ = ["ExactStepper"]


class ExactStepper(EulerStepper):
    """Advances ``bodies`` among ``statics`` exactly. :attr:`status` holds the kernel's
    counters (``exact_kernels.STATUS_SIZE``), summed over every call."""

    def __init__(
        self,
        bodies: BodyArrays,
        statics: StaticArrays,
        dims: int,
        gravity: NDArray[np.float64],
        params: WorldParams,
        record_events: bool = True,
    ) -> None:
        super().__init__(bodies, statics, dims, gravity, params, record_events)
        self.status = np.zeros(exact_kernels.STATUS_SIZE, np.int64)

    def advance(self, kernels: ModuleType, dt: float, restitution: float, first_step: int, steps: int) -> None:
        """Run ``steps`` exact steps of ``dt`` from step number ``first_step``, with ``kernels``
        the exact kernels' Python or compiled form. Resets the events first; :attr:`ledger` keeps
        the totals since the stepper was made."""
        b, s, p = self.bodies, self.statics, self.params
        self._event_count[0] = 0
        self.release_events()
        ca, cb, cd = self._contacts
        self._touch_keys, ca, cb, cd, self._events = kernels.run_exact_steps(
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
            self.min_cell,
            TOI_GAP,
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
            self.status,
        )
        self._contacts = (ca, cb, cd)
