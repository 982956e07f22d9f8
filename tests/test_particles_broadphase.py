"""The particle broad phase finds exactly the pairs that checking all pairs finds."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collisionlab.errors import InvalidInputError
from collisionlab.particles import brute_force_pairs, grid_pairs
from collisionlab.particles.broadphase import half_stencil

BACKENDS = ["python", "numba"]  # the same kernels, uncompiled and compiled


@pytest.mark.parametrize("dim", [2, 3])
def test_half_stencil_visits_every_neighbour_pair_once(dim: int) -> None:
    rows = [tuple(r[:dim]) for r in half_stencil(dim).tolist()]
    assert rows[0] == (0,) * dim
    half = set(rows[1:])
    mirrored = {tuple(-x for x in r) for r in half}
    everything = set(itertools.product((-1, 0, 1), repeat=dim)) - {(0,) * dim}
    assert half.isdisjoint(mirrored)
    assert half | mirrored == everything  # 3^dim - 1 neighbours: 4 + 4 in 2D, 13 + 13 in 3D


@st.composite
def scenes(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray]:
    """Up to 60 balls, clustered or spread, of one size or many, some exactly touching."""
    dim = draw(st.sampled_from([2, 3]))
    n = draw(st.integers(1, 60))
    seed = draw(st.integers(0, 2**32 - 1))
    spread = draw(st.sampled_from([3.0, 10.0, 60.0, 1e4]))
    rng = np.random.default_rng(seed)
    pos = rng.uniform(-spread, spread, (n, dim))
    if draw(st.booleans()):  # integer lattice: many exact ties and exact touching at distance 2
        pos = np.round(pos)
    one_size = draw(st.sampled_from([None, 0.5, 1.0, 2.5]))
    rad = rng.uniform(0.1, 5.0, n) if one_size is None else np.full(n, one_size)
    if n >= 2 and draw(st.booleans()):
        pos[1] = pos[0]  # coincident centres
    return pos, rad


@settings(max_examples=150)
@given(scenes())
def test_grid_pairs_equal_brute_force(scene: tuple[np.ndarray, np.ndarray]) -> None:
    pos, rad = scene
    expected = brute_force_pairs(pos, rad)
    for backend in BACKENDS:
        np.testing.assert_array_equal(grid_pairs(pos, rad, backend=backend), expected)


@pytest.mark.parametrize("backend", BACKENDS)
def test_touching_is_a_contact_and_a_gap_is_not(backend: str) -> None:
    # distance 2 = 1 + 1 exactly: touching counts; 2 + 1e-9 apart does not.
    pos = [[0.0, 0.0], [2.0, 0.0], [10.0, 0.0], [12.000000001, 0.0]]
    assert grid_pairs(pos, 1.0, backend=backend).tolist() == [[0, 1]]


@pytest.mark.parametrize("backend", BACKENDS)
def test_pairs_across_cell_boundaries_and_in_a_huge_sparse_scene(backend: str) -> None:
    # Balls strung along a line 1e6 long force the grid to widen its cells; pairs 3-4 and 5-6
    # straddle arbitrary cell boundaries.
    pos = np.array([[0, 0], [1e6, 0], [5e5, 0], [7.3, 1.1], [8.9, 1.9], [-3e5, 4.0], [-3e5 + 1.2, 5.5]])
    expected = brute_force_pairs(pos, 1.0)
    assert expected.tolist() == [[3, 4], [5, 6]]
    np.testing.assert_array_equal(grid_pairs(pos, 1.0, backend=backend), expected)


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_dense_gas_in_3d(backend: str) -> None:
    rng = np.random.default_rng(7)
    pos = rng.uniform(0.0, 20.0, (2000, 3))
    rad = rng.uniform(0.5, 1.5, 2000)
    found = grid_pairs(pos, rad, backend=backend)
    assert len(found) > 500  # the test means something: many pairs
    np.testing.assert_array_equal(found, brute_force_pairs(pos, rad))


def test_one_ball_has_no_pairs() -> None:
    assert grid_pairs([[1.0, 2.0, 3.0]], 1.0).shape == (0, 2)
    assert brute_force_pairs([[1.0, 2.0, 3.0]], 1.0).shape == (0, 2)


@pytest.mark.parametrize(
    ("positions", "radii", "field"),
    [
        ([[0.0, 0.0, 0.0, 0.0]], 1.0, "positions"),
        ([[0.0, float("nan")]], 1.0, "positions"),
        (np.empty((0, 2)), 1.0, "positions"),
        ([[0.0, 0.0]], -1.0, "radii"),
        ([[0.0, 0.0]], 0.0, "radii"),
    ],
)
def test_bad_input_names_the_field(positions: object, radii: object, field: str) -> None:
    with pytest.raises(InvalidInputError) as caught:
        grid_pairs(positions, radii)
    assert caught.value.field == field


def test_unknown_backend_is_refused() -> None:
    with pytest.raises(InvalidInputError, match="backend"):
        grid_pairs([[0.0, 0.0]], 1.0, backend="gpu")
