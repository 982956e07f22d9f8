"""The event-driven world: exact by hand on few bodies, conservation, order independence, no
overlap, and a heap that comes to rest under gravity with e < 1."""

from __future__ import annotations

import math

import numpy as np
import pytest

from collisionlab.edmd import EventDrivenWorld, box_side, gaussian_velocities, lattice
from collisionlab.edmd.observables import ExactGas
from collisionlab.errors import InvalidInputError


def _brute_overlap(world: EventDrivenWorld) -> float:
    """Deepest overlap of any pair, in diameters, by checking all N^2 pairs (an oracle
    independent of the engine's neighbour lists)."""
    p = world.positions
    d = p[:, None, :] - p[None, :, :]
    if world.periodic:
        d -= np.round(d / world.sides) * world.sides
    dist = np.sqrt((d * d).sum(axis=2))
    np.fill_diagonal(dist, np.inf)
    return float((2.0 * world.radius - dist.min()) / (2.0 * world.radius))


def test_head_on_pair_swaps_velocities_at_the_right_time() -> None:
    # centres 4 apart, closing at 2: the gap of 2 closes at t = 1; equal masses swap velocities
    w = EventDrivenWorld([[3.0, 5.0], [7.0, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], [10.0, 10.0], periodic=False)
    events: list[np.ndarray] = []
    w.run(1.5, sink=lambda block: events.append(block.copy()))
    rows = np.concatenate(events)
    assert rows.shape == (1, 4)
    assert rows[0, 0] == pytest.approx(1.0, rel=1e-15)
    assert rows[0, 3] == pytest.approx(2.0, rel=1e-15)  # impulse m * delta v = 1 * 2
    assert w.velocities.tolist() == [[-1.0, 0.0], [1.0, 0.0]]
    assert w.positions.ravel().tolist() == pytest.approx([3.5, 5.0, 6.5, 5.0], rel=1e-15)


def test_ball_bounces_off_a_wall_and_the_pressure_adds_up() -> None:
    # one ball at x = 5 moving at 2 in a box of 10: hits x = 9 at t = 2, x = 1 at t = 6
    w = EventDrivenWorld([[5.0, 5.0]], [[2.0, 0.0]], [10.0, 10.0], periodic=False)
    w.run(7.0)
    tally = w.tally()
    assert tally.wall_collisions == 2
    assert tally.wall_momentum == pytest.approx((4.0, 4.0, 0.0, 0.0))  # 2 m v each
    assert w.positions[0, 0] == pytest.approx(3.0)  # 1 + 2 * (7 - 6)


def test_periodic_wrap_and_pair_across_the_edge() -> None:
    # discs at x = 1 and 18 in a periodic box of 20 are 3 apart across the edge; closing at 2,
    # the gap of 1 closes at t = 0.5; by t = 1 they are back where they started
    w = EventDrivenWorld([[1.0, 10.0], [18.0, 10.0]], [[-1.0, 0.0], [1.0, 0.0]], [20.0, 20.0], periodic=True)
    w.run(1.0)
    assert w.tally().pair_collisions == 1
    assert w.velocities.tolist() == [[1.0, 0.0], [-1.0, 0.0]]
    assert w.positions.ravel().tolist() == pytest.approx([1.0, 10.0, 18.0, 10.0])


def test_ball_dropped_under_gravity_lands_when_theory_says() -> None:
    # from y = 11 to the floor contact y = r = 1 under g = 2: sqrt(2 * 10 / 2) = sqrt 10
    w = EventDrivenWorld([[5.0, 11.0]], [[0.0, 0.0]], [10.0, 20.0], periodic=False, gravity=2.0, tc=1e-3)
    events: list[np.ndarray] = []
    w.run(3.2, sink=lambda block: events.append(block.copy()))
    assert np.concatenate(events)[0, 0] == pytest.approx(math.sqrt(10.0), rel=1e-14)


def test_elastic_energy_is_constant_over_a_million_collisions() -> None:
    w = ExactGas(n=2000, dim=3, fraction=0.35, boundary="periodic", seed=3).world()
    e0 = w.kinetic_energy()
    w.run(150.0)
    assert w.tally().pair_collisions > 1_000_000
    assert abs(w.kinetic_energy() / e0 - 1.0) < 1e-12
    assert _brute_overlap(w) < 1e-9


def test_a_permutation_of_the_bodies_gives_the_same_run() -> None:
    n, dim, fraction = 400, 3, 0.3
    pos = lattice(n, dim, fraction, 1.0, True, 7)
    vel = gaussian_velocities(n, dim, 1.0, 1.0, 7)
    side = [box_side(n, dim, fraction, 1.0)] * dim
    order = np.random.default_rng(1).permutation(n)
    a = EventDrivenWorld(pos, vel, side)
    b = EventDrivenWorld(pos[order], vel[order], side)
    a.run(20.0)
    b.run(20.0)
    assert a.tally().pair_collisions > 10_000  # long enough for any difference to grow chaotically
    assert a.tally().pair_collisions == b.tally().pair_collisions
    assert np.array_equal(a.positions[order], b.positions)
    assert np.array_equal(a.velocities[order], b.velocities)


@pytest.mark.parametrize(("dim", "boundary"), [(2, "walls"), (2, "periodic"), (3, "walls"), (3, "periodic")])
def test_no_overlap_beyond_a_billionth_of_a_diameter(dim: int, boundary: str) -> None:
    w = ExactGas(n=600, dim=dim, fraction=0.45, boundary=boundary, seed=2).world()
    for t in (1.0, 5.0, 10.0):
        w.run(t)
        assert _brute_overlap(w) < 1e-9
    assert w.tally().max_contact_overlap / 2.0 < 1e-9


def test_a_thousand_balls_dropped_with_e_07_come_to_rest_in_a_heap() -> None:
    # 1,000 balls on a lattice filling a cube of side 43.8 (fraction 0.05), g = 1, e = 0.7, TC
    # model with t_c = 0.01. Starting energy per ball: 1.5 kinetic + about 22 potential.
    w = ExactGas(n=1000, dim=3, fraction=0.05, boundary="walls", restitution=0.7, gravity=1.0).world()
    w.run(60.0)
    kinetic = w.kinetic_energy() / w.n
    heights = w.positions[:, 1]
    # From 1.5 (and ~22 potential) to below 3e-3 by t = 60 (seen: 4.5e-4 and 1.1e-3 with two
    # event orders), on its way to the TC model's floor of ~6e-5 (python3 tasks.py edmd-long).
    assert kinetic < 3e-3
    # A heap: 1,000 balls over a floor of 43.8^2 make 1.6 close-packed layers; none is above 3 layers
    assert heights.max() < 1.0 + 3 * 2.0 and heights.mean() < 2.5
    assert _brute_overlap(w) < 1e-9 and w.tally().max_contact_overlap / 2.0 < 1e-9


def test_bad_input_names_the_field() -> None:
    with pytest.raises(InvalidInputError, match=r"^positions"):
        EventDrivenWorld([[0.0, 0.0]], [[0.0, 0.0]], [10.0, 10.0], periodic=False)  # inside the wall
    with pytest.raises(InvalidInputError, match=r"^positions: balls must not overlap"):
        EventDrivenWorld([[5.0, 5.0], [6.0, 5.0]], [[0.0, 0.0]] * 2, [10.0, 10.0], periodic=False)
    with pytest.raises(InvalidInputError, match=r"^gravity"):
        EventDrivenWorld([[5.0, 5.0]], [[0.0, 0.0]], [10.0, 10.0], gravity=1.0, tc=0.1)
    with pytest.raises(InvalidInputError, match=r"^sides"):
        EventDrivenWorld([[1.0, 1.0]], [[0.0, 0.0]], [5.0, 5.0])
    with pytest.raises(InvalidInputError, match=r"^fraction"):
        ExactGas(n=100, dim=3, fraction=0.7, boundary="walls").world()


# --- issue 11 (the audit): a run looked at between chunks (Ctrl-C, the range guard) --------------
def test_looking_between_chunks_changes_nothing() -> None:
    # The guard and the command line's look for Ctrl-C run between chunks of events: the run is
    # the same to the last bit as one run straight through (the events, the final state).
    gas = ExactGas(n=400, dim=3, time=5.0, boundary="periodic").checked()
    straight = gas.world()
    straight.run(gas.time)
    chunked = gas.world()
    looks: list[None] = []
    chunked.run(gas.time, between=lambda: looks.append(None), every=100)
    assert len(looks) >= straight.tally().events // 100 > 10
    assert chunked.tally() == straight.tally()
    assert np.array_equal(chunked.positions, straight.positions)
    assert np.array_equal(chunked.velocities, straight.velocities)


# --- the cells as compact rows (float32 centres, rows that fill and are widened) ----------------
def test_neighbour_lists_hold_exactly_the_bodies_within_the_cut_despite_float32_cells() -> None:
    # The cells keep float32 centres (off by ~1e-4 at a coordinate of 1,800): pairs placed at
    # 1 +- 1e-7 of the cut apart are decided again from the float64 centres. Oracle: every pair's
    # distance in float64, all N^2 of them.
    from collisionlab.edmd import layout as L

    side, m = 2000.0, 400  # 400 pairs on a 20 x 20 lattice near the far corner of the box

    def pairs(cut: float) -> np.ndarray:
        base = 1700.0 + 3.0 * cut * np.stack(np.meshgrid(np.arange(20), np.arange(20)), -1).reshape(m, 2)
        gap = cut * (1.0 + np.where(np.arange(m) % 2 == 0, -1e-7, 1e-7))  # in, out, in, out...
        return np.concatenate([base, base + np.column_stack([gap, np.zeros(m)])])

    cut = EventDrivenWorld(pairs(4.0), np.zeros((2 * m, 2)), [side, side]).P[L.P_CUT]  # n, box: the cut
    world = EventDrivenWorld(pairs(cut), np.zeros((2 * m, 2)), [side, side])
    assert world.P[L.P_CUT] == cut
    centres = world.F[:, L.C : L.C + 2]
    distance = np.sqrt(((centres[:, None, :] - centres[None, :, :]) ** 2).sum(axis=2))
    np.fill_diagonal(distance, np.inf)
    for i in range(2 * m):
        listed = set(world.NB[i, : world.IX[i, L.NNB]].tolist())
        assert listed == set(np.flatnonzero(distance[i] < cut).tolist()), i
    assert sum(int(world.IX[i, L.NNB]) for i in range(2 * m)) == m  # half the pairs, each listed twice


def test_cells_that_fill_are_widened_and_the_run_is_the_same(monkeypatch: pytest.MonkeyPatch) -> None:
    # Rows of room for one body each fill at once and are doubled (CELL_FULL) until all fit;
    # the run then goes as with the usual room: the same collisions, and the same state to
    # rounding (every list is built again after a widening, which re-bases each flight at a
    # different moment: 7e-15 here after 6,000 collisions; a wrong list would differ at O(1)).
    import collisionlab.edmd.world as world_module

    gas = ExactGas(n=500, dim=3, fraction=0.3, boundary="periodic", seed=4).checked()
    usual = gas.world()
    monkeypatch.setattr(world_module, "CELL_SLOTS", 2)
    cramped = gas.world()
    assert cramped.CI.shape[1] > 2 and cramped.CI.shape[1] != usual.CI.shape[1]  # widened
    usual.run(5.0)
    cramped.run(5.0)
    assert usual.tally().pair_collisions > 5_000
    a, b = cramped.tally(), usual.tally()
    assert a.pair_collisions == b.pair_collisions
    assert np.abs(cramped.positions - usual.positions).max() < 1e-12
    assert np.abs(cramped.velocities - usual.velocities).max() < 1e-12
