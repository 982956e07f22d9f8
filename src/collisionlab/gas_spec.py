"""What a scenario file's ``[[gas]]`` table says, validated: :class:`GasSpec`.

Its own file, below both of its readers: :mod:`collisionlab.body_block` keeps the spec of the
table that placed a block (a scenario file writes it back) and :mod:`collisionlab.gas_table`
places the bodies it describes, which are a block. Imports nothing from collisionlab.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["GasSpec"]


@dataclass(frozen=True)
class GasSpec:
    """A validated ``[[gas]]`` table. ``half`` is the half extent per axis (the radius, three
    times, for a ball); ``region`` two corners (low, high); ``velocity`` is used when ``kT`` is
    ``None``."""

    name: str
    shape: str
    half: tuple[float, float, float]
    region: tuple[tuple[float, float, float], tuple[float, float, float]]
    count: int
    mass: float
    kT: float | None
    velocity: tuple[float, float, float] | None
    restitution: float | None
    seed: int

    @property
    def dims(self) -> int:
        return 2 if self.shape == "circle" or (self.shape == "aabb" and self.half[2] == 0.0) else 3
