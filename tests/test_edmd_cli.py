"""``collisionlab gas --mode exact``: the report's fields, the event stream, and bad flags."""

from __future__ import annotations

import csv
import io
import json
import os
import signal
import stat
from pathlib import Path

import pytest

from collisionlab.cli import main
from collisionlab.cli.streams import Streams
from tests.cli_helpers import finish, on_a_terminal, run_cli, wait_for_cpu_seconds

FIELDS = [
    "n",
    "dim",
    "fraction",
    "mode",
    "boundary",
    "sim_time",
    "collisions",
    "seconds",
    "collisions_per_s",
    "kT",
    "compressibility",
    "collision_rate",
    "energy_drift",
    "max_overlap",
]


def run(argv: list[str]) -> tuple[int, str, str]:
    streams = Streams(stdin=io.StringIO(), stdout=io.StringIO(), stderr=io.StringIO(), interactive=False)
    status = main(["gas", "--mode", "exact", *argv], streams)
    return status, streams.stdout.getvalue(), streams.stderr.getvalue()  # type: ignore[attr-defined]


def test_json_has_every_field_the_issue_lists() -> None:
    status, out, err = run(["--n", "500", "--dim", "3", "--boundary", "periodic", "--time", "5", "--format", "json"])
    assert status == 0 and err == ""
    report = json.loads(out)
    assert set(FIELDS) <= set(report)
    assert (report["n"], report["dim"], report["mode"], report["boundary"]) == (500, 3, "exact", "periodic")
    assert report["sim_time"] == 5.0 and report["collisions"] > 0
    assert report["kT"] == pytest.approx(1.0, rel=1e-12)  # defaults: kT 1, elastic
    assert abs(report["energy_drift"]) < 1e-12 and report["max_overlap"] < 1e-9
    assert report["collisions_per_s"] == pytest.approx(report["collisions"] / report["seconds"])


def test_walls_report_the_pressure_on_the_walls_too() -> None:
    status, out, _ = run(["--n", "300", "--dim", "2", "--time", "5", "--format", "json"])
    report = json.loads(out)
    assert status == 0 and report["boundary"] == "walls" and report["wall_collisions"] > 0
    assert len(report["wall_momentum"]) == 4 and report["compressibility_walls"] > 1.0


def test_table() -> None:
    status, out, _ = run(["--n", "300", "--dim", "2", "--time", "2"])
    assert status == 0
    assert out.startswith("collisionlab gas: 300 discs in 2D, exact (event-driven), walls")
    assert "Z = PV/(N kT)" in out and "max overlap" in out


@pytest.mark.parametrize("suffix", [".csv", ".jsonl"])
def test_events_stream_to_a_file(tmp_path: Path, suffix: str) -> None:
    path = tmp_path / f"events{suffix}"
    status, out, _ = run(["--n", "200", "--dim", "2", "--time", "20", "--events", str(path), "--format", "json"])
    report = json.loads(out)
    assert status == 0
    if suffix == ".csv":
        rows = list(csv.DictReader(path.open()))
        others = [row["b"] for row in rows]
        times = [float(row["time"]) for row in rows]
    else:
        lines = [json.loads(line) for line in path.read_text().splitlines()]
        others = [str(line["pair"][1]) for line in lines]
        times = [line["time"] for line in lines]
    # one line per collision, in time order; walls named by axis and side
    assert len(others) == report["collisions"] + report["wall_collisions"]
    assert times == sorted(times)
    assert sum(o in {"x-", "x+", "y-", "y+"} for o in others) == report["wall_collisions"]


def test_more_events_than_one_buffer(tmp_path: Path) -> None:
    path = tmp_path / "many.csv"
    status, out, _ = run(["--n", "2000", "--dim", "3", "--time", "30", "--events", str(path), "--format", "json"])
    report = json.loads(out)
    total = report["collisions"] + report["wall_collisions"]
    assert status == 0 and total > 1 << 16  # more than the loop's buffer holds at once
    assert sum(1 for _ in path.open()) == total + 1  # and a header


@pytest.mark.parametrize(
    ("argv", "flag"),
    [
        (["--fraction", "0.8"], "--fraction"),
        (["--fraction", "0"], "--fraction"),
        (["--time", "-1"], "--time"),
        (["--tc", "-1"], "--tc"),
        (["--events", "out.txt"], "--events"),
        (["--gravity", "1", "--boundary", "periodic"], "--gravity"),
        (["--plot", "x.txt"], "--plot"),  # (a picture of the balls: .png, .svg, .pdf or .gif)
        (["--n", "0"], "--n"),
        # The range every scenario has (found by the fuzz suite: e = 1e308 ran for ever).
        (["--restitution", "1e308"], "--restitution"),
        (["--restitution", "10.5"], "--restitution"),
        (["--gravity", "1e300"], "--gravity"),
        # issue 11 (the audit): each ended in "unexpected error", Infinity in the JSON, or ran for ever
        # (--n 1e20 and --time 1e308, which ran for ever: tests/test_limits.py, on the library)
        (["--time", "5e-324"], "--time"),  # exit 0 with "compressibility_walls": Infinity
        (["--fraction", "1e-20"], "--fraction"),  # ValueError: negative dimensions
        (["--seed", "-1"], "--seed"),  # ValueError: expected non-negative integer
    ],
)
def test_bad_values_name_the_flag(argv: list[str], flag: str, tmp_path: Path) -> None:
    status, out, err = run(["--n", "100", "--time", "1", *argv])
    assert status == 2 and out == ""
    assert err.startswith(f"collisionlab gas: {flag}: ") and err.count("\n") == 1


def test_the_command_line_offers_the_engine_s_boundaries() -> None:
    from collisionlab.cli.gas_command import BOUNDARIES as offered
    from collisionlab.edmd.observables import BOUNDARIES

    assert offered == BOUNDARIES


def test_a_failed_events_file_leaves_nothing(tmp_path: Path) -> None:
    status, _, err = run(["--n", "100", "--time", "1", "--events", str(tmp_path / "no" / "such" / "e.csv")])
    assert status == 1 and "--events" in err
    assert not (tmp_path / "no").exists()


# --- issue 11 (the audit): the exact gas stops, with the right status, whatever happens -------------
def test_json_meets_the_shipped_gas_schema(tmp_path: Path) -> None:
    # run_cli checks every JSON output against its schema: the gas schema described the stepped
    # gas only (found by the fuzz suite), the exact report broke it.
    for extra in ([], ["--dim", "3", "--boundary", "periodic", "--restitution", "0.5"]):
        result = run_cli(["gas", "--mode", "exact", "--n", "300", "--time", "1", "--format", "json", *extra])
        assert result.status == 0, result.err
    events = tmp_path / "e.csv"
    result = run_cli(
        ["gas", "--mode", "exact", "--n", "50", "--time", "1", "--format", "json", "--events", str(events)]
    )
    assert result.status == 0 and result.json()["events_file"] == str(events)


@pytest.mark.parametrize(("name", "status"), [("SIGINT", 130), ("SIGTERM", 143), ("SIGHUP", 129)])
def test_a_signal_during_the_exact_gas_stops_it(tmp_path: Path, name: str, status: int) -> None:
    # The event loop is one compiled call: without --events (whose writes came back to Python)
    # Ctrl-C, SIGTERM and SIGHUP were ignored until the whole run ended (--time 100000: hours).
    # Now they are looked at between chunks of events. The start takes ~1.2 s of CPU: at 5 s the
    # loop is running. The helpers bound each wait, so a hang fails instead of blocking.
    argv = ["gas", "--mode", "exact", "--n", "20000", "--time", "100000", "--quiet"]
    with on_a_terminal(argv, tmp_path, stdout_too=False) as (process, _):
        wait_for_cpu_seconds(process.pid, 5.0)
        process.send_signal(getattr(signal, name))
        code, err = finish(process, timeout=30)
    assert code == status, err
    said = "interrupted" if name == "SIGINT" else f"stopped by {name}"
    assert err.decode().rstrip().endswith(f"collisionlab: {said}") and b"Error" not in err


def test_events_are_written_through_a_fifo(tmp_path: Path) -> None:
    # A FIFO given as --events was replaced by a regular file (the reader got nothing, the pipe
    # was gone); as --output does, the whole text now goes into it.
    fifo = tmp_path / "e.csv"
    os.mkfifo(fifo)
    reader = os.open(fifo, os.O_RDONLY | os.O_NONBLOCK)  # a reader is there: the writer's open does not block
    try:
        status, out, err = run(["--n", "50", "--time", "1", "--events", str(fifo), "--format", "json"])
        try:
            received = os.read(reader, 1 << 16).decode()  # a few hundred bytes: far below a pipe's buffer
        except BlockingIOError:  # nothing was written into the pipe
            received = ""
    finally:
        os.close(reader)
    assert status == 0, err
    assert stat.S_ISFIFO(fifo.stat().st_mode)
    report = json.loads(out)
    assert received.startswith("time,a,b,impulse\n")
    assert len(received.splitlines()) == 1 + report["collisions"] + report["wall_collisions"]
