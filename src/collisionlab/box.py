"""A scenario's box: two corners and a boundary, hard walls on every face or periodic. Part of
:mod:`collisionlab.model` (which re-exports it); it knows nothing of bodies.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

from .errors import InvalidInputError
from .vector import Vector3D, as_vector

__all__ = ["BOUNDARIES", "Boundary", "Box"]

Boundary = Literal["walls", "periodic"]
#: A vector as a box's corners take it: a :class:`Vector3D`, or 2 or 3 numbers.
VectorLike = Vector3D | Sequence[float]
#: A box's boundary: hard walls, or periodic.
BOUNDARIES: tuple[Boundary, ...] = ("walls", "periodic")


@dataclass(frozen=True, init=False)
class Box:
    """The scenario's box, from corner ``low`` to corner ``high`` (2D when both have z = 0).
    ``"walls"``: a hard, one-sided wall on every face, the inside being the box (named
    ``wall x-``, ``wall x+``, ``wall y-``, ...); ``"periodic"``: a body leaving by one face comes
    back by the opposite one (the event-driven stepper only: balls, ``mode = "exact"``).

    >>> Box((0, 0), (10, 5)).walls()[:2]
    [('wall x-', (0.0, 0.0, 0.0), (1.0, 0.0, 0.0)), ('wall x+', (10.0, 5.0, 0.0), (-1.0, 0.0, 0.0))]
    >>> try:
    ...     Box((0, 0), (10, 0))              # no height
    ... except InvalidInputError as error:
    ...     print(error.field)
    box.region
    """

    low: Vector3D
    high: Vector3D
    boundary: Boundary = "walls"

    def __init__(self, low: VectorLike, high: VectorLike, boundary: Boundary = "walls") -> None:
        low = as_vector(low, "box.region")
        high = as_vector(high, "box.region")
        object.__setattr__(self, "low", low)
        object.__setattr__(self, "high", high)
        object.__setattr__(self, "boundary", boundary)
        if any(h <= lo for lo, h in list(zip(low, high, strict=True))[: self.dims]):
            raise InvalidInputError("box.region", "the second corner must be above the first on every axis", high)
        if self.boundary not in BOUNDARIES:
            raise InvalidInputError("box.boundary", f"must be one of {', '.join(BOUNDARIES)}", got=self.boundary)

    @property
    def dims(self) -> int:
        return 2 if self.low.z == 0.0 and self.high.z == 0.0 else 3

    @property
    def sides(self) -> tuple[float, ...]:
        return tuple(h - lo for lo, h in list(zip(self.low, self.high, strict=True))[: self.dims])

    def walls(self) -> list[tuple[str, tuple[float, float, float], tuple[float, float, float]]]:
        """Each face as ``(name, point, inward unit normal)``: ``x-``, ``x+``, ``y-``, ... in turn."""
        faces = []
        for k, axis in enumerate("xyz"[: self.dims]):
            unit = tuple(1.0 if j == k else 0.0 for j in range(3))
            faces.append((f"wall {axis}-", self.low.as_tuple(), unit))
            faces.append((f"wall {axis}+", self.high.as_tuple(), tuple(-c + 0.0 for c in unit)))
        return faces  # type: ignore[return-value]
