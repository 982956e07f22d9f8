"""A mixture's own fields of an exact gas's report (:mod:`.observables` makes the rest): each
species' count, radius, mass and kT, each ordered pair of species' collision rate beside
Enskog's (:func:`.theory.enskog_pair_rates`), and the mixture's compressibility in theory
(:func:`.theory.mixture_compressibility`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .exact_gas import ExactGas
from .theory import enskog_pair_rates, mixture_compressibility
from .world import EventDrivenWorld

__all__ = ["species_report"]


def species_report(gas: ExactGas, world: EventDrivenWorld, kt: float) -> dict[str, Any]:
    """A mixture's own fields of the report: ``compressibility_theory`` and
    ``collision_rate_enskog`` for the mixture (elastic, no gravity; else ``None``), ``species``
    (each one's name, count, radius, mass and kT) and ``pair_collision_rates`` (per ordered pair
    ``(a, b)``: the collisions between the two species, ``rate`` = how often one ball of ``a``
    hits a ball of ``b`` per unit time, and Enskog's ``rate_enskog``). A species' ``kT`` is
    ``2 <E_a> / (d N_a)``, ``<E_a>`` its kinetic energy averaged over the run (exact: it changes
    only at collisions), or under gravity the end's."""
    kinds, _, _, counts = gas.mixture()
    if gas.gravity == 0.0:  # averaged over the run (a snapshot of N_a balls scatters by sqrt(2 / (d N_a)))
        energies = world.species_mean_energy().tolist()
    else:  # the energy changes between collisions too: the end's
        velocities = world.velocities
        energy = 0.5 * world.masses * np.einsum("ij,ij->i", velocities, velocities)
        energies = [float(energy[kinds == k].sum()) for k in range(len(counts))]
    t = world.time
    tally = world.tally()
    dim = gas.dim
    fractions = [count / gas.n for count in counts]
    diameters = [2.0 * sp.radius for sp in gas.species]
    species_masses = [sp.mass_in(dim) for sp in gas.species]
    elastic_gas = gas.restitution == 1.0 and gas.gravity == 0.0
    rates = enskog_pair_rates(fractions, diameters, species_masses, gas.fraction, dim, kt) if elastic_gas else None
    pairs = []
    for a, first in enumerate(gas.species):
        for b, second in enumerate(gas.species):
            # a ball of a in a collision with a ball of b (counted for each of a's: twice if a = b)
            hits = tally.species_collisions[a][b]
            pairs.append(
                {
                    "species": [first.name, second.name],
                    "collisions": hits // 2 if a == b else hits,
                    "rate": hits / (counts[a] * t) if t > 0 else 0.0,
                    "rate_enskog": rates[a][b] if rates is not None else None,
                }
            )
    return {
        "compressibility_theory": mixture_compressibility(fractions, diameters, gas.fraction, dim)
        if elastic_gas
        else None,
        "collision_rate_enskog": sum(x * sum(row) for x, row in zip(fractions, rates, strict=True))
        if rates is not None
        else None,
        "bytes_per_body": world.nbytes / gas.n,
        "species": [
            {
                "name": sp.name,
                "count": count,
                "radius": sp.radius,
                "mass": sp.mass_in(dim),
                "kT": 2.0 * energies[k] / (dim * count),
            }
            for k, (sp, count) in enumerate(zip(gas.species, counts, strict=True))
        ],
        "pair_collision_rates": pairs,
    }
