"""The equation of state of the event-driven gas against theory: a table and docs/edmd-eos.png.

Periodic box, N = 4,000, relaxed from the lattice for 2 time units, then measured over a window
of about 10^6 collisions (the virial route, ``Z = 1 + W / (d N kT t)``). Theory: Carnahan-Starling
(3D), Henderson (2D).

    python bench/edmd_eos.py            # prints a Markdown table, writes docs/edmd-eos.png
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from collisionlab.edmd import carnahan_starling, enskog_collision_rate, henderson
from collisionlab.edmd.observables import ExactGas

FRACTIONS = {3: (0.05, 0.1, 0.2, 0.3, 0.4, 0.45), 2: (0.05, 0.1, 0.2, 0.3, 0.4, 0.5)}
N = 4000
TARGET_COLLISIONS = 1_000_000


def measure(dim: int, fraction: float) -> tuple[float, float, int]:
    world = ExactGas(n=N, dim=dim, fraction=fraction, boundary="periodic", seed=0).world()
    world.run(2.0)
    a = world.tally()
    rate = enskog_collision_rate(fraction, dim, 1.0, 1.0, 1.0)
    window = 2.0 * TARGET_COLLISIONS / (N * rate)
    world.run(2.0 + window)
    b = world.tally()
    kt = 2.0 * world.kinetic_energy() / (dim * N)
    z = 1.0 + (b.virial - a.virial) / (dim * N * kt * window)
    return z, 2.0 * (b.pair_collisions - a.pair_collisions) / (N * window), b.pair_collisions - a.pair_collisions


def main() -> None:
    rows = []
    print("| dim | fraction | collisions | Z measured | Z theory | difference | rate measured | rate Enskog |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|")
    for dim, fractions in FRACTIONS.items():
        for eta in fractions:
            z, rate, count = measure(dim, eta)
            theory = carnahan_starling(eta) if dim == 3 else henderson(eta)
            enskog = enskog_collision_rate(eta, dim, 1.0, 1.0, 1.0)
            rows.append((dim, eta, z, theory))
            print(
                f"| {dim}D | {eta} | {count:,} | {z:.4f} | {theory:.4f} | {100 * (z / theory - 1):+.2f}% "
                f"| {rate:.4f} | {enskog:.4f} |",
                flush=True,
            )
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    grid = np.linspace(0.0, 0.52, 200)
    ax.plot(grid, [carnahan_starling(x) for x in grid], "C0-", label="Carnahan-Starling (3D)")
    ax.plot(grid, [henderson(x) for x in grid], "C1-", label="Henderson (2D)")
    for dim, marker, colour in ((3, "o", "C0"), (2, "s", "C1")):
        pts = [(eta, z) for d, eta, z, _ in rows if d == dim]
        ax.plot(*zip(*pts, strict=True), marker, color=colour, mfc="none", label=f"collisionlab edmd, {dim}D, N = {N}")
    ax.set_xlabel("packing fraction")
    ax.set_ylabel("Z = PV / (N kT)")
    ax.set_title("Hard spheres and discs: equation of state")
    ax.legend()
    fig.tight_layout()
    out = Path(__file__).resolve().parents[1] / "docs" / "edmd-eos.png"
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
