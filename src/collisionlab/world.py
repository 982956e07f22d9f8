"""The stateful simulation: :class:`World` and :func:`simulate` (they live in
:mod:`collisionlab.engine.world`; this module keeps the short import path)."""

from __future__ import annotations

from .engine.exact_kernels import MAX_IMPACTS_PER_STEP, RELAX_IMPULSES
from .engine.world import InitialOverlapError, World, simulate

__all__ = ["MAX_IMPACTS_PER_STEP", "RELAX_IMPULSES", "InitialOverlapError", "World", "simulate"]
