"""A sequence whose items are built only when read: many bodies or events held as arrays."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import TypeVar, overload

__all__ = ["BuiltSequence"]

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
