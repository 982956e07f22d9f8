"""Many bodies, fast: a particle world of balls in a box, with a grid broad phase.

:class:`ParticleWorld` holds N discs (2D) or spheres (3D) as arrays and steps them with the
scalar core's impulse law; :func:`grid_pairs` is its broad phase as a stateless query;
:func:`gas_scenario` builds the benchmark's gas. numba (a dependency; optional at run time)
makes it much faster (``bench/README.md`` has the figures); without it the same numbers come
from plain numpy.
"""

from __future__ import annotations

from .backend import BACKENDS, pick_backend
from .broadphase import brute_force_pairs, grid_pairs
from .maxwell import component_variance, speed_pdf
from .scenarios import GasScenario, gas_scenario
from .world import ParticleWorld, Progress, StepReport, warm_up

__all__ = [
    "BACKENDS",
    "GasScenario",
    "ParticleWorld",
    "Progress",
    "StepReport",
    "brute_force_pairs",
    "component_variance",
    "gas_scenario",
    "grid_pairs",
    "pick_backend",
    "speed_pdf",
    "warm_up",
]
