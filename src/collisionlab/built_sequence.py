"""A sequence whose items are built only when read: many bodies or events held as arrays."""

from __future__ import annotations

import bisect
from collections.abc import Iterator, Sequence
from typing import TypeVar, overload

__all__ = ["BuiltSequence", "SequenceChain"]

T = TypeVar("T")


class BuiltSequence(Sequence[T]):
    """``Sequence[T]`` over ``len(self)`` items that :meth:`_item` builds from arrays when one is
    read (an index, a slice, iteration): subclasses give ``__len__`` and ``_item``.

    >>> class Squares(BuiltSequence[int]):
    ...     def __len__(self) -> int:
    ...         return 4
    ...     def _item(self, i: int) -> int:
    ...         return i * i
    >>> Squares()[-1], Squares()[1:3], list(Squares())
    (9, [1, 4], [0, 1, 4, 9])
    """

    def __len__(self) -> int:
        raise NotImplementedError

    def _item(self, i: int) -> T:
        """Item ``i``, ``0 <= i < len(self)``."""
        raise NotImplementedError

    @overload
    def __getitem__(self, index: int) -> T: ...

    @overload
    def __getitem__(self, index: slice) -> Sequence[T]: ...

    def __getitem__(self, index: int | slice) -> T | Sequence[T]:
        if isinstance(index, slice):
            return [self._item(i) for i in range(*index.indices(len(self)))]
        if not -len(self) <= index < len(self):
            raise IndexError(f"{type(self).__name__} index out of range")
        return self._item(index % len(self))

    def __iter__(self) -> Iterator[T]:
        return (self._item(i) for i in range(len(self)))


class SequenceChain(BuiltSequence[T]):
    """The items of several sequences one after another, the sequences kept as they are (a run's
    events arrive as arrays, a block per chunk of steps; an item is built only when read).
    ``extend`` adds a sequence, ``append`` one item; equal to any sequence of equal items.

    >>> chain = SequenceChain([1, 2])
    >>> chain.extend(range(3, 5)); chain.append(5)
    >>> len(chain), chain[2], chain[-1], chain[1:4], chain == [1, 2, 3, 4, 5], chain == [1]
    (5, 3, 5, [2, 3, 4], True, False)
    """

    def __init__(self, items: Sequence[T] = ()) -> None:
        self._parts: list[Sequence[T]] = []
        self._ends: list[int] = []  # the running total of items after each part
        self.extend(items)

    def extend(self, items: Sequence[T]) -> None:
        if len(items):
            self._parts.append(items)
            self._ends.append(len(self) + len(items))

    def append(self, item: T) -> None:
        self.extend([item])

    def __len__(self) -> int:
        return self._ends[-1] if self._ends else 0

    def _item(self, i: int) -> T:
        part = bisect.bisect_right(self._ends, i)
        return self._parts[part][i - (self._ends[part - 1] if part else 0)]

    def __iter__(self) -> Iterator[T]:
        for part in self._parts:
            yield from part

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Sequence) or isinstance(other, str) or len(other) != len(self):
            return False
        return all(x == y for x, y in zip(self, other, strict=True))

    __hash__ = None  # type: ignore[assignment]  # mutable, like a list

    def __repr__(self) -> str:
        return f"SequenceChain({list(self)!r})" if len(self) <= 10 else f"<SequenceChain of {len(self)} items>"
