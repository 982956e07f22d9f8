"""Sums that every machine rounds alike: the ledger's energies and momenta.

``np.dot`` and ``@`` hand their sums to BLAS, whose order (and use of fused multiply-adds)
follows the CPU's vector width: the same run's ``kinetic_start`` came out
2.973149827369922 J on one machine and 2.9731498273699217 J on another (AVX-512 against
AVX2), and printed outputs must not depend on the machine. Here each product is rounded on
its own (numpy's element-wise operations are IEEE-exact per element) and the terms are
summed by :func:`math.fsum`, which rounds the exact sum once, whatever their order.

Imports nothing from the package: the collision layer and the worlds both use it.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["exact_dot", "exact_sum", "row_dots", "squared_lengths"]


def exact_sum(values: Any) -> float:
    """The correctly rounded sum of ``values`` (any order gives the same float).

    >>> exact_sum(np.array([1e16, 1.0, -1e16]))
    1.0
    >>> exact_sum(np.array([]))
    0.0
    """
    return math.fsum(np.asarray(values, dtype=np.float64).ravel().tolist())


def exact_dot(weights: Any, values: Any) -> float:
    """``sum_i w_i v_i``: each product rounded, then :func:`exact_sum`.

    >>> exact_dot(np.array([1.0, 2.0, 3.0]), np.array([4.0, 5.0, 6.0]))  # 4 + 10 + 18
    32.0
    """
    return exact_sum(np.multiply(weights, values))


def row_dots(rows: Any, other: Any) -> np.ndarray[Any, np.dtype[np.float64]]:
    """``r . o`` for each row ``r`` of ``rows`` (``other``: rows alike, or one vector for all),
    the products added left to right (no fused multiply-add).

    >>> row_dots(np.array([[1.0, 2.0, 3.0], [0.0, 1.0, 0.0]]), np.array([0.0, -9.81, 0.0])).tolist()
    [-19.62, -9.81]
    """
    rows = np.asarray(rows, dtype=np.float64)
    other = np.broadcast_to(np.asarray(other, dtype=np.float64), rows.shape)
    total = rows[:, 0] * other[:, 0]
    for k in range(1, rows.shape[1]):
        total = total + rows[:, k] * other[:, k]
    return np.asarray(total, dtype=np.float64)


def squared_lengths(rows: Any) -> np.ndarray[Any, np.dtype[np.float64]]:
    """``|r|^2`` of each row (:func:`row_dots` of the rows with themselves).

    >>> squared_lengths(np.array([[3.0, 4.0, 0.0], [1.0, 1.0, 1.0]])).tolist()
    [25.0, 3.0]
    """
    return row_dots(rows, rows)
