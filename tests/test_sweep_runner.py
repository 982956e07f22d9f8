"""Sweeps on a local Dask cluster: the same table with 1, 2 and 4 workers, equal to lone runs; an
invalid point does not stop the sweep; Ctrl-C then --resume finishes without running a row twice."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import time
import warnings
from collections.abc import Iterator
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from collisionlab.cli.interrupts import Stopped
from collisionlab.sweep.runner import dask_client
from collisionlab.tolerances import ISCLOSE_REL_TOL

from .cli_helpers import EXAMPLES, SCRIPT, example, finish, run_cli

#: Diameters: an exact gas's overlap is rounding only (the library's relative closeness).
ROUNDING = ISCLOSE_REL_TOL

GAS = """
[sweep]
replicas = 2
metrics = ["collisions", "wall_collisions", "kinetic_energy_end", "energy_drift", "momentum_end", "wall_time"]
[sweep.gas]
n = 200
steps = 150
[sweep.parameters]
"gas.restitution" = [0.8, 1.0]
"gas.n" = [200, 0]            # 0 balls: invalid, its rows say so and the rest goes on
"""


def table_without_wall_time(path: Path) -> list[dict[str, object]]:
    return pq.read_table(path).drop_columns(["wall_time"]).to_pylist()


def test_one_two_and_four_workers_give_the_same_table_and_it_equals_lone_runs(tmp_path: Path) -> None:
    sweep = tmp_path / "gas.toml"
    sweep.write_text(GAS)
    tables = []
    for workers in ("1", "2", "4"):
        result = run_cli(["sweep", str(sweep), "--workers", workers, "--output", str(tmp_path / f"w{workers}")])
        assert result.status == 0, result.err
        assert f"on {workers} worker" in result.err and "4 rows report an error" in result.err
        tables.append(table_without_wall_time(tmp_path / f"w{workers}.parquet"))
        assert (tmp_path / f"w{workers}.csv").read_bytes() != b""
    assert tables[0] == tables[1] == tables[2]  # every bit of every row
    rows = tables[0]
    assert [(r["point"], r["replica"]) for r in rows] == [(p, r) for p in range(4) for r in range(2)]
    bad = [r for r in rows if r["gas.n"] == 0]
    assert len(bad) == 4 and all(r["error"].startswith("n: must be a whole number >= 1") for r in bad)
    assert all(r["collisions"] is None for r in bad)
    for row in rows:
        if row["error"]:
            continue
        argv = ["gas", "--n", "200", "--steps", "150", "--restitution", str(row["gas.restitution"])]
        alone = run_cli([*argv, "--seed", str(row["seed"]), "--format", "json"]).json()
        assert (row["collisions"], row["kinetic_energy_end"]) == (alone["collisions"], alone["kinetic_energy_end"])
    # the CSV says the same as the Parquet file
    csv_lines = (tmp_path / "w1.csv").read_text().splitlines()
    assert len(csv_lines) == 9 and csv_lines[0].startswith("point,replica,seed,gas.restitution,gas.n,error,")


SLOW = """
[sweep]
demo = "sphere-plane"
metrics = ["first_collision_step", "wall_time"]
[sweep.parameters]
"simulation.dt" = {start = 0.001, stop = 0.012, num = 12}
"simulation.steps" = [1500]
"""


def data_lines(path: Path) -> list[str]:
    if not path.exists():
        return []
    return [line for line in path.read_text().splitlines()[1:] if line]


EXACT = """
[sweep]
replicas = 2
metrics = ["collisions", "compressibility", "energy_drift", "max_overlap", "wall_time"]
[sweep.gas]
mode = "exact"
n = 64
dim = 3
boundary = "periodic"
time = 2
[sweep.parameters]
"gas.fraction" = [0.1, 0.3, 0.8]   # 0.8: above close packing, its rows say so
"""


def test_an_exact_gas_sweep_gives_the_same_table_on_one_and_two_workers(tmp_path: Path) -> None:
    sweep = tmp_path / "exact.toml"
    sweep.write_text(EXACT)
    tables = []
    for workers in ("1", "2"):
        result = run_cli(["sweep", str(sweep), "--workers", workers, "--output", str(tmp_path / f"w{workers}")])
        assert result.status == 0, result.err
        tables.append(table_without_wall_time(tmp_path / f"w{workers}.parquet"))
    assert tables[0] == tables[1]  # every bit of every row
    bad = [r for r in tables[0] if r["gas.fraction"] == 0.8]
    assert len(bad) == 2 and all(r["error"].startswith("fraction: must be below close packing") for r in bad)
    good = [r for r in tables[0] if not r["error"]]
    assert len(good) == 4 and all(r["collisions"] > 0 and r["max_overlap"] < ROUNDING for r in good)


def test_an_interrupted_sweep_resumes_without_running_a_row_twice(tmp_path: Path) -> None:
    sweep = tmp_path / "slow.toml"
    sweep.write_text(SLOW)
    csv = tmp_path / "slow.csv"
    process = subprocess.Popen(
        [str(SCRIPT), "sweep", str(sweep), "--workers", "1"],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    try:
        deadline = time.monotonic() + 60
        while len(data_lines(csv)) < 3 and process.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
        assert process.poll() is None, "the sweep ended before it could be interrupted"
        os.kill(process.pid, signal.SIGINT)  # Ctrl-C
        status, err = finish(process, timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    assert status == 130, err
    assert b"--resume" in err
    before = {tuple(line.split(",")[:2]): line for line in data_lines(csv)}
    assert 3 <= len(before) < 12
    again = run_cli(["sweep", str(sweep), "--resume", "--workers", "2", "--output", str(tmp_path / "slow")])
    assert again.status == 0, again.err
    assert f"{len(before)} of 12 rows already in" in again.err
    assert f"{12 - len(before)} rows written ({len(before)} already there)" in again.err
    after = data_lines(csv)
    keys = [tuple(line.split(",")[:2]) for line in after]
    assert keys == [(str(p), "0") for p in range(12)]  # every row once, in order
    for line in after:  # the rows of the first run are kept as they were (their wall time too)
        key = tuple(line.split(",")[:2])
        if key in before:
            assert before[key] == line
    table = pq.read_table(tmp_path / "slow.parquet").to_pylist()
    alone = run_cli(["run", example("sphere-plane"), "--dt", "0.001", "--steps", "1500", "--format", "json"]).json()
    assert table[0]["simulation.dt"] == 0.001
    assert table[0]["first_collision_step"] == alone["events"][0]["step"] == 1256  # about 1.255 / dt
    # nothing more to do: a second --resume runs nothing
    done = run_cli(["sweep", str(sweep), "--resume", "--quiet", "--output", str(tmp_path / "slow")])
    assert done.status == 0 and "nothing to run" in done.err


# --- issue 11 (the audit): sweep's --output checked before the run; SIGTERM and SIGHUP as Ctrl-C ---
def test_an_output_in_a_missing_folder_is_refused_before_a_cluster_starts(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # It ran the whole sweep (20 s), then said "missing/.x.rznyb3az.tmp.csv: No such file or
    # directory" (the temporary file), exit 1, with a Dask traceback now and then.
    from collisionlab.sweep import runner

    def no_cluster(*_: object) -> None:
        raise AssertionError("a cluster was started")

    monkeypatch.setattr(runner, "dask_client", no_cluster)
    prefix = tmp_path / "missing" / "x"
    result = run_cli(["sweep", str(EXAMPLES / "sweep-dt.toml"), "--output", str(prefix)])
    assert result.status == 2
    assert result.err.strip() == (
        f"collisionlab: --output: cannot write {prefix}.csv: the folder {prefix.parent} does not exist"
    )


def test_a_shipped_sweep_runs_by_name_from_any_folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # "collisionlab sweep sweep-restitution" failed from another folder (issue 28); the file is
    # found and read when the sweep gets as far as checking where its table goes.
    from collisionlab.sweep import runner

    def no_cluster(*_: object) -> None:
        raise AssertionError("a cluster was started")

    monkeypatch.setattr(runner, "dask_client", no_cluster)
    monkeypatch.chdir(tmp_path)
    result = run_cli(["sweep", "sweep-restitution", "--output", str(tmp_path / "missing" / "r")])
    assert result.status == 2
    assert "cannot write" in result.err and "does not exist" in result.err
    listed = run_cli(["examples"]).out
    assert "sweep-restitution" in listed and "sweep-dt" in listed and "sweep-eos" in listed


@pytest.mark.parametrize("named", ["x.csv", "x.parquet", "x"])
def test_an_output_that_names_the_csv_or_parquet_file_writes_that_pair(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, named: str
) -> None:
    # "--output /tmp/sweep.csv" wrote sweep.csv.csv and sweep.csv.parquet (issue 28). The files a
    # sweep would write are the ones its check of the folder names (no cluster needed for that).
    from collisionlab.sweep import runner

    def no_cluster(*_: object) -> None:
        raise AssertionError("a cluster was started")

    monkeypatch.setattr(runner, "dask_client", no_cluster)
    target = tmp_path / "missing" / named
    result = run_cli(["sweep", str(EXAMPLES / "sweep-dt.toml"), "--output", str(target)])
    assert result.status == 2
    assert f"cannot write {tmp_path / 'missing' / 'x.csv'}:" in result.err


@pytest.mark.parametrize(("signum", "status"), [(signal.SIGTERM, 143), (signal.SIGHUP, 129)])
def test_sigterm_and_sighup_stop_a_sweep_as_ctrl_c_with_their_own_status(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, signum: int, status: int
) -> None:
    # They ended as "interrupted", status 130 (the README: 143 and 129).
    from collisionlab.sweep import runner

    @contextlib.contextmanager
    def no_cluster(*_: object) -> Iterator[None]:
        yield None

    def stopped(*_: object) -> None:
        raise Stopped(signum)

    monkeypatch.setattr(runner, "dask_client", no_cluster)
    monkeypatch.setattr(runner, "run_sweep", stopped)
    result = run_cli(["sweep", str(EXAMPLES / "sweep-dt.toml"), "--output", str(tmp_path / "x")])
    name = signal.Signals(signum).name
    assert result.status == status
    assert f"collisionlab sweep: stopped by {name}: 0 of " in result.err and "--resume" in result.err


def test_two_local_clusters_at_once_warn_nothing() -> None:
    # Two sweeps on one machine: the second's scheduler found port 8787 taken by the first's HTTP
    # server and warned (UserWarning: Port 8787 is already in use) in the middle of its output.
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)
        with dask_client(workers=1) as first, dask_client(workers=1) as second:
            assert first.submit(sum, [1, 2]).result() == 3
            assert second.submit(sum, [3, 4]).result() == 7
