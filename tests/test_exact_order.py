"""The exact stepper orders a subset of the contacts (those in contact, those push-apart looks
at) as the Forward Euler stepper's order of all of them would: deepest first, ties by geometry,
then by number. Many ties, as resting contacts make, short runs and long ones."""

from __future__ import annotations

import numpy as np
import pytest

from collisionlab.engine import exact_kernels, step_kernels


def _contacts(seed: int, on_grid: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Up to 200 contacts among up to 40 bodies and 3 statics, depths from a few values (long
    runs of equal depth), positions on a coarse grid when ``on_grid`` (equal coordinates)."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 40))
    pos = rng.integers(0, 3, (n, 3)) * 0.5 if on_grid else rng.normal(size=(n, 3))
    count = int(rng.integers(1, 200))
    ca = rng.integers(-3, n, count)
    cb = rng.integers(0, n, count)
    cd = rng.choice(np.array([0.0, -1e-9, 1e-10, -5e-8]), count)
    return pos.astype(float), ca, cb, cd


@pytest.mark.parametrize("on_grid", [False, True])
@pytest.mark.parametrize("seed", range(20))
def test_a_subset_is_ordered_as_the_whole_order_leaves_it(seed: int, on_grid: bool) -> None:
    pos, ca, cb, cd = _contacts(seed, on_grid)
    count = cd.shape[0]
    whole = step_kernels._order_contacts(pos, ca, cb, cd, count)
    rng = np.random.default_rng(1000 + seed)
    idx = np.sort(rng.choice(count, int(rng.integers(1, count + 1)), replace=False))
    wanted = whole[np.isin(whole, idx)]
    got = exact_kernels._order_subset(pos, ca, cb, cd, idx, idx.shape[0])
    assert got.tolist() == wanted.tolist()
