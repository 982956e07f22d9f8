"""Event-driven hard spheres: collisionlab's ``edmd`` against F. Smallenburg's C code (the peer).

The same workloads for both: N spheres in a periodic cube, FCC start at packing fraction eta,
Maxwell velocities at kT = 1, run for the same physical time (the peer's unit of length is the
diameter, ours the radius, so our time is twice its number). Each run is a fresh process;
runs of the two engines alternate, and every figure is the median of ``--repeats`` runs with the
spread (min-max). Ours: collisions per second of the simulation loop (``EventDrivenWorld.run``;
set-up and the numba compile excluded, the compile is cached beforehand). The peer: collisions
per second of its whole program as ``run.sh`` times it (its set-up is a small part).

    python3 tasks.py bench-edmd              # everything (about 10 minutes on 2 cores)
    python bench/bench_edmd.py --quick       # N = 4,000 only
    python bench/bench_edmd.py --one '{"dim": 3, "n": 4000, "fraction": 0.25, "time": 20}'
    python bench/bench_edmd.py --mixtures    # a binary mixture: speed against one kind, BMCSL, kT

Not a test: it prints numbers (recorded in bench/README.md).
"""

from __future__ import annotations

import argparse
import json
import platform
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

#: The peer's script: ``shared/peers/edmd/run.sh`` beside the checkout (at whatever depth it sits).
_PEER_SCRIPT = Path("shared", "peers", "edmd", "run.sh")
PEER = next(
    (folder / _PEER_SCRIPT for folder in Path(__file__).resolve().parents if (folder / _PEER_SCRIPT).exists()),
    Path("..") / _PEER_SCRIPT,
)

#: (dim, N, packing fraction, the peer's simulated time (ours is twice it; the peer needs >= 2: it reports once
#: per unit of time), whether the peer runs it too). N 4,000 runs 1.4-1.7 M collisions, about 3 s: runs of
#: 0.3 s spread by a quarter from one process to the next (bench/LOG.md, 2026-11-29).
WORKLOADS: list[tuple[int, int, float, float, bool]] = [
    (3, 4000, 0.25, 100.0, True),
    (3, 4000, 0.45, 30.0, True),
    (3, 32000, 0.25, 2.0, True),
    (3, 32000, 0.45, 2.0, True),
    (2, 10000, 0.25, 10.0, False),
    (2, 10000, 0.45, 5.0, False),
    (3, 10000, 0.25, 2.0, False),
    (3, 1_000_000, 0.25, 2.0, False),
]


def run_ours(spec: dict[str, Any]) -> dict[str, Any]:
    """One run in this process: build, compile (cached), run, report."""
    from collisionlab.edmd.observables import ExactGas, Species

    ExactGas(n=500, dim=spec["dim"], fraction=0.2, boundary="periodic").world().run(0.1)  # load the compiled loop
    rss_before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    began = time.perf_counter()
    species = tuple(Species(*s) for s in spec.get("species", ()))
    world = ExactGas(
        n=spec["n"], dim=spec["dim"], fraction=spec["fraction"], boundary="periodic", species=species
    ).world()
    setup = time.perf_counter() - began
    energy = world.kinetic_energy()
    began = time.perf_counter()
    world.run(spec["time"])
    seconds = time.perf_counter() - began
    tally = world.tally()
    kt = 2.0 * world.kinetic_energy() / (world.dim * world.n)
    return {
        "collisions": tally.pair_collisions,
        "seconds": seconds,
        "setup_seconds": setup,
        "collisions_per_s": tally.pair_collisions / seconds,
        "events_per_collision": tally.events / tally.pair_collisions,
        "z": 1.0 + tally.virial / (world.dim * world.n * kt * tally.time),
        "energy_drift": world.kinetic_energy() / energy - 1.0,
        "bytes_per_body": world.nbytes / world.n,
        "peak_rss_growth_per_body": (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - rss_before) * 1024 / world.n,
    }


#: ``--mixtures``: the issue's binary (radii 1 and 0.5, half of each by number, masses by volume).
BINARY = [["big", 0.5, 1.0], ["small", 0.5, 0.5]]


def mixtures(repeats: int) -> None:
    """A binary mixture against one kind of ball, each in a fresh process, alternating: time per
    collision (medians of ``repeats``); then the issue's check at N = 4,000, fraction 0.3: Z
    against BMCSL, the species' kT (averaged over the run), Enskog's pair rates."""
    from collisionlab.edmd.observables import ExactGas, Species, species_counts
    from collisionlab.edmd.theory import bmcsl, disc_mixture, enskog_pair_rates

    print("| workload | one kind, collisions/s | binary, collisions/s | time per collision, binary / one kind |")
    print("|---|---:|---:|---:|")
    for dim, time_ in ((3, 20.0), (2, 40.0)):
        one, two = [], []
        for _ in range(repeats):
            one.append(ours(dim, 4000, 0.3, time_)["collisions_per_s"])
            two.append(ours(dim, 4000, 0.3, time_, BINARY)["collisions_per_s"])
        ratio = statistics.median(one) / statistics.median(two)
        print(f"| {dim}D N=4,000 eta=0.3 | {spread(one)} | {spread(two)} | {ratio:.2f}x |")
    for dim, window in ((3, 400.0), (2, 600.0)):
        species = tuple(Species(*s) for s in BINARY)
        gas = ExactGas(n=4000, dim=dim, fraction=0.3, boundary="periodic", species=species).checked()
        world = gas.world()
        relax = 5.0
        world.run(relax)
        a, ea = world.tally(), world.species_mean_energy() * relax
        world.run(relax + window)
        b, eb = world.tally(), world.species_mean_energy() * (relax + window)
        counts = species_counts(gas.species, gas.n)
        kts = [2.0 * (eb[k] - ea[k]) / window / (dim * counts[k]) for k in range(2)]
        kt = sum(c * k for c, k in zip(counts, kts, strict=True)) / gas.n
        z = 1.0 + (b.virial - a.virial) / (dim * gas.n * kt * window)
        x = [c / gas.n for c in counts]
        theory = bmcsl(x, [2.0, 1.0], 0.3) if dim == 3 else disc_mixture(x, [2.0, 1.0], 0.3)
        masses = [sp.mass_in(dim) for sp in species]
        enskog = enskog_pair_rates(x, [2.0, 1.0], masses, 0.3, dim, kt)
        hits = [[b.species_collisions[i][j] - a.species_collisions[i][j] for j in range(2)] for i in range(2)]
        rates = " ".join(
            f"{gas.species[i].name}->{gas.species[j].name} {hits[i][j] / (counts[i] * window) / enskog[i][j] - 1:+.2%}"
            for i in range(2)
            for j in range(2)
        )
        print(
            f"{dim}D binary, N = 4,000, eta 0.3, window {window:g}: Z {z:.5f}, theory {theory:.5f} "
            f"({z / theory - 1:+.3%}); kT big {kts[0]:.5f}, small {kts[1]:.5f} ({kts[1] / kts[0] - 1:+.3%}); "
            f"pair rates against Enskog: {rates}; {b.pair_collisions - a.pair_collisions:,} collisions"
        )


def ours(dim: int, n: int, fraction: float, time_: float, species: list[list[Any]] | None = None) -> dict[str, Any]:
    spec = json.dumps({"dim": dim, "n": n, "fraction": fraction, "time": time_, "species": species or []})
    out = subprocess.run([sys.executable, __file__, "--one", spec], capture_output=True, text=True, check=True)
    return dict(json.loads(out.stdout.strip().splitlines()[-1]))


def peer(n: int, fraction: float, time_: float) -> dict[str, Any]:
    out = subprocess.run(
        ["bash", str(PEER), str(n), str(fraction), str(time_)], capture_output=True, text=True, check=True
    )
    result = dict(json.loads(out.stdout.strip().splitlines()[-1]))
    result["z"] = result["pressure"] / (6.0 * fraction / 3.141592653589793)
    return result


def spread(values: list[float]) -> str:
    return f"{statistics.median(values) / 1e3:,.0f} k ({min(values) / 1e3:,.0f}-{max(values) / 1e3:,.0f})"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="N = 4,000 only")
    parser.add_argument("--no-peer", action="store_true", help="ours only")
    parser.add_argument("--mixtures", action="store_true", help="a binary mixture against one kind of ball")
    parser.add_argument("--one", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one:
        print(json.dumps(run_ours(json.loads(args.one))))
        return
    if args.mixtures:
        mixtures(args.repeats)
        return
    workloads = [w for w in WORKLOADS if w[1] == 4000] if args.quick else WORKLOADS
    with_peer = not args.no_peer and PEER.exists()
    when = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    print(f"# {when}, {platform.machine()}, Python {platform.python_version()}")
    results: dict[tuple[int, int, float], dict[str, list[dict[str, Any]]]] = {}
    for _ in range(args.repeats):
        for dim, n, fraction, peer_time, compare in workloads:
            slot = results.setdefault((dim, n, fraction), {"ours": [], "peer": []})
            slot["ours"].append(ours(dim, n, fraction, 2.0 * peer_time))
            if compare and with_peer:
                slot["peer"].append(peer(n, fraction, peer_time))
            print(".", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    print(
        "| workload | collisions/run | ours, collisions/s | peer (C), collisions/s | ours / peer "
        "| Z ours | Z peer | B/body |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for (dim, n, fraction), slot in results.items():
        mine = [r["collisions_per_s"] for r in slot["ours"]]
        theirs = [r["collisions_per_s"] for r in slot["peer"]]
        ratio = f"{statistics.median(mine) / statistics.median(theirs):.2f}x" if theirs else "-"
        z_peer = f"{statistics.median(r['z'] for r in slot['peer']):.4f}" if theirs else "-"
        print(
            f"| {dim}D N={n:,} eta={fraction} | {statistics.median(r['collisions'] for r in slot['ours']):,.0f} "
            f"| {spread(mine)} | {spread(theirs) if theirs else '-'} | {ratio} "
            f"| {statistics.median(r['z'] for r in slot['ours']):.4f} | {z_peer} "
            f"| {statistics.median(r['bytes_per_body'] for r in slot['ours']):.0f} "
            f"(RSS {statistics.median(r['peak_rss_growth_per_body'] for r in slot['ours']):.0f}) |"
        )


if __name__ == "__main__":
    main()
