"""The check of bodies overlapping at the start (``engine/overlap.py``): the same pairs and
depths as the kernels' narrow phase, found by a grid in NumPy; a refusal names the file."""

from __future__ import annotations

import numpy as np
import pytest

from collisionlab.engine import pair_separation as ps
from collisionlab.engine import step_kernels as sk
from collisionlab.engine.overlap import find_overlaps
from collisionlab.engine.params import WorldParams
from collisionlab.engine.state import BodyArrays, StaticArrays
from collisionlab.engine.stepper import near_pairs
from collisionlab.scenario_file import ScenarioError, load_scenario
from tests.cli_helpers import run_cli

SLOP = WorldParams().slop


def _bodies(kind: np.ndarray, pos: np.ndarray, ext: np.ndarray) -> BodyArrays:
    n = kind.shape[0]
    return BodyArrays(kind, pos, np.zeros((n, 3)), ext, np.ones(n), np.full(n, np.nan), np.arange(n, dtype=np.int64))


def _pile(path, count: int) -> None:
    """``count`` circles of radius 0.5 all at the origin."""
    rows = ["[simulation]", "dt = 0.01", "steps = 10"]
    for i in range(count):
        rows += ["[[body]]", f'name = "b{i}"', 'shape = "circle"', "position = [0, 0]", "radius = 0.5"]
    path.write_text("\n".join(rows) + "\n")


@pytest.mark.parametrize("seed", range(40))
def test_the_overlaps_found_are_the_narrow_phases(seed: int) -> None:
    # Balls and boxes of mixed sizes (up to three much wider, which the grid leaves out), and
    # statics:
    # the count and the deepest depth are those of the kernels' own search (Python form).
    rng = np.random.default_rng(seed)
    n, dims = int(rng.integers(2, 90)), int(rng.integers(2, 4))
    kind = (rng.integers(0, 2, n) * 2 + dims - 2).astype(np.int64)
    pos = np.zeros((n, 3))
    pos[:, :dims] = rng.uniform(0.0, 6.0, (n, dims))
    balls = kind <= ps.BALL_3D
    ext = np.zeros((n, 3))
    ext[:, :dims] = rng.uniform(0.05, 0.8, (n, dims))  # a box's half sizes (z = 0 in 2D)
    ext[balls] = rng.uniform(0.05, 0.8, (int(balls.sum()), 1))  # a ball's radius on every axis
    ext[: int(rng.integers(0, 4))] *= 6.0
    statics = StaticArrays(
        np.array([ps.STATIC_BOUNDARY, ps.STATIC_BOX, ps.STATIC_WALL], np.int64),
        np.array([[0.0, 0.3, 0.0], [2.0, 2.0, -9.0], [6.0, 0.0, 0.0]]),
        np.array([[0.0, 1.0, 0.0], [3.0, 2.5, 9.0], [-1.0, 0.0, 0.0]]),
        np.full(3, np.nan),
    )
    bodies = _bodies(kind, pos, ext)
    found = find_overlaps(bodies, statics, dims, SLOP, every=True)
    _, depths = near_pairs(sk, bodies, statics, dims, WorldParams(), 0.0)
    deep = depths[depths > SLOP]
    assert found.complete and found.count == deep.size
    if deep.size:
        assert found.depth == pytest.approx(deep.max(), abs=1e-12)


def test_bodies_spread_out_on_a_lattice_do_not_overlap_and_a_pile_does() -> None:
    side = 300  # 90,000 circles 1 m apart, each 0.98 m across: none overlaps
    grid = np.stack(np.meshgrid(np.arange(side), np.arange(side)), -1).reshape(-1, 2).astype(float)
    pos = np.zeros((grid.shape[0], 3))
    pos[:, :2] = grid
    n = pos.shape[0]
    none = StaticArrays(np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0))
    spread = find_overlaps(_bodies(np.zeros(n, np.int64), pos, np.full((n, 3), 0.49)), none, 2, SLOP, every=False)
    assert spread.count == 0
    pile = find_overlaps(_bodies(np.zeros(n, np.int64), pos * 0.0, np.full((n, 3), 0.49)), none, 2, SLOP, every=False)
    assert pile.count > 0 and not pile.complete and pile.depth == pytest.approx(0.98)


def test_a_file_of_many_bodies_at_one_point_is_refused_naming_the_file_and_a_pair(tmp_path) -> None:
    path = tmp_path / "pile.toml"
    _pile(path, 2000)
    with pytest.raises(ScenarioError, match=r"pile\.toml: body: 'b0' and 'b1' overlap by 1 m at the start \(and at"):
        load_scenario(path)
    result = run_cli(["run", str(path), "--format", "json"])
    assert result.status == 65
    assert str(path) in result.err and "'b0' and 'b1' overlap by 1 m" in result.err
    assert len(result.err.strip().splitlines()) == 1 and "Traceback" not in result.err


def test_an_overlap_the_file_allows_is_counted_whole_in_the_warning(tmp_path) -> None:
    path = tmp_path / "pile.toml"
    _pile(path, 5)
    path.write_text(path.read_text().replace("[simulation]", "[simulation]\nallow_initial_overlap = true"))
    result = run_cli(["run", str(path), "--steps", "1"])
    assert result.status == 0 and "10 pairs overlapped at the start" in result.out
