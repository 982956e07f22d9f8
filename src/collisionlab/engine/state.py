"""The state a world steps: a structure of arrays, built from a scenario or from plain arrays.

Bodies (``n``): ``kind`` (ball 2D/3D, box 2D/3D), ``pos`` and ``vel`` ``(n, 3)`` (z = 0 in 2D),
``ext`` ``(n, 3)`` the half extents (a ball's radius on every axis, a box's half size, so that
``pos -+ ext`` is always the body's bounding box), ``ima`` the inverse mass (0: kinematic),
``eb`` the body's restitution override (NaN: none) and ``ids``, the order the bodies were given
(the steppers store bodies in cell order and carry ``ids`` along).

Statics (``m``): ``s_kind`` (a two-sided line or plane, a one-sided wall, a fixed box), ``s_a``
and ``s_b`` ``(m, 3)`` (a point and the unit normal, or the box's two corners) and ``s_e``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..model import Scenario
from . import pair_separation as ps
from .shape_rows import body_row, static_row

__all__ = ["BodyArrays", "StaticArrays", "bodies_of", "body_row", "static_names", "static_row", "statics_of"]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


@dataclass
class BodyArrays:
    kind: IntArray
    pos: FloatArray
    vel: FloatArray
    ext: FloatArray
    ima: FloatArray
    eb: FloatArray
    ids: IntArray

    @property
    def n(self) -> int:
        return int(self.pos.shape[0])

    def nbytes(self) -> int:
        return int(sum(a.nbytes for a in (self.kind, self.pos, self.vel, self.ext, self.ima, self.eb, self.ids)))


@dataclass
class StaticArrays:
    kind: IntArray
    a: FloatArray
    b: FloatArray
    e: FloatArray

    @property
    def m(self) -> int:
        return int(self.kind.shape[0])


def bodies_of(scenario: Scenario) -> BodyArrays:
    """The scenario's moving bodies as arrays, in the order given (a block's straight from its
    arrays: no :class:`~collisionlab.model.Body` is built)."""
    c = scenario.bodies.columns()  # fresh arrays: the world steps them in place
    return BodyArrays(c.kind, c.pos, c.vel, c.ext, c.ima, c.eb, np.arange(c.kind.shape[0], dtype=np.int64))


def statics_of(scenario: Scenario) -> StaticArrays:
    """The scenario's static obstacles as arrays, in the order given, then its box's walls
    (one-sided, the inside being the box) when it has walls."""
    obstacles = scenario.obstacles
    walls = scenario.box.walls() if scenario.box is not None and scenario.box.boundary == "walls" else []
    m = len(obstacles) + len(walls)
    kind = np.zeros(m, np.int64)
    a = np.zeros((m, 3))
    b = np.zeros((m, 3))
    e = np.full(m, math.nan)
    for s, obstacle in enumerate(obstacles):
        kind[s], a[s], b[s] = static_row(obstacle.shape)
        if obstacle.restitution is not None:
            e[s] = obstacle.restitution
    for w, (_, point, normal) in enumerate(walls):
        s = len(obstacles) + w
        kind[s], a[s], b[s] = ps.STATIC_WALL, point, normal
    return StaticArrays(kind, a, b, e)


def static_names(scenario: Scenario) -> list[str]:
    """The names of :func:`statics_of` 's rows: the obstacles', then the walls'."""
    walls = scenario.box.walls() if scenario.box is not None and scenario.box.boundary == "walls" else []
    return [o.name for o in scenario.obstacles] + [name for name, _, _ in walls]
