"""The Forward Euler stepper's grid finds exactly the pairs that checking all pairs finds, with
bodies of many sizes (the widest few are met apart from the grid), in a grid of cells and in a
hashed one (a spread-out scene), in both forms of the kernels; and a run with such bodies is the
same in both forms and under a permutation of the bodies."""

from __future__ import annotations

import dataclasses
import tomllib
from typing import Any

import numpy as np
import pytest

from collisionlab.engine import broad_phase_grid, compiled, pair_separation, step_kernels
from collisionlab.engine.params import WorldParams
from collisionlab.engine.stepper import max_cells, stencil
from collisionlab.scenario_file import parse_scenario
from collisionlab.world import World

MARGIN = 1e-7


def _scene(dims: int, spread: float, seed: int) -> tuple[Any, ...]:
    """100 bodies: balls and boxes of 0.05-0.2, a few boxes up to 2.5 wide, some touching."""
    rng = np.random.default_rng(seed)
    n = 100
    kind = np.where(rng.random(n) < 0.7, pair_separation.BALL_2D, pair_separation.BOX_2D).astype(np.int64)
    kind += 1 if dims == 3 else 0  # BALL_3D, BOX_3D
    ext = np.zeros((n, 3))
    ext[:, :dims] = rng.uniform(0.05, 0.2, (n, dims))
    balls = kind <= pair_separation.BALL_3D
    ext[balls, :] = ext[balls, :1]
    large = rng.choice(np.flatnonzero(~balls), 3, replace=False)
    ext[large, :dims] = rng.uniform(0.5, 1.25, (3, dims))
    if dims == 2:
        ext[~balls, 2] = 0.0  # a 2-D box has no depth; a circle keeps (r, r, r)
    pos = np.zeros((n, 3))
    pos[:, :dims] = rng.uniform(-spread, spread, (n, dims))
    pos[1] = pos[0]  # coincident
    pos[3, :dims] = pos[2, :dims] + (ext[2, 0] + ext[3, 0]) * np.eye(dims)[0]  # touching along x
    statics = (
        np.array([pair_separation.STATIC_BOX], np.int64),
        np.array([[-1.0, -1.0, -1.0]]),
        np.array([[0.5, 0.0, 0.5]]),
    )
    return kind, pos, ext, np.arange(n, dtype=np.int64), statics


def _brute_force(kind: Any, pos: Any, ext: Any, statics: tuple[Any, ...]) -> dict[tuple[int, int], float]:
    s_kind, s_a, s_b = statics
    found = {}
    n = pos.shape[0]
    for i in range(n):
        for j in range(i + 1, n):
            sep = pair_separation._body_separation(kind, pos, ext, i, j)
            if sep[0] <= MARGIN:
                found[(i, j)] = -sep[0]
        for s in range(s_kind.shape[0]):
            sep = pair_separation._static_separation(s_kind, s_a, s_b, s, kind, pos, ext, i)
            if sep[0] <= MARGIN:
                found[(-1 - s, i)] = -sep[0]
    return found


@pytest.mark.parametrize("form", ["python", "compiled"])
@pytest.mark.parametrize("dims", [2, 3])
@pytest.mark.parametrize("spread", [1.5, 3.0, 300.0])
def test_the_grid_finds_every_near_pair_of_bodies_of_many_sizes(form: str, dims: int, spread: float) -> None:
    kernels = compiled.kernels() if form == "compiled" else step_kernels
    for seed in range(3):
        kind, pos, ext, ids, statics = _scene(dims, spread, seed)
        pairs, depths = kernels.find_near(
            kind, pos, ext, ids, *statics, stencil(dims), dims, 1.0, max_cells(len(kind)), MARGIN
        )
        found = {(int(a), int(b)): float(d) for (a, b), d in zip(pairs, depths, strict=True)}
        assert len(found) == len(pairs)  # each pair once
        assert found == _brute_force(kind, pos, ext, statics)
        assert len(found) >= 2


def _incline(count: int, region: str, mode: str = "euler") -> str:
    return f"""
    [simulation]
    mode = "{mode}"
    dt = 0.005
    steps = 60
    restitution = 0.8
    gravity = [0, -9.81, 0]
    [[gas]]
    name = "ball"
    shape = "sphere"
    radius = 0.1
    region = {region}
    count = {count}
    seed = 3
    [[gas]]
    name = "crate"
    shape = "aabb"
    size = [0.9, 0.6, 0.9]
    region = [[-1.5, 1.6, -1.5], [1.5, 2.6, 1.5]]
    count = 2
    seed = 4
    [[static]]
    name = "incline"
    shape = "plane"
    point = [0, 0, 0]
    normal = [0.3, 1, 0]
    """


@pytest.mark.parametrize("region", ["[[-1, 0.2, -1], [1, 1.5, 1]]", "[[-30, 0.2, -30], [30, 1.5, 30]]"])
def test_a_run_with_a_few_large_bodies_is_the_same_compiled_and_permuted(region: str) -> None:
    # 64 balls and 2 large crates: the crates are met apart from the grid (one body in 32 may
    # be); the wide region needs more cells than the budget, so the grid is hashed.
    scenario = parse_scenario(tomllib.loads(_incline(64, region)))
    slow = World(scenario, WorldParams(compiled=False)).run(every=20)
    fast = World(scenario, WorldParams(compiled=True)).run(every=20)
    assert [f.bodies for f in slow.frames] == [f.bodies for f in fast.frames]
    assert slow.events == fast.events
    order = np.random.default_rng(1).permutation(len(scenario.bodies))
    permuted = dataclasses.replace(scenario, bodies=tuple(scenario.bodies[i] for i in order))
    again = World(permuted, WorldParams(compiled=True)).run(every=20)
    by_name = [{b.name: b for b in f.bodies} for f in again.frames]
    assert by_name == [{b.name: b for b in f.bodies} for f in fast.frames]
    assert len(fast.events) > 0


def test_a_crowded_hashed_grid_still_finds_every_pair(monkeypatch: pytest.MonkeyPatch) -> None:
    # One bucket per body (the Python form reads the constant when called): rows of cells share
    # buckets with many other cells, and many rows wrap around the end of the table.
    monkeypatch.setattr(broad_phase_grid, "BUCKETS_PER_BODY", 1)
    for dims in (2, 3):
        for seed in range(3):
            kind, pos, ext, ids, statics = _scene(dims, 30.0, seed)
            pairs, depths = step_kernels.find_near(
                kind, pos, ext, ids, *statics, stencil(dims), dims, 1.0, max_cells(len(kind)), MARGIN
            )
            found = {(int(a), int(b)): float(d) for (a, b), d in zip(pairs, depths, strict=True)}
            assert found == _brute_force(kind, pos, ext, statics)
