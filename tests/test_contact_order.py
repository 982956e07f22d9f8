"""The order of the contacts (contact_order): deepest first, ties by geometry, then by number. A
subset of them is ordered as the order of all of them leaves it (many ties, as resting contacts
make, short runs and long ones); a sweep may take the contacts alone on their bodies anywhere."""

from __future__ import annotations

import numpy as np
import pytest

from collisionlab.engine import contact_order, euler_push_apart, pair_separation


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
    whole = contact_order._order_contacts(pos, ca, cb, cd, count)
    rng = np.random.default_rng(1000 + seed)
    idx = np.sort(rng.choice(count, int(rng.integers(1, count + 1)), replace=False))
    wanted = whole[np.isin(whole, idx)]
    got = contact_order._order_subset(pos, ca, cb, cd, idx, idx.shape[0])
    assert got.tolist() == wanted.tolist()
    rng.shuffle(idx)  # given in any order: the same
    assert contact_order._order_subset(pos, ca, cb, cd, idx, idx.shape[0]).tolist() == wanted.tolist()


def _pile(seed: int) -> tuple[np.ndarray, ...]:
    """Up to 40 balls of radius 0.1 sunk a little into a floor (most touch only it), some in
    overlapping clusters, and every contact among them and with the floor: ``(pos, ext, ima,
    ca, cb, cd)``."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 40))
    pos = np.zeros((n, 3))
    pos[:, 0] = rng.uniform(0, 10, n)
    pos[:, 2] = rng.uniform(0, 10, n)
    pos[:, 1] = 0.1 - rng.uniform(0, 1e-3, n)
    lifted = rng.random(n) < 0.3  # on top of the ball before it, overlapping it a little
    for i in np.flatnonzero(lifted[1:]) + 1:
        pos[i] = pos[i - 1] + rng.normal(size=3) * 0.01 + np.array([0.0, 0.199, 0.0])
    ext = np.full((n, 3), 0.1)
    ima = rng.uniform(0.5, 2.0, n)
    ca, cb, cd = [], [], []
    for i in range(n):
        if pos[i, 1] - 0.1 < 1e-3:
            ca.append(-1)
            cb.append(i)
            cd.append(0.1 - pos[i, 1])
        for j in range(i + 1, n):
            depth = 0.2 - float(np.linalg.norm(pos[i] - pos[j]))
            if depth > -1e-3:
                ca.append(i)
                cb.append(j)
                cd.append(depth)
    return pos, ext, ima, np.array(ca), np.array(cb), np.array(cd)


@pytest.mark.parametrize("seed", range(20))
def test_a_contact_alone_on_its_bodies_may_come_anywhere_in_a_push_apart_sweep(seed: int) -> None:
    # The exact stepper sweeps the contacts that share a body in the whole order and the others
    # after them; push-apart (passes until nothing moves) must end with the same positions, to
    # the bit, as the Forward Euler stepper's order of all of them gives.
    pos, ext, ima, ca, cb, cd = _pile(seed)
    count = cd.shape[0]
    kind = np.full(pos.shape[0], pair_separation.BALL_3D, np.int64)
    floor = (np.array([pair_separation.STATIC_WALL]), np.zeros((1, 3)), np.array([[0.0, 1.0, 0.0]]))
    whole = contact_order._order_contacts(pos, ca, cb, cd, count)
    coupled = contact_order._order_coupled(pos, ca, cb, cd, np.arange(count), count, np.zeros(len(pos), np.int64))
    assert sorted(coupled.tolist()) == list(range(count))
    ends, ledgers = [], []
    for order in (whole, coupled):
        moved, ledger = pos.copy(), np.zeros(8)
        for _ in range(50):
            gravity = np.array([0, -9.81, 0])
            if not euler_push_apart._push_apart(kind, moved, ext, ima, *floor, ca, cb, cd, order, gravity,
                                                1e-9, 1e-3, ledger):  # fmt: skip
                break
        ends.append(moved)
        ledgers.append(ledger)
    assert np.array_equal(ends[0], ends[1])
    assert not np.array_equal(ends[0], pos)  # something was pushed
    assert ledgers[1] == pytest.approx(ledgers[0], rel=1e-12, abs=1e-15)


@pytest.mark.parametrize("seed", range(20))
def test_the_events_of_a_pass_are_put_in_the_order_of_all_the_contacts(seed: int) -> None:
    # A pass resolves the contacts in _order_coupled's order and writes an event for some of
    # them; afterwards they must read as if every contact had been sorted (_order_contacts).
    if seed % 2:  # most contacts alone on their bodies (balls on a floor)
        pos, _, _, ca, cb, cd = _pile(seed)
    else:  # most sharing them, many ties
        pos, ca, cb, cd = _contacts(seed, seed % 4 == 0)
    count = cd.shape[0]
    order = contact_order._order_coupled(pos, ca, cb, cd, np.arange(count), count, np.zeros(len(pos), np.int64))
    rng = np.random.default_rng(2000 + seed)
    resolved = np.sort(rng.choice(count, int(rng.integers(1, count + 1)), replace=False))  # positions in order
    events = np.zeros((len(resolved) + 3, 4))
    events[:3, 0] = -1.0  # rows of an earlier pass stay
    events[3:, 0] = order[resolved]  # each row names its contact
    events[3:, 1] = np.arange(len(resolved))
    contact_order._events_in_order(events, 3, len(events), resolved, order, pos, ca, cb, cd)
    whole = contact_order._order_contacts(pos, ca, cb, cd, count)
    assert events[3:, 0].astype(int).tolist() == [c for c in whole if c in set(order[resolved])]
    assert events[:3, 0].tolist() == [-1.0] * 3
    assert sorted(events[3:, 1].tolist()) == list(range(len(resolved)))  # whole rows moved
