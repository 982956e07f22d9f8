"""The gas scenario and the Maxwell-Boltzmann law it relaxes to."""

from __future__ import annotations

import math

import numpy as np
import pytest

from collisionlab.errors import InvalidInputError
from collisionlab.particles import brute_force_pairs, component_variance, gas_scenario, speed_pdf


@pytest.mark.parametrize(("n", "dim"), [(1, 2), (1000, 2), (999, 3), (64, 3)])
def test_fraction_lattice_and_step_length(n: int, dim: int) -> None:
    gas = gas_scenario(n, dim, seed=5)
    volume = math.pi if dim == 2 else 4.0 / 3.0 * math.pi
    assert math.isclose(n * volume / gas.side**dim, 0.2, rel_tol=1e-12)
    assert gas.positions.shape == (n, dim) and gas.velocities.shape == (n, dim)
    assert np.all(gas.positions > gas.radius) and np.all(gas.positions < gas.side - gas.radius)
    assert brute_force_pairs(gas.positions, gas.radius).shape == (0, 2)  # nobody overlaps at the start
    rms = math.sqrt(float(np.mean(np.sum(gas.velocities**2, axis=1))))
    assert math.isclose(rms * gas.dt, 0.1 * gas.radius, rel_tol=1e-12)
    if n > 1:
        np.testing.assert_allclose(gas.velocities.mean(axis=0), 0.0, atol=1e-14)


def test_seeded_and_reproducible() -> None:
    a, b, c = gas_scenario(100, 2, seed=1), gas_scenario(100, 2, seed=1), gas_scenario(100, 2, seed=2)
    np.testing.assert_array_equal(a.velocities, b.velocities)
    assert not np.array_equal(a.velocities, c.velocities)


def test_equal_speeds_start() -> None:
    gas = gas_scenario(5000, 3, seed=1, speeds="equal")
    speeds = np.linalg.norm(gas.velocities, axis=1)
    assert speeds.std() < 0.05 * speeds.mean()  # equal up to the removed mean velocity


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"n": 0}, "n"),
        ({"dim": 4}, "dim"),
        ({"fraction": 0.9}, "fraction"),
        ({"speeds": "hot"}, "speeds"),
        ({"seed": -1}, "seed"),
        ({"radius": 0.0}, "radius"),
    ],
)
def test_bad_values_name_the_field(kwargs: dict[str, object], field: str) -> None:
    args: dict[str, object] = {"n": 10, "dim": 2} | kwargs
    with pytest.raises(InvalidInputError) as caught:
        gas_scenario(**args)  # type: ignore[arg-type]
    assert caught.value.field == field


@pytest.mark.parametrize("dim", [2, 3])
def test_speed_pdf_is_a_density_with_the_right_mean_square(dim: int) -> None:
    v = np.linspace(0.0, 20.0, 200_001)
    f = speed_pdf(v, dim, 1.7)
    assert math.isclose(np.trapezoid(f, v), 1.0, rel_tol=1e-9)
    assert math.isclose(np.trapezoid(v**2 * f, v), dim * 1.7, rel_tol=1e-9)  # <v^2> = dim kT/m


def test_relaxation_to_maxwell_boltzmann() -> None:
    # Equal speeds relax, through collisions alone, to a speed histogram close to the law.
    gas = gas_scenario(4000, 2, seed=3, speeds="equal")
    world = gas.world()
    world.step(gas.dt, 1500)
    speeds = np.linalg.norm(world.velocities, axis=1)
    variance = component_variance(world.velocities)
    counts, edges = np.histogram(speeds, bins=20, range=(0.0, 4.0))
    centres = 0.5 * (edges[1:] + edges[:-1])
    expected = speed_pdf(centres, 2, variance) * len(speeds) * (edges[1] - edges[0])
    assert np.abs(counts - expected).max() < 0.2 * expected.max()
    start = np.histogram(np.linalg.norm(gas.velocities, axis=1), bins=20, range=(0.0, 4.0))[0]
    assert np.abs(start - expected).max() > 2.0 * expected.max()  # far from it at the start
