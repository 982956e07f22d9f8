"""A sweep on a real Dask cluster: ``dask scheduler`` and two ``dask worker`` processes on
127.0.0.1, reached with ``--scheduler``; one worker is killed mid-sweep and no row is lost or
written twice. Every process started here is ended, whatever happens."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from .cli_helpers import SCRIPT, finish

DASK = Path(sys.executable).with_name("dask")

SWEEP = """
[sweep]
demo = "sphere-plane"
metrics = ["first_collision_step", "collisions"]
[sweep.parameters]
"simulation.dt" = {start = 0.001, stop = 0.016, num = 16}
"simulation.steps" = [1500]
"""


def wait_for(condition: object, seconds: float, what: str) -> None:
    """Poll ``condition()`` until true; bounded, so a cluster that never comes up fails the test."""
    deadline = time.monotonic() + seconds
    while not condition():  # type: ignore[operator]
        if time.monotonic() > deadline:
            raise AssertionError(f"{what} did not happen within {seconds} s")
        time.sleep(0.05)


@pytest.fixture
def cluster(tmp_path: Path) -> Iterator[tuple[str, list[subprocess.Popen[bytes]]]]:
    """A scheduler and two single-threaded workers (no nanny: a killed worker stays dead)."""
    scheduler_file = tmp_path / "scheduler.json"
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL, "cwd": tmp_path}
    processes = [
        subprocess.Popen(
            [str(DASK), "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
             "--scheduler-file", str(scheduler_file)],
            **quiet,  # type: ignore[call-overload]
        )
    ]  # fmt: skip
    try:
        wait_for(lambda: scheduler_file.exists() and scheduler_file.read_text().strip(), 60, "the scheduler start")
        address = json.loads(scheduler_file.read_text())["address"]
        for name in ("w1", "w2"):
            processes.append(
                subprocess.Popen(
                    [str(DASK), "worker", address, "--nthreads", "1", "--no-nanny", "--no-dashboard",
                     "--name", name, "--host", "127.0.0.1"],
                    **quiet,  # type: ignore[call-overload]
                )
            )  # fmt: skip
        from distributed import Client

        with Client(address, timeout=30) as client:
            client.wait_for_workers(2, timeout=60)
        yield address, processes
    finally:
        for process in reversed(processes):
            if process.poll() is None:
                process.terminate()
        for process in processes:
            try:
                process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()


def test_a_sweep_on_a_cluster_survives_a_killed_worker(
    tmp_path: Path, cluster: tuple[str, list[subprocess.Popen[bytes]]]
) -> None:
    address, processes = cluster
    sweep = tmp_path / "dt.toml"
    sweep.write_text(SWEEP)
    csv = tmp_path / "dt.csv"
    process = subprocess.Popen(
        [str(SCRIPT), "sweep", str(sweep), "--scheduler", address],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    try:
        wait_for(lambda: csv.exists() and len(csv.read_text().splitlines()) >= 3, 60, "two rows")
        rows_at_kill = len(csv.read_text().splitlines()) - 1
        os.kill(processes[1].pid, signal.SIGKILL)  # worker w1 dies, with a task in hand
        status, err = finish(process, timeout=120)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    assert processes[1].poll() is not None
    assert rows_at_kill < 16
    assert status == 0, err
    assert b"16 rows written" in err and b"dt.csv" in err
    table = pq.read_table(tmp_path / "dt.parquet").to_pylist()
    assert [(r["point"], r["replica"]) for r in table] == [(p, 0) for p in range(16)]  # all there, once each
    assert all(r["error"] == "" and r["collisions"] == 1 for r in table)
    lines = csv.read_text().splitlines()
    assert len(lines) == 17 and len(set(lines)) == 17
