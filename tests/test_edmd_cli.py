"""``collisionlab gas --mode exact``: the report's fields, the event stream, and bad flags."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import pytest

from collisionlab.cli import main
from collisionlab.cli.streams import Streams

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
        (["--plot", "x.png"], "--plot"),
        (["--n", "0"], "--n"),
        # The range every scenario has (found by the fuzz suite: e = 1e308 ran for ever).
        (["--restitution", "1e308"], "--restitution"),
        (["--restitution", "10.5"], "--restitution"),
        (["--gravity", "1e300"], "--gravity"),
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
