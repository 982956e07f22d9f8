"""Sweeps on dask.distributed: the speed-up of two local workers over one, and the overhead per point.

1. Scaling: a 40-point sweep of the lab's case 4 (``sphere-plane``, Forward Euler) whose number of
   steps is calibrated on this machine so that one point takes about 1 second, run on a local
   cluster of 1 worker and of 2 workers. Target: 2 workers take <= 0.6x the time of 1.
2. Overhead: 1,000 trivial points (the same scenario, 1 step: about 0.2 ms of simulation) on 2
   local workers; the time per point of the whole sweep (submission, scheduling, the result's
   trip back, the row appended to the CSV and the Parquet snapshots). Target: < 20 ms.

Each figure is the median of ``--runs`` runs (default 3), with the spread (min-max), and the load
average after each run (on a shared machine, other work takes cores from the workers). The time is
that of :func:`collisionlab.sweep.runner.run_sweep` (the cluster already up, as on a cluster one
reuses); the cluster's start-up is reported beside it.

    python bench/bench_sweep.py               # both (about 6 minutes)
    python bench/bench_sweep.py --runs 5
    python bench/bench_sweep.py --only overhead

Not a test: it prints numbers (recorded in bench/README.md).
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import tempfile
import time
import tomllib
from pathlib import Path

import dask
import distributed

from collisionlab.demos import load_demo
from collisionlab.sweep.runner import dask_client, run_sweep, table_columns
from collisionlab.sweep.spec import SweepSpec, parse_sweep
from collisionlab.sweep.store import ResultStore
from collisionlab.world import simulate

POINT_SECONDS = 1.0


def spec_for(points: int, steps: int) -> SweepSpec:
    text = f"""
[sweep]
demo = "sphere-plane"
metrics = ["collisions", "wall_time"]
[sweep.parameters]
"simulation.dt" = {{start = 0.001, stop = 0.002, num = {points}}}
"simulation.steps" = [{steps}]
"""
    return parse_sweep(tomllib.loads(text), "bench")


def calibrate_steps() -> int:
    """Steps of the lab's case 4 that take about ``POINT_SECONDS`` here (median of 3 timings)."""
    probe = 2000
    scenario = load_demo("sphere-plane").with_settings(steps=probe, dt=0.001)
    times = []
    for _ in range(3):
        began = time.perf_counter()
        simulate(scenario)
        times.append(time.perf_counter() - began)
    return round(probe * POINT_SECONDS / statistics.median(times))


def timed_sweep(spec: SweepSpec, workers: int) -> tuple[float, float, list[float]]:
    """(seconds of the sweep, seconds to start the cluster, each row's wall_time)."""
    with tempfile.TemporaryDirectory() as folder:
        store = ResultStore(Path(folder) / "t", table_columns(spec))
        store.start(resume=False)
        began = time.perf_counter()
        with dask_client(None, workers) as client:
            client.wait_for_workers(workers)
            started = time.perf_counter() - began
            outcome = run_sweep(spec, store, client)
        assert outcome.written == len(spec.tasks()) and outcome.errors == 0
        return outcome.seconds, started, [float(row["wall_time"]) for row in store.rows.values()]


def spread(values: list[float]) -> str:
    return f"median {statistics.median(values):.3f} (min {min(values):.3f}, max {max(values):.3f}; n = {len(values)})"


def scaling(runs: int) -> None:
    steps = calibrate_steps()
    spec = spec_for(40, steps)
    print(f"scaling: 40 points of the lab's case 4, {steps} steps each (about {POINT_SECONDS} s here)")
    results: dict[int, list[float]] = {1: [], 2: []}
    for run in range(runs):
        for workers in (1, 2):
            seconds, started, walls = timed_sweep(spec, workers)
            results[workers].append(seconds)
            print(
                f"  run {run + 1}, {workers} worker{'s' if workers > 1 else ' '}: {seconds:7.2f} s "
                f"(cluster start {started:.2f} s; a point's own time {statistics.median(walls):.3f} s median; "
                f"load average {os.getloadavg()[0]:.1f})",
                flush=True,
            )
    one, two = statistics.median(results[1]), statistics.median(results[2])
    ratios = [b / a for a, b in zip(results[1], results[2], strict=True)]
    print(f"  1 worker : {spread(results[1])} s")
    print(f"  2 workers: {spread(results[2])} s")
    print(
        f"  ratio 2/1: {two / one:.3f} of the medians; per run {', '.join(f'{r:.3f}' for r in ratios)} (target <= 0.6)"
    )


def overhead(runs: int) -> None:
    spec = spec_for(1000, 1)
    per_point = []
    print("overhead: 1,000 points of 1 step each, 2 local workers")
    for run in range(runs):
        seconds, started, walls = timed_sweep(spec, 2)
        per_point.append(seconds)  # s per 1,000 points = ms per point
        print(
            f"  run {run + 1}: {seconds:6.2f} s, {seconds:.3f} ms per point "
            f"(simulation {statistics.median(walls) * 1000:.2f} ms of it; cluster start {started:.2f} s; "
            f"load average {os.getloadavg()[0]:.1f})",
            flush=True,
        )
    print(f"  per point: {spread(per_point)} ms (target < 20 ms)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=3, help="runs of each measurement (median reported)")
    parser.add_argument("--only", choices=("scaling", "overhead"), help="run one of the two")
    args = parser.parse_args()
    print(
        f"{time.strftime('%Y-%m-%d')}, {platform.machine()}, {len(os.sched_getaffinity(0))} cores, "
        f"CPython {platform.python_version()}, dask {dask.__version__}, distributed {distributed.__version__}"
    )
    if args.only in (None, "overhead"):
        overhead(args.runs)
    if args.only in (None, "scaling"):
        scaling(args.runs)


if __name__ == "__main__":
    main()
