#!/usr/bin/env python3
"""Set up and run collisionlab with nothing but Python 3.11 and pip (``make`` is optional).

    python3 tasks.py run     # a virtual environment in .venv, every kernel compiled, then the lab's four demos
    python3 tasks.py test    # the same with the test tools, then ruff, mypy, the docs site and pytest
    python3 tasks.py bench   # the many-body benchmark against pymunk and pybullet (bench/README.md)
    python3 tasks.py bench-engine   # the engine's figures: a 2,020-body scenario, memory, start-up
    python3 tasks.py bench-piles    # circles poured into a box: the contact solver against pymunk
    python3 tasks.py bench-piles-3d # spheres poured into a walled box: the contact solver against pybullet
    python3 tasks.py bench-edmd     # the event-driven engine against the reference C code
    python3 tasks.py edmd-long      # 10^7 elastic collisions; 1,000 balls coming to rest
    python3 tasks.py bench-sweep    # sweeps on Dask: 2 workers against 1, overhead per point
    python3 tasks.py bench-compile  # each kind of kernels compiled alone from an empty cache, and where it goes
    python3 tasks.py fuzz           # every input surface at 100,000 inputs, counts by outcome

Each step is printed before it runs; the first failure stops with its exit status.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent
VENV = ROOT / ".venv"
BIN = VENV / ("Scripts" if os.name == "nt" else "bin")
PYTHON = BIN / ("python.exe" if os.name == "nt" else "python")
STAMP = VENV / ".installed"
#: apt-get's exit status when another apt or dpkg process holds the lock.
APT_LOCKED = 100
#: How often and how long to wait for that lock before giving up (10 minutes in all).
LOCK_ATTEMPTS = 60
LOCK_WAIT_SECONDS = 10.0


def sh(*command: str | Path) -> None:
    """Run ``command`` in the project's folder, then say how long it took (CI's log then shows
    where its minutes go); exit with its status if it failed."""
    words = [str(word) for word in command]
    print("+", " ".join(words), flush=True)
    start = time.monotonic()
    result = subprocess.run(words, cwd=ROOT, check=False)
    print(f"+ ({time.monotonic() - start:.0f} s)", flush=True)
    if result.returncode != 0:
        sys.exit(result.returncode)


def sh_waiting_for_apt(*command: str | Path) -> None:
    """``sh(command)``, run again while it fails because another apt process holds the dpkg
    lock (status 100), up to ``LOCK_ATTEMPTS`` times ``LOCK_WAIT_SECONDS`` apart."""
    for attempt in range(1, LOCK_ATTEMPTS + 1):
        try:
            sh(*command)
            return
        except SystemExit as stop:
            if stop.code != APT_LOCKED or attempt == LOCK_ATTEMPTS:
                raise
        print(f"(apt is busy: waiting {LOCK_WAIT_SECONDS:g} s for its lock, then again)", flush=True)
        time.sleep(LOCK_WAIT_SECONDS)


def setup(*extras: str) -> None:
    """Create .venv and install the package with ``extras``, unless that is already done and
    pyproject.toml has not changed since."""
    wanted = set(extras)
    done = set(STAMP.read_text().split()) if STAMP.exists() else None
    fresh = done is not None and STAMP.stat().st_mtime >= (ROOT / "pyproject.toml").stat().st_mtime
    if fresh and done is not None and wanted <= done:
        return
    if not PYTHON.exists():
        sh(sys.executable, "-m", "venv", VENV)
        sh(PYTHON, "-m", "pip", "install", "--quiet", "--upgrade", "pip")
    target = f".[{','.join(sorted(wanted))}]" if wanted else "."
    sh(PYTHON, "-m", "pip", "install", "--quiet", "-e", target)
    STAMP.write_text(" ".join(sorted(wanted | (done if fresh and done else set()))) + "\n")


def run() -> None:
    setup("all")  # the sweeps' and the interactive page's extras too: the README's commands all work
    sh(BIN / "collisionlab", "compile")  # every kernel now (once per machine), so no run waits for it
    sh(BIN / "collisionlab", "demo")


def test() -> None:
    setup("all", "dev")
    sh(BIN / "ruff", "check", "src", "tests", "bench", "tasks.py")
    sh(BIN / "ruff", "format", "--check", "src", "tests", "bench", "tasks.py")
    sh(BIN / "mypy")
    sh(BIN / "mkdocs", "build", "--strict", "--quiet")  # the API reference; a warning fails it
    sh_waiting_for_apt("bash", "tests/setup_browser.sh")  # Debian's chromium for the browser test
    # pytest-xdist: one worker per core; the slowest setups show what compiling the kernels took
    sh(PYTHON, "-m", "pytest", "-n", "auto", "--durations=12")


def bench() -> None:
    setup("dev", "bench")
    sh(PYTHON, "bench/bench_gas.py", *sys.argv[2:])


def bench_engine() -> None:
    setup()
    sh(PYTHON, "bench/bench_engine.py", *sys.argv[2:])


def bench_piles() -> None:
    setup("bench")
    sh(PYTHON, "bench/bench_piles.py", *sys.argv[2:])


def bench_piles_3d() -> None:
    setup("bench")
    sh(PYTHON, "bench/bench_piles_3d.py", *sys.argv[2:])


def bench_edmd() -> None:
    setup("dev")
    sh(PYTHON, "bench/bench_edmd.py", *sys.argv[2:])


def edmd_long() -> None:
    """The long checks of the event-driven engine: 10^7 elastic collisions, and the heap of
    1,000 balls (e = 0.7) followed until its energy stops falling."""
    setup("dev")
    sh(PYTHON, "bench/edmd_long.py", *sys.argv[2:])


def bench_sweep() -> None:
    setup("dev")
    sh(PYTHON, "bench/bench_sweep.py", *sys.argv[2:])


def bench_compile() -> None:
    setup("dev")
    sh(PYTHON, "bench/bench_compile.py", *sys.argv[2:])


def fuzz() -> None:
    """The fuzz suite's harness (tests/fuzz_harness.py) at 100,000 inputs or more."""
    setup("dev")
    sh(PYTHON, "-m", "tests.fuzz_harness", *(sys.argv[2:] or ["--inputs", "100000", "--jobs", "3"]))


TASKS = {
    "run": run,
    "test": test,
    "bench": bench,
    "bench-engine": bench_engine,
    "bench-piles": bench_piles,
    "bench-piles-3d": bench_piles_3d,
    "bench-edmd": bench_edmd,
    "edmd-long": edmd_long,
    "bench-sweep": bench_sweep,
    "bench-compile": bench_compile,
    "fuzz": fuzz,
}

if __name__ == "__main__":
    if len(sys.argv) < 2 or sys.argv[1] not in TASKS:
        print(f"usage: python3 tasks.py {{{'|'.join(TASKS)}}}", file=sys.stderr)
        sys.exit(2)
    TASKS[sys.argv[1]]()
