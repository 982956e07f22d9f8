"""Long checks of the event-driven engine, too slow for the test suite (``python3 tasks.py edmd-long``).

1. Energy: 4,000 spheres at packing 0.35, periodic, e = 1, run until 10^7 collisions; prints
   the relative change of kinetic energy (the issue asks for < 1e-12) and the deepest overlap.
2. Heap: 1,000 balls dropped from a lattice filling a cube (fraction 0.05) with g = 1, e = 0.7,
   TC model t_c = 0.01; prints kinetic energy per ball, the highest centre and overlap as time
   goes on, and the wall-clock time it took.
"""

from __future__ import annotations

import time

from collisionlab.edmd.observables import ExactGas


def energy() -> None:
    world = ExactGas(n=4000, dim=3, fraction=0.35, boundary="periodic", seed=5).world()
    e0 = world.kinetic_energy()
    began = time.perf_counter()
    t = 0.0
    while world.tally().pair_collisions < 10_000_000:
        t += 50.0
        world.run(t)
    drift = world.kinetic_energy() / e0 - 1.0
    tally = world.tally()
    overlap = max(tally.max_contact_overlap, world.max_overlap()) / 2.0
    print(
        f"energy: {tally.pair_collisions:,} collisions to t = {t:g} in {time.perf_counter() - began:.1f} s; "
        f"relative energy change {drift:.3e}; deepest overlap {overlap:.2e} diameters"
    )


def heap() -> None:
    world = ExactGas(n=1000, dim=3, fraction=0.05, boundary="walls", restitution=0.7, gravity=1.0).world()
    began = time.perf_counter()
    for t in (10, 20, 40, 60, 100, 150, 200):
        world.run(float(t))
        y = world.positions[:, 1]
        tally = world.tally()
        overlap = max(tally.max_contact_overlap, world.max_overlap()) / 2.0
        print(
            f"heap: t = {t:4d}  kinetic/ball {world.kinetic_energy() / world.n:.3e}  highest centre {y.max():6.3f}  "
            f"mean {y.mean():.3f}  events {tally.events:,}  overlap {overlap:.1e} diameters  "
            f"wall clock {time.perf_counter() - began:.1f} s"
        )


if __name__ == "__main__":
    heap()
    energy()
