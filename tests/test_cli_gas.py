"""``collisionlab gas``: output, flags, errors, plot and progress bar."""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest

from collisionlab.cli import main
from collisionlab.cli import progress as progress_module
from collisionlab.cli.streams import Streams
from tests.schema_check import check


def run(argv: list[str], interactive: bool = False) -> tuple[int, str, str]:
    streams = Streams(stdin=io.StringIO(), stdout=io.StringIO(), stderr=io.StringIO(), interactive=interactive)
    status = main(["gas", *argv], streams)
    if status == 0 and "--format" in argv and argv[argv.index("--format") + 1] == "json":
        check("gas", json.loads(streams.stdout.getvalue()))  # type: ignore[attr-defined]
    return status, streams.stdout.getvalue(), streams.stderr.getvalue()  # type: ignore[attr-defined]


def test_json_report() -> None:
    status, out, err = run(["--n", "500", "--dim", "3", "--steps", "300", "--format", "json"])
    assert status == 0 and err == ""
    report = json.loads(out)
    assert (report["n"], report["dim"], report["steps"]) == (500, 3, 300)
    assert report["seconds"] > 0
    assert report["body_steps_per_s"] == pytest.approx(500 * 300 / report["seconds"])
    assert report["collisions"] > 0
    assert abs(report["energy_drift"]) < 1e-9  # e = 1, no gravity
    assert report["bytes_per_body"] < 300


def test_table_report_and_same_scenario_as_the_library() -> None:
    status, out, _ = run(["--n", "400", "--steps", "50"])
    assert status == 0
    assert out.splitlines()[0].startswith("collisionlab gas: 400 discs in 2D, 50 steps")
    assert "body-steps/s" in out and "energy drift" in out
    status, again, _ = run(["--n", "400", "--steps", "50", "--format", "json"])
    collisions = json.loads(again)["collisions"]
    assert f"{collisions:,} between balls" in out  # seeded: the same run twice


def test_gravity_and_restitution_change_the_energy() -> None:
    _, out, _ = run(["--n", "300", "--steps", "200", "--restitution", "0.5", "--format", "json"])
    assert json.loads(out)["energy_drift"] < -0.05


@pytest.mark.parametrize(
    ("argv", "flag"),
    [
        (["--n", "0"], "--n"),
        (["--dim", "4"], "--dim"),
        (["--steps", "0"], "--steps"),
        (["--restitution", "-0.5"], "--restitution"),
        (["--seed", "-3"], "--seed"),
        (["--plot", "speeds.txt"], "--plot"),
        (["--plot", "/no/such/folder/s.png"], "--plot"),
    ],
)
def test_bad_values_print_one_line_naming_the_flag(argv: list[str], flag: str) -> None:
    status, out, err = run(argv)
    assert status == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and flag in err and "Traceback" not in err


def test_bad_usage_is_argparse_exit_2() -> None:
    status, _, err = run(["--n", "many"])
    assert status == 2 and "--n" in err


def test_plot_is_written_whole(tmp_path: Path) -> None:
    target = tmp_path / "speeds.png"
    status, out, _ = run(["--n", "300", "--steps", "100", "--speeds", "equal", "--plot", str(target)])
    assert status == 0 and str(target) in out
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [p.name for p in tmp_path.iterdir()] == ["speeds.png"]  # no temporary left behind


@pytest.mark.parametrize(
    ("interactive", "quiet", "drawn"), [(True, False, True), (True, True, False), (False, False, False)]
)
def test_progress_bar_only_on_a_terminal(
    monkeypatch: pytest.MonkeyPatch, interactive: bool, quiet: bool, drawn: bool
) -> None:
    monkeypatch.setattr(progress_module, "SHOW_AFTER", 0.0)  # as if the run were long
    status, _, err = run(["--n", "200", "--steps", "200", *(["--quiet"] if quiet else [])], interactive)
    assert status == 0
    assert ("200/200" in err) is drawn


def test_restitution_above_one_is_allowed_with_a_warning_and_adds_energy() -> None:
    status, out, err = run(["--n", "300", "--steps", "200", "--restitution", "1.5", "--format", "json"])
    assert status == 0
    assert "adds kinetic energy" in err
    assert json.loads(out)["energy_drift"] > 0
