"""Many bodies as arrays: a :class:`BodyBlock` (what a ``[[gas]]`` table or ``collisionlab gas``
places) and :class:`Bodies`, the sequence of a scenario's bodies.

A gas of a million balls is a million rows of numbers, not a million :class:`Body` objects: a
block holds its positions and velocities as arrays and builds a ``Body`` only when one is read
(``block[i]``, iteration). :class:`Bodies` chains single bodies and blocks into one
``Sequence[Body]`` in the order they were given, and hands the engine its arrays directly
(:meth:`Bodies.columns`), so nothing per body is built to run a gas.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from .body import Body
from .built_sequence import BuiltSequence
from .errors import InvalidInputError
from .gas_spec import GasSpec
from .shapes import AABB, Circle, Sphere
from .validate import non_negative, positive, positive_or_inf, printable
from .vector import Vector3D

__all__ = ["BLOCK_SHAPES", "Bodies", "BodyBlock", "BodyColumns"]

FloatArray = NDArray[np.float64]
#: The shapes a block's bodies can have.
BLOCK_SHAPES: tuple[str, ...] = ("circle", "sphere", "aabb")
BlockShape = Literal["circle", "sphere", "aabb"]


def _rows(value: object, field: str, n: int | None) -> FloatArray:
    """``value`` as a read-only ``(n, 3)`` float array: rows of 2 numbers get z = 0."""
    try:
        array = np.array(value, dtype=np.float64, ndmin=2)
    except (TypeError, ValueError, OverflowError):
        raise InvalidInputError(field, "must be rows of 2 or 3 numbers") from None
    if array.ndim != 2 or array.shape[1] not in (2, 3) or (n is not None and array.shape[0] != n):
        rows = "n" if n is None else str(n)
        raise InvalidInputError(field, f"must be {rows} rows of 2 or 3 numbers", got=array.shape)
    if not np.all(np.isfinite(array)):
        raise InvalidInputError(field, "must be finite numbers (no NaN or inf)")
    if array.shape[1] == 2:
        array = np.column_stack((array, np.zeros(array.shape[0])))
    array = np.ascontiguousarray(array + 0.0)  # no signed zeros, as Vector3D
    array.flags.writeable = False
    return array


@dataclass(frozen=True, eq=False)
class BodyBlock(BuiltSequence[Body]):
    """``len(positions)`` bodies of one ``shape`` (``"circle"``, ``"sphere"`` or ``"aabb"``), all
    of half extent ``half`` (a ball's radius three times; a box's half size, z = 0 for a 2D box),
    one ``mass`` and restitution override; body ``i`` is named ``f"{name}{i}"``.

    ``positions`` (the centres) and ``velocities`` are ``(n, 2)`` or ``(n, 3)`` arrays, kept as
    read-only ``(n, 3)`` copies. A circle or a 2D box lives in the x-y plane (z must be 0), as a
    single :class:`Body` does.

    >>> block = BodyBlock("ball", "circle", (0.5, 0.5, 0.5), [[0, 0], [2, 0]], [[1, 0], [-1, 0]])
    >>> len(block), block[1].name, block[1].shape.center, block.dims
    (2, 'ball1', Vector3D(x=2.0, y=0.0, z=0.0), 2)
    >>> BodyBlock("ball", "sphere", (0.5, 0.5, 0.5), [[0, 0, 0]], [[0, 0, 0]], mass=-1)
    Traceback (most recent call last):
    ...
    collisionlab.errors.InvalidInputError: mass: must be > 0 (math.inf for a static body) (got -1)
    """

    name: str
    shape: BlockShape
    half: tuple[float, float, float]
    positions: FloatArray
    velocities: FloatArray
    mass: float = 1.0
    restitution: float | None = None
    #: The ``[[gas]]`` table that placed these bodies, if one did (a scenario file writes it back).
    spec: GasSpec | None = None

    def __post_init__(self) -> None:
        printable(self.name, "name")
        if self.shape not in BLOCK_SHAPES:
            raise InvalidInputError("shape", f"must be one of {', '.join(BLOCK_SHAPES)}", got=self.shape)
        half = tuple(float(h) for h in self.half)
        if len(half) != 3:
            raise InvalidInputError("half", "must be three half extents", got=self.half)
        if self.shape == "aabb":
            flat = half[2] == 0.0
            for h in half[: 2 if flat else 3]:
                positive(h, "size")
        else:
            half = (positive(half[0], "radius"),) * 3
        object.__setattr__(self, "half", half)
        positions = _rows(self.positions, "positions", None)
        velocities = _rows(self.velocities, "velocities", positions.shape[0])
        if self.dims == 2 and (np.any(positions[:, 2] != 0.0) or np.any(velocities[:, 2] != 0.0)):
            raise InvalidInputError("velocities", "a circle or a 2D box moves in the x-y plane: z must be 0")
        object.__setattr__(self, "positions", positions)
        object.__setattr__(self, "velocities", velocities)
        object.__setattr__(self, "mass", positive_or_inf(self.mass, "mass"))
        if self.restitution is not None:
            object.__setattr__(self, "restitution", non_negative(self.restitution, "restitution"))

    @property
    def dims(self) -> int:
        """2 for circles and 2D boxes (no extent in z), else 3."""
        return 2 if self.shape == "circle" or (self.shape == "aabb" and self.half[2] == 0.0) else 3

    def __len__(self) -> int:
        return int(self.positions.shape[0])

    def _item(self, i: int) -> Body:
        centre = Vector3D(*self.positions[i].tolist())
        shape: Circle | Sphere | AABB
        if self.shape == "circle":
            shape = Circle(centre, self.half[0])
        elif self.shape == "sphere":
            shape = Sphere(centre, self.half[0])
        else:
            half = Vector3D(*self.half)
            shape = AABB(centre - half, centre + half)
        return Body(f"{self.name}{i}", shape, Vector3D(*self.velocities[i].tolist()), self.mass, self.restitution)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, BodyBlock):
            return NotImplemented
        return (
            (self.name, self.shape, self.half, self.mass, self.restitution)
            == (other.name, other.shape, other.half, other.mass, other.restitution)
            and np.array_equal(self.positions, other.positions)
            and np.array_equal(self.velocities, other.velocities)
        )

    __hash__ = None  # type: ignore[assignment]  # holds arrays: equal by value, not hashable

    def __repr__(self) -> str:
        return f"BodyBlock({self.name!r}, {self.shape!r}, {len(self):,} bodies)"

    def names_clash(self, name: str) -> bool:
        """Whether one of this block's bodies is called ``name`` (``name`` is the block's name
        and a body's number, written without leading zeros).

        >>> block = BodyBlock("g", "circle", (1, 1, 1), [[0, 0]] * 12, [[0, 0]] * 12)
        >>> block.names_clash("g11"), block.names_clash("g12"), block.names_clash("g01"), block.names_clash("h1")
        (True, False, False, False)
        """
        if not name.startswith(self.name):
            return False
        number = name[len(self.name) :]
        return number.isascii() and number.isdigit() and str(int(number)) == number and int(number) < len(self)


@dataclass(frozen=True)
class BodyColumns:
    """The bodies as the engine's columns, in the order given: the shape's kind (0 circle,
    1 sphere, 2 2D box, 3 3D box), centres, velocities, half extents, inverse masses (0: a
    kinematic body) and restitution overrides (NaN: none)."""

    kind: NDArray[np.int64]
    pos: FloatArray
    vel: FloatArray
    ext: FloatArray
    ima: FloatArray
    eb: FloatArray
    mass: FloatArray


def _kind_of(shape: object) -> int:
    if isinstance(shape, Circle):
        return 0
    if isinstance(shape, Sphere):
        return 1
    return 2 if isinstance(shape, AABB) and shape.dim == 2 else 3


_BLOCK_KIND = {"circle": 0, "sphere": 1}


class Bodies(BuiltSequence[Body]):
    """A scenario's moving bodies in the order given: single :class:`Body` objects and
    :class:`BodyBlock` s chained into one sequence. Equal to a tuple of the same bodies.

    >>> ball = Body("ball", Sphere((0, 5, 0), 1), (0, 0, 0))
    >>> gas = BodyBlock("g", "sphere", (0.5, 0.5, 0.5), [[0, 0, 0], [2, 0, 0]], [[0, 0, 0], [0, 0, 0]])
    >>> bodies = Bodies([ball, gas])
    >>> len(bodies), [b.name for b in bodies], bodies[2].name
    (3, ['ball', 'g0', 'g1'], 'g1')
    >>> bodies.columns().pos[:, 0].tolist()
    [0.0, 0.0, 2.0]
    """

    def __init__(self, items: Iterable[Body | BodyBlock]) -> None:
        parts: list[tuple[Body, ...] | BodyBlock] = []
        singles: list[Body] = []
        for item in items:
            if isinstance(item, BodyBlock):
                if singles:
                    parts.append(tuple(singles))
                    singles = []
                if len(item):
                    parts.append(item)
            elif isinstance(item, Body):
                singles.append(item)
            else:
                raise InvalidInputError("bodies", "must be Body or BodyBlock objects", got=type(item).__name__)
        if singles:
            parts.append(tuple(singles))
        self.parts: tuple[tuple[Body, ...] | BodyBlock, ...] = tuple(parts)
        self._starts = np.cumsum([0] + [len(p) for p in self.parts])

    @property
    def blocks(self) -> tuple[BodyBlock, ...]:
        return tuple(p for p in self.parts if isinstance(p, BodyBlock))

    @property
    def singles(self) -> tuple[Body, ...]:
        """The bodies given one by one (not in a block)."""
        return tuple(b for p in self.parts if not isinstance(p, BodyBlock) for b in p)

    def __len__(self) -> int:
        return int(self._starts[-1])

    def _item(self, index: int) -> Body:
        part = int(np.searchsorted(self._starts, index, side="right")) - 1
        return self.parts[part][index - int(self._starts[part])]

    def __iter__(self) -> Iterator[Body]:
        for part in self.parts:
            yield from part

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Bodies):
            return self.parts == other.parts
        if isinstance(other, (tuple, list)):
            return len(self) == len(other) and all(a == b for a, b in zip(self, other, strict=True))
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"Bodies({', '.join(repr(p) if isinstance(p, BodyBlock) else f'{len(p)} single' for p in self.parts)})"

    def names(self) -> list[str]:
        """Every body's name, in order (a block's without building its bodies)."""
        out: list[str] = []
        for part in self.parts:
            if isinstance(part, BodyBlock):
                out += [f"{part.name}{i}" for i in range(len(part))]
            else:
                out += [b.name for b in part]
        return out

    def columns(self) -> BodyColumns:
        """The bodies as the engine's arrays (see :class:`BodyColumns`), made afresh at each
        call (a world steps them in place; nothing of this size is kept beside the blocks)."""
        kinds: list[NDArray[np.int64]] = []
        pos: list[FloatArray] = []
        vel: list[FloatArray] = []
        ext: list[FloatArray] = []
        eb: list[FloatArray] = []
        mass: list[FloatArray] = []
        for part in self.parts:
            n = len(part)
            if isinstance(part, BodyBlock):
                kind = (2 if part.dims == 2 else 3) if part.shape == "aabb" else _BLOCK_KIND[part.shape]
                kinds.append(np.full(n, kind, np.int64))
                pos.append(part.positions)
                vel.append(part.velocities)
                ext.append(np.tile(np.array(part.half), (n, 1)))
                mass.append(np.full(n, part.mass))
                eb.append(np.full(n, math.nan if part.restitution is None else part.restitution))
            else:
                kinds.append(np.array([_kind_of(b.shape) for b in part], np.int64))
                pos.append(np.array([b.position.as_tuple() for b in part]))
                vel.append(np.array([b.velocity.as_tuple() for b in part]))
                ext.append(np.array([_half_of(b.shape) for b in part]))
                mass.append(np.array([b.mass for b in part]))
                eb.append(np.array([math.nan if b.restitution is None else b.restitution for b in part]))
        masses = np.concatenate(mass) if mass else np.zeros(0)
        with np.errstate(divide="ignore", over="ignore"):  # 1 / 1e-310: refused by the range check, later
            inverse = np.where(np.isfinite(masses), 1.0 / masses, 0.0)
        columns = BodyColumns(
            kind=np.concatenate(kinds) if kinds else np.zeros(0, np.int64),
            pos=np.ascontiguousarray(np.concatenate(pos)) if pos else np.zeros((0, 3)),
            vel=np.ascontiguousarray(np.concatenate(vel)) if vel else np.zeros((0, 3)),
            ext=np.ascontiguousarray(np.concatenate(ext)) if ext else np.zeros((0, 3)),
            ima=inverse,
            eb=np.concatenate(eb) if eb else np.zeros(0),
            mass=masses,
        )
        return columns

    def representatives(self) -> list[Body]:
        """Up to two bodies of each kind of shape (its type and dimension), in order: whether a
        pair of bodies has a collision query depends on their kinds only."""
        firsts: dict[tuple[str, int], int] = {}
        chosen: list[Body] = []
        for part in self.parts:
            candidates: Iterable[Body] = part[:2] if isinstance(part, BodyBlock) else part
            for body in candidates:
                shape = body.shape
                key = (type(shape).__name__, shape.dim if isinstance(shape, AABB) else 0)
                if firsts.get(key, 0) < 2:
                    firsts[key] = firsts.get(key, 0) + 1
                    chosen.append(body)
        return chosen


def _half_of(shape: Any) -> tuple[float, float, float]:
    if isinstance(shape, AABB):
        return shape.half_size.as_tuple()
    return (shape.radius,) * 3
