"""The engine: one world that owns its state in arrays and steps it two ways.

* :mod:`.geometry_kernels` - the narrow phase and the contact law as scalar kernels, written
  once: the scalar API calls them as Python, the steppers compiled.
* :mod:`.params` - :class:`WorldParams`, every tunable of a world in one typed object.
* :mod:`.state` - the structure of arrays a world steps, built from a scenario.
* :mod:`.step_kernels` - the Forward Euler stepper over arrays (grid broad phase, contacts in
  a geometric order, sequential impulses, push-apart, events).
* :mod:`.compiled` - the same kernels compiled by numba, for large worlds.
* :mod:`.world` - :class:`World`: steps, runs, and records what happened.
"""

from __future__ import annotations

from .params import WorldParams

__all__ = ["WorldParams"]
