"""The contact solver's order of its contacts (contact_solver._lowest_first): lowest first, equal
heights in the order they came (a stable sort), in the Python form and in the compiled one. The
oracle is Python's own sort (stable) of ``(height, place)``."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collisionlab.engine import compiled, contact_solver


@pytest.mark.parametrize("form", ["python", "compiled"])
def test_equal_heights_keep_their_order(form: str) -> None:
    # heights 2, 1, 2, 1, 0, 1 at places 0..5: lowest first is place 4 (0), then 1, 3, 5 (1),
    # then 0, 2 (2), as they came.
    module = contact_solver if form == "python" else compiled._module("contact_solver")
    contacts = np.array([10, 11, 12, 13, 14, 15, 99], np.int64)  # one spare slot past c
    heights = np.array([2.0, 1.0, 2.0, 1.0, 0.0, 1.0])
    module._lowest_first(contacts, heights, 6)
    assert contacts.tolist() == [14, 11, 13, 15, 10, 12, 99]


@settings(max_examples=200, deadline=None)
@given(st.lists(st.sampled_from([-1.5, 0.0, 0.25, 3.0]), min_size=0, max_size=80))
def test_the_order_is_a_stable_sort_of_the_heights(levels: list[float]) -> None:
    c = len(levels)
    heights = np.array(levels, float)  # few values: long runs of equal heights, as a flat layer makes
    contacts = np.arange(100, 100 + c, dtype=np.int64)
    np.random.default_rng(c).shuffle(contacts)
    wanted = [int(contacts[q]) for q in sorted(range(c), key=lambda q: (levels[q], q))]
    got = contacts.copy()
    contact_solver._lowest_first(got, heights, c)
    assert got.tolist() == wanted
