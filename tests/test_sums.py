"""collisionlab.sums: correctly rounded sums, whatever the order of the terms or the machine."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from collisionlab.sums import exact_dot, exact_sum, squared_lengths

finite = st.floats(min_value=-1e12, max_value=1e12, allow_nan=False)


@given(st.lists(finite, max_size=60), st.randoms(use_true_random=False))
@settings(max_examples=200, deadline=None)
def test_the_sum_is_the_exact_sum_rounded_once_in_any_order(values: list[float], rng: object) -> None:
    # oracle: exact rational arithmetic, rounded once at the end
    exact = float(sum((Fraction(x) for x in values), Fraction(0)))
    shuffled = list(values)
    rng.shuffle(shuffled)  # type: ignore[attr-defined]
    assert exact_sum(np.array(values)) == exact
    assert exact_sum(np.array(shuffled)) == exact


def test_cancellation_that_a_running_sum_loses() -> None:
    # left to right in floats: (1e16 + 1) rounds to 1e16, then - 1e16 gives 0; exactly it is 1
    values = np.array([1e16, 1.0, -1e16])
    assert float(np.add.reduce(values[:2]) + values[2]) == 0.0
    assert exact_sum(values) == 1.0


def test_a_dot_rounds_each_product_then_sums_exactly() -> None:
    # 0.1 * 3 rounds to 0.30000000000000004; three of them and -0.9: the products' exact sum
    w, v = np.array([0.1, 0.1, 0.1, -0.9]), np.array([3.0, 3.0, 3.0, 1.0])
    products = [Fraction(0.1 * 3.0)] * 3 + [Fraction(-0.9)]
    assert exact_dot(w, v) == float(sum(products, Fraction(0)))


def test_squared_lengths_by_hand() -> None:
    # 3^2 + 4^2 = 25; 1 + 4 + 9 = 14; a 2D row 0.5^2 + 0.5^2 = 0.5
    assert squared_lengths(np.array([[3.0, 4.0, 0.0], [1.0, 2.0, 3.0]])).tolist() == [25.0, 14.0]
    assert squared_lengths(np.array([[0.5, 0.5]])).tolist() == [0.5]
