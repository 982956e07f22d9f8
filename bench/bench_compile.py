"""Where the compile of the kernels goes: each kind of kernels compiled alone from an empty
numba cache, in a process of its own, with numba's own accounts of it, and then the whole
``collisionlab compile`` (the kinds side by side) from an empty cache.

    python3 tasks.py bench-compile            # or: python bench/bench_compile.py [--runs N] [--kinds K,K]

Per kind: the wall time of ``load_kernels(kind)`` and the process's peak RSS; numba's
``numba:compile`` events give each function its own time (less the functions compiled inside
it), and its compiler's records (each compiled function's ``pipeline_times``, and LLVM's pass
timings, ``NUMBA_LLVM_PASS_TIMINGS=1``, which cost a few per cent) split the kind's time in three:

- *LLVM*: LLVM's passes and machine code, for each function and for every callee linked into
  its module (numba links each callee's IR into its caller's module and optimizes it again
  there);
- *inlining*: numba's inlining of the ``INLINE`` helpers (each site reads the helper's bytecode
  again);
- *numba*: the rest: numba's typing and its translation into LLVM IR (in Python), its other
  passes, the imports and the cache's files. (numba's other passes are not split out: some
  compile functions inside them, so their records overlap.)

The kinds share helpers, so a kind alone compiles some of what another compiles too: the
whole command (the kinds side by side, each helper compiled once if its cache file is
written before the other kind asks) takes less than their sum.

Medians of ``--runs`` runs with the spread (min-max). The numbers are the machine's; bench/README.md
and bench/LOG.md hold them with date and load. Nothing here is a test.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

KINDS = ("exact", "solve", "event-driven", "euler", "particles")
STAGES = ("numba", "inlining", "LLVM")


def _child(kind: str) -> None:
    """Compile ``kind`` in this process (the cache is empty) and print its accounts as JSON."""
    from numba.core import event

    spans: list[tuple[Any, float, float]] = []
    open_at: list[float] = []

    class Compiles(event.Listener):
        def on_start(self, ev: Any) -> None:
            open_at.append(time.perf_counter())

        def on_end(self, ev: Any) -> None:
            spans.append((ev.data["dispatcher"], open_at.pop(), time.perf_counter()))

    event.register("numba:compile", Compiles())  # type: ignore[no-untyped-call]
    from collisionlab.engine.ahead import load_kernels

    started = time.perf_counter()
    load_kernels(kind)
    wall = time.perf_counter() - started

    spans.sort(key=lambda span: span[1])
    own: dict[str, float] = {}
    for dispatcher, start, end in spans:
        inner: list[tuple[float, float]] = []  # the compiles directly inside this one
        for _, s2, e2 in spans:
            if s2 > start and e2 < end and (not inner or s2 > inner[-1][1]):
                inner.append((s2, e2))
        module = dispatcher.py_func.__module__.rpartition("._compiled_")[2].rpartition(".")[2]
        name = f"{module}.{dispatcher.py_func.__qualname__}"
        own[name] = own.get(name, 0.0) + (end - start) - sum(e2 - s2 for s2, e2 in inner)
    # Each compiled function's records, read once: its inlining pass (it compiles nothing inside)
    # and LLVM's passes on its own module (a library's passes never contain another's).
    stages = {"inlining": 0.0, "LLVM": 0.0}
    for dispatcher in {id(span[0]): span[0] for span in spans}.values():
        for result in dispatcher.overloads.values():
            for table in result.metadata.get("pipeline_times", {}).values():
                for name, timing in table.items():
                    if name.endswith("_inline_inlinables"):
                        stages["inlining"] += timing.init + timing.run + timing.finalize
            for record in result.metadata.get("llvm_pass_timings") or ():
                stages["LLVM"] += record.timings.get_total_time()
    stages["numba"] = wall - stages["inlining"] - stages["LLVM"]
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(
        json.dumps(
            {"wall": wall, "peak_mb": peak, "stages": stages, "own": sorted(own.items(), key=lambda item: -item[1])[:8]}
        )
    )


def _run_kind(kind: str, cache: Path) -> dict[str, Any]:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), NUMBA_LLVM_PASS_TIMINGS="1")
    out = subprocess.run(
        [sys.executable, "-W", "ignore", __file__, "--child", kind], env=env, capture_output=True, text=True, check=True
    )
    result: dict[str, Any] = json.loads(out.stdout.strip().splitlines()[-1])
    return result


def _whole(cache: Path) -> float:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    started = time.perf_counter()
    subprocess.run(
        [sys.executable, "-W", "ignore", "-m", "collisionlab", "compile"], env=env, capture_output=True, check=True
    )
    return time.perf_counter() - started


def _spread(values: list[float], digits: int = 1) -> str:
    return f"{statistics.median(values):.{digits}f} ({min(values):.{digits}f}-{max(values):.{digits}f})"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="runs of each measurement (default 3)")
    parser.add_argument("--kinds", default=",".join(KINDS), help=f"kinds to compile alone (default {','.join(KINDS)})")
    parser.add_argument("--no-whole", action="store_true", help="leave out the whole `collisionlab compile`")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        _child(args.child)
        return
    kinds = [k for k in args.kinds.split(",") if k]
    unknown = sorted(set(kinds) - set(KINDS))
    if unknown or args.runs < 1:
        parser.error(f"--kinds: each one of {', '.join(KINDS)}; --runs: at least 1 (got {unknown or args.runs})")
    results: dict[str, list[dict[str, Any]]] = {k: [] for k in kinds}
    wholes: list[float] = []
    for run in range(args.runs):
        for kind in kinds:
            with tempfile.TemporaryDirectory() as cache:
                results[kind].append(_run_kind(kind, Path(cache)))
            print(f"run {run + 1}, {kind}: {results[kind][-1]['wall']:.1f} s", file=sys.stderr, flush=True)
        if not args.no_whole:
            with tempfile.TemporaryDirectory() as cache:
                wholes.append(_whole(Path(cache)))
            print(f"run {run + 1}, collisionlab compile: {wholes[-1]:.1f} s", file=sys.stderr, flush=True)

    print(f"Each kind alone from an empty cache, medians of {args.runs} (min-max), seconds:")
    print(f"| kind | wall | peak RSS, MB | {' | '.join(STAGES)} |")
    print(f"|---|---|---|{'---|' * len(STAGES)}")
    for kind, rows in results.items():
        cells = [_spread([r["stages"].get(s, 0.0) for r in rows]) for s in STAGES]
        peak = _spread([r["peak_mb"] for r in rows], 0)
        print(f"| {kind} | {_spread([r['wall'] for r in rows])} | {peak} | {' | '.join(cells)} |")
    if wholes:
        print(f"`collisionlab compile` (the kinds side by side), empty cache: {_spread(wholes)} s")
    print("Each kind's functions taking most of its compile (own seconds, the last run):")
    for kind, rows in results.items():
        top = ", ".join(f"{name} {seconds:.1f}" for name, seconds in rows[-1]["own"][:6])
        print(f"  {kind}: {top}")


if __name__ == "__main__":
    main()
