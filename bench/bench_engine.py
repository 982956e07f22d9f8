#!/usr/bin/env python3
"""The engine's figures for issue "One engine", each run as a whole command, medians of >= 3.

    python3 tasks.py bench-engine            # everything (several minutes)
    python3 tasks.py bench-engine --quick    # fewer steps

1. ``collisionlab run`` on a scenario file of 2,000 spheres on a tilted plane with 20 boxes in
   euler and in exact mode: body-steps per second of the whole command.
2. 100,000 bodies from one ``[[gas]]`` table: bytes per body (the engine's arrays, and the peak
   memory of the process over a bare Python one).
3. Start-up: ``collisionlab demo`` (the lab's four cases) with an empty compile cache, then warm.
4. Memory of a long run that streams: the head-on example for 1,000,000 steps with
   ``--format json --every 1000 --output``: peak RSS.

Every figure is the median of the runs with its min and max. Paste the output into
bench/README.md with the date and the machine.

The incline's figures are absolute, and the machines here are shared: where the reference C
code sits beside the checkout (``shared/peers/edmd``, as for ``bench_edmd.py``), its speed on a
fixed workload is read before and after them (``--no-yardstick``: not), so a run taken while
the machine was loaded can be told from a slower build.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import bench_edmd  # the reference C code's path and runner (this folder is on sys.path when run)

ROOT = Path(__file__).resolve().parent.parent
CLI = [sys.executable, "-m", "collisionlab"]

INCLINE = """
[simulation]
title = "spheres and boxes on an incline"
dt = 0.002
steps = {steps}
restitution = 0.5
gravity = [0, -9.81, 0]
mode = "{mode}"

[[gas]]
name = "ball"
shape = "sphere"
radius = 0.05
region = [[-2, 1, -2], [2, 3, 2]]
count = {balls}
kT = 0.01
seed = 1

[[gas]]
name = "crate"
shape = "aabb"
size = [0.3, 0.3, 0.3]
region = [[-2, 3.2, -2], [2, 4.2, 2]]
count = {boxes}
kT = 0.01
seed = 2

[[static]]
name = "incline"
shape = "plane"
point = [0, 0, 0]
normal = [0.2, 1, 0]
"""

GAS = """
[simulation]
title = "100,000 discs"
dt = 0.01
steps = {steps}

[[gas]]
name = "d"
shape = "circle"
radius = 0.5
region = [[0, 0], [400, 400]]
count = 100000
seed = 1
"""


#: The environment of the commands timed: Python's bytecode is written as on a user's machine
#: (pip compiles it at install; some sandboxes set PYTHONDONTWRITEBYTECODE, and then every
#: start compiles ~50 modules again: about 0.15 s of the incline's command).
USER_ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def timed(command: list[str], env: dict[str, str] | None = None) -> tuple[float, int, str]:
    """Wall seconds, peak RSS in bytes and stderr of one run of ``command``."""
    start = time.perf_counter()
    process = subprocess.Popen(
        command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=USER_ENV if env is None else env, cwd=ROOT
    )
    _, status, usage = os.wait4(process.pid, 0)
    seconds = time.perf_counter() - start
    err = process.stderr.read().decode() if process.stderr else ""
    if status != 0:
        raise SystemExit(f"{' '.join(command)} failed ({status}): {err}")
    return seconds, usage.ru_maxrss * 1024, err


def spread(values: list[float], fmt: str = "{:.3g}") -> str:
    return f"{fmt.format(statistics.median(values))} (min {fmt.format(min(values))}, max {fmt.format(max(values))})"


def yardstick() -> str:
    """The machine's speed of the moment: the reference C code's collisions per second on a fixed
    workload (4,000 spheres at packing fraction 0.25 to time 10; 490-500 k on a quiet machine
    here, bench/README.md), or why it was not read."""
    if not bench_edmd.PEER.exists():
        return "not read (no shared/peers/edmd beside the checkout)"
    try:
        return f"{bench_edmd.peer(4000, 0.25, 10.0)['collisions_per_s'] / 1e3:,.0f} k collisions/s"
    except (OSError, subprocess.CalledProcessError, ValueError, KeyError) as error:
        return f"not read ({type(error).__name__})"


def incline(runs: int, plan: dict[str, tuple[int, int, int]], folder: Path, machine: bool = True) -> None:
    """The whole command, with the lab's table (``--quiet``: every collision and the velocity
    after it) and with JSON (every collision's working, every number in full); with ``machine``,
    the :func:`yardstick` before and after."""
    print("1. collisionlab run: spheres and boxes on a tilted plane")
    if machine:
        print(f"   the machine before: the reference C code, {yardstick()}")
    for mode, (balls, boxes, count) in plan.items():
        path = folder / f"incline-{mode}.toml"
        path.write_text(INCLINE.format(steps=count, mode=mode, balls=balls, boxes=boxes))
        for fmt in ("table", "json"):
            command = [*CLI, "run", str(path), "--quiet", "--every", str(count), "--format", fmt]
            command += ["--output", str(folder / f"out.{fmt}")]
            timed(command)  # warm-up: the compile cache
            bodies = balls + boxes
            rates = [bodies * count / timed(command)[0] for _ in range(runs)]
            print(
                f"   {mode:5s} {fmt:5s} {bodies:5d} bodies, {count:5d} steps: "
                f"{spread(rates, '{:,.0f}')} body-steps/s (command)"
            )
    if machine:
        print(f"   the machine after: the reference C code, {yardstick()}")


def gas_memory(runs: int, folder: Path) -> None:
    print("2. 100,000 discs from one [[gas]] table")
    path = folder / "gas.toml"
    path.write_text(GAS.format(steps=10))
    probe = (
        "import resource, sys\n"
        "from collisionlab.scenario_file import load_scenario\n"
        "from collisionlab.engine.world import World\n"
        "w = World(load_scenario(sys.argv[1]))\n"
        "w.step(10)\n"
        "arrays = w.nbytes()\n"
        "print(arrays)\n"
    )
    bare = [timed([sys.executable, "-c", "import collisionlab.engine.world"])[1] for _ in range(runs)]
    peaks, arrays = [], []
    for _ in range(runs):
        out = subprocess.run(
            [sys.executable, "-c", probe, str(path)], capture_output=True, text=True, check=True, env=USER_ENV
        )
        arrays.append(int(out.stdout.strip()) / 100_000)
        peaks.append((timed([sys.executable, "-c", probe, str(path)])[1] - statistics.median(bare)) / 100_000)
    print(f"   engine arrays: {spread(arrays, '{:.0f}')} B/body")
    print(f"   peak RSS over a bare import (the scenario's arrays included): {spread(peaks, '{:.0f}')} B/body")


def start_up(runs: int) -> None:
    print("3. collisionlab demo (the lab's four cases)")
    cold = []
    for _ in range(runs):
        with tempfile.TemporaryDirectory() as cache:
            cold.append(timed([*CLI, "demo"], {**USER_ENV, "NUMBA_CACHE_DIR": cache})[0])
    warm = [timed([*CLI, "demo"])[0] for _ in range(runs)]
    print(f"   empty compile cache: {spread(cold)} s; warm: {spread(warm)} s")


def long_run(runs: int, steps: int, folder: Path) -> None:
    print(f"4. head-on example, {steps:,} steps, --format json --every 1000 --output")
    out = folder / "f.json"
    command = [*CLI, "run", "examples/head-on.toml", "--steps", str(steps), "--format", "json"]
    command += ["--every", "1000", "--output", str(out)]
    results = [timed(command) for _ in range(runs)]
    print(f"   wall {spread([r[0] for r in results])} s, peak RSS {spread([r[1] / 2**20 for r in results])} MB")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="fewer steps (a smoke run)")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--only", choices=("incline", "memory", "startup", "long"), help="one part only")
    parser.add_argument("--no-yardstick", action="store_true", help="do not time the reference C code around part 1")
    args = parser.parse_args()
    parts = {args.only} if args.only else {"incline", "memory", "startup", "long"}
    print(f"python {sys.version.split()[0]}, {os.cpu_count()} cores, {time.strftime('%Y-%m-%d')}")
    with tempfile.TemporaryDirectory() as folder:
        where = Path(folder)
        # The same 2,020 bodies in both modes (the exact stepper runs on the engine's arrays).
        count = 200 if args.quick else 2000
        if "incline" in parts:
            plan = {"euler": (2000, 20, count), "exact": (2000, 20, count)}
            incline(args.runs, plan, where, machine=not args.no_yardstick)
        if "memory" in parts:
            gas_memory(args.runs, where)
        if "startup" in parts:
            start_up(args.runs)
        if "long" in parts:
            long_run(args.runs, 10_000 if args.quick else 1_000_000, where)
    print(f"(children's peak: {resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024:.0f} MB)")


if __name__ == "__main__":
    main()
