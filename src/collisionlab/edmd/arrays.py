"""Where an event-driven world's arrays live in memory: which arrays make its state, rows that
start on a cache line, and the storage order of the bodies (Morton order of their cells, so
that neighbours in space are neighbours in memory). The columns of each array are
:mod:`.layout`'s."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["ALIGNED", "CACHE_LINE", "STATE_ARRAYS", "aligned_zeros", "morton_order"]

#: The arrays that hold a world's whole state (:meth:`EventDrivenWorld.state_arrays`): the
#: bodies, their lists, cells and calendar, the parameters, accumulators and counters, the
#: species' tallies and the storage order. ``CF`` is ``CI``'s memory read as float32.
STATE_ARRAYS = ("F", "IX", "NB", "CI", "heap", "lists", "P", "Q", "G", "K", "S", "KS", "SE", "order")
#: Those laid out on cache lines (:func:`aligned_zeros`), as the constructor makes them.
ALIGNED = ("F", "IX", "NB", "CI", "heap")


#: Bytes of a cache line: rows of the hot arrays start on one (see :func:`aligned_zeros`).
CACHE_LINE = 64


def aligned_zeros(shape: tuple[int, ...], dtype: type = np.float64) -> NDArray[Any]:
    """Zeros whose first byte starts a cache line (numpy's own start 16 bytes into one, from
    malloc). A row of ``F`` (128 bytes, see :mod:`.layout`) then holds the position, velocity
    and times that a neighbour's prediction reads in one line, instead of across two; a
    neighbour list of 32 (128 bytes) spans two lines, not three.

    >>> a = aligned_zeros((3, 12))
    >>> a.ctypes.data % CACHE_LINE, a.shape, a.dtype.name, float(a.sum())
    (0, (3, 12), 'float64', 0.0)
    """
    size = int(np.prod(shape)) * np.dtype(dtype).itemsize
    memory = np.zeros(size + CACHE_LINE, dtype=np.uint8)
    skip = -memory.ctypes.data % CACHE_LINE
    return memory[skip : skip + size].view(dtype).reshape(shape)


def morton_order(pos: NDArray[np.float64], cell: float) -> NDArray[np.int64]:
    """Indices that sort ``pos`` by the Morton code of cells of side ``cell`` (ties by position).

    >>> morton_order(np.array([[3.0, 3.0], [0.0, 0.0], [3.0, 0.0], [0.0, 3.0]]), 2.0).tolist()
    [1, 2, 3, 0]
    """
    n, dim = pos.shape
    cells = np.floor((pos - pos.min(axis=0)) / cell).astype(np.uint64)
    code = np.zeros(n, dtype=np.uint64)
    for bit in range(63 // dim):
        for k in range(dim):
            code |= ((cells[:, k] >> np.uint64(bit)) & np.uint64(1)) << np.uint64(bit * dim + k)
    keys = [pos[:, k] for k in reversed(range(dim))]
    return np.lexsort((*keys, code)).astype(np.int64)
