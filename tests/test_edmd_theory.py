"""Equations of state and collision rates of the event-driven gas, against the literature.

Oracles: Carnahan and Starling, J. Chem. Phys. 51, 635 (1969) in 3D; Henderson, Mol. Phys.
30, 971 (1975) in 2D; Enskog's collision frequency with the contact value of each. Each run
starts from a lattice, is let relax, and then measures over a window (the virial route,
``Z = 1 + W / (d N kT t)``). Statistical scatter at these lengths, seen over seeds 0-2: about
0.2% at fraction 0.4 (3D) and 0.3 (2D), so 0.5% is a real test, not a formality.
"""

from __future__ import annotations

import math

import pytest

from collisionlab.edmd import EventDrivenWorld, carnahan_starling, enskog_collision_rate, henderson
from collisionlab.edmd.observables import ExactGas


def test_equations_of_state_by_hand() -> None:
    # CS at 0.4: (1 + .4 + .16 - .064) / .6^3 = 1.496 / 0.216 = 6.925926
    assert carnahan_starling(0.4) == pytest.approx(1.496 / 0.216, rel=1e-14)
    # Henderson at 0.3: (1 + 0.09/8) / 0.49 = 1.01125 / 0.49 = 2.0637755
    assert henderson(0.3) == pytest.approx(1.01125 / 0.49, rel=1e-14)
    # Enskog, 3D, eta = 0.4, r = 1: n = 0.4 / (4 pi/3), g = 0.8 / 0.216, rate = 4 sqrt(pi) n 4 g
    n = 0.4 / (4.0 * math.pi / 3.0)
    assert enskog_collision_rate(0.4, 3, 1.0, 1.0, 1.0) == pytest.approx(16.0 * math.sqrt(math.pi) * n * 0.8 / 0.216)


def _measure(dim: int, fraction: float, n: int, relax: float, window: float) -> tuple[float, float, float]:
    world: EventDrivenWorld = ExactGas(n=n, dim=dim, fraction=fraction, boundary="periodic", seed=0).world()
    world.run(relax)
    a = world.tally()
    world.run(relax + window)
    b = world.tally()
    kt = 2.0 * world.kinetic_energy() / (dim * n)
    z = 1.0 + (b.virial - a.virial) / (dim * n * kt * window)
    rate = 2.0 * (b.pair_collisions - a.pair_collisions) / (n * window)
    overlap = max(b.max_contact_overlap, world.max_overlap()) / 2.0
    return z, rate, overlap


@pytest.mark.parametrize(
    ("dim", "fraction", "window"),
    [(3, 0.2, 40.0), (3, 0.3, 30.0), (3, 0.4, 30.0), (2, 0.2, 60.0), (2, 0.3, 100.0)],
)
def test_compressibility_and_collision_rate_match_theory(dim: int, fraction: float, window: float) -> None:
    z, rate, overlap = _measure(dim, fraction, 4000, 2.0, window)
    theory = carnahan_starling(fraction) if dim == 3 else henderson(fraction)
    assert z == pytest.approx(theory, rel=0.005)
    # Enskog's rate with g(sigma) from the same equation of state: Z - 1 = 4 eta g (3D), 2 eta g (2D)
    assert rate == pytest.approx(enskog_collision_rate(fraction, dim, 1.0, 1.0, 1.0), rel=0.01)
    assert overlap < 1e-9


def test_an_ideal_gas_has_z_one() -> None:
    # fraction 0.001: Z = 1 + 4 eta + ... = 1.004 (CS), measured to within 0.5%
    z, _, _ = _measure(3, 0.001, 500, 0.0, 50.0)
    assert z == pytest.approx(carnahan_starling(0.001), rel=0.005)
