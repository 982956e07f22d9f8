"""``collisionlab gas``: output, flags, errors, plot and progress bar."""

from __future__ import annotations

import io
import json
import signal
from pathlib import Path

import pytest

from collisionlab.cli import main
from collisionlab.cli import progress as progress_module
from collisionlab.cli.interrupts import Pending
from collisionlab.cli.streams import Streams
from collisionlab.engine import WorldParams
from collisionlab.engine.chunks import CHUNK_SECONDS
from collisionlab.engine.world import World
from collisionlab.particles import gas_scenario
from tests.cli_helpers import finish, on_a_terminal, read_until, wait_for_cpu_seconds
from tests.schema_check import check


def run(argv: list[str], terminal: bool = False) -> tuple[int, str, str]:
    """``collisionlab gas argv``; ``terminal``: as if stdin and stderr were a terminal."""
    streams = Streams(io.StringIO(), io.StringIO(), io.StringIO(), interactive=terminal, err_terminal=terminal)
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
    ("terminal", "quiet", "drawn"), [(True, False, True), (True, True, False), (False, False, False)]
)
def test_progress_bar_only_on_a_terminal(
    monkeypatch: pytest.MonkeyPatch, terminal: bool, quiet: bool, drawn: bool
) -> None:
    monkeypatch.setattr(progress_module, "SHOW_AFTER", 0.0)  # as if the run were long
    status, _, err = run(["--n", "200", "--steps", "200", *(["--quiet"] if quiet else [])], terminal)
    assert status == 0
    assert ("200/200" in err) is drawn


def test_restitution_above_one_is_allowed_with_a_warning_and_adds_energy() -> None:
    status, out, err = run(["--n", "300", "--steps", "50", "--restitution", "1.5", "--format", "json"])
    assert status == 0
    assert "adds kinetic energy" in err
    assert json.loads(out)["energy_drift"] > 0


# --- issue 11: interrupts, and numbers out of range ----------------------------------------------
@pytest.mark.parametrize(
    ("argv", "flag", "words"),
    [
        (["--gravity", "1e300"], "--gravity", "at most"),
        (["--gravity", "nan"], "--gravity", "finite"),
        (["--restitution", "1e308"], "--restitution", "at most"),
        (["--steps", "100000000000000000000000"], "--steps", "at most"),
        # issue 11 (the audit): "unexpected error: ValueError: array is too big (please report this)"
        (["--n", "99999999999999999999"], "--n", "at most"),
    ],
)
def test_magnitudes_out_of_range_are_refused_naming_the_flag(argv: list[str], flag: str, words: str) -> None:
    # gas --gravity 1e300 used to exit 0 with Infinity in its JSON; 1e23 steps ended in OverflowError.
    status, out, err = run(["--n", "100", *argv, "--format", "json"])
    assert status == 2 and out == ""
    assert err.startswith(f"collisionlab gas: {flag}: ") and words in err


def test_energy_that_grows_out_of_range_stops_the_run_with_status_65() -> None:
    # e = 10 multiplies a pair's approach speed by 10 at each collision: within a few thousand
    # steps speeds pass the 1e12 every run is bounded by (and would reach inf, then NaN, and the
    # compiled kernel would hang).
    status, out, err = run(["--n", "300", "--steps", "3000", "--restitution", "10", "--format", "json"])
    assert status == 65 and out == ""
    assert "too large to simulate" in err.splitlines()[-1]


class _Chunks:
    """A clock on which each step of ``world`` takes 0.01 s, and the chunk sizes it was asked for."""

    def __init__(self, world: World) -> None:
        self.world = world
        self.chunks: list[int] = []

    def clock(self) -> float:
        return 0.01 * self.world.step_index

    def between(self, done: int, total: int) -> None:
        self.chunks.append(done - sum(self.chunks))


def _gas_world() -> World:
    return World(gas_scenario(200, 2, seed=1).scenario(1000), WorldParams(compiled=True), events=False)


def test_steps_go_in_chunks_of_a_fraction_of_a_second() -> None:
    world = _gas_world()
    chunks = _Chunks(world)
    world.advance(1000, chunks.between, chunks.clock)
    assert sum(chunks.chunks) == 1000 == world.step_index
    assert max(chunks.chunks) * 0.01 <= CHUNK_SECONDS + 1e-12  # no chunk lasts longer than the target
    assert chunks.chunks[:4] == [1, 4, 16, 25]  # from one step, growing up to the target (0.25 s: 25 steps)


def test_an_interrupt_noted_during_a_chunk_stops_after_it() -> None:
    world = _gas_world()
    chunks = _Chunks(world)
    pending = Pending()
    pending.note(signal.SIGINT, None)

    def between(done: int, total: int) -> None:
        chunks.between(done, total)
        pending.check()

    with pytest.raises(KeyboardInterrupt):
        world.advance(1000, between, chunks.clock)
    assert chunks.chunks == [1] and world.step_index == 1


@pytest.mark.parametrize(("backend", "quiet"), [("numba", True), ("python", False)])
def test_ctrl_c_during_gas_exits_130_in_every_mode(tmp_path: Path, backend: str, quiet: bool) -> None:
    # A run of ~2e10 body-steps (hours). Ctrl-C used to end in "SystemError: CPUDispatcher(...)
    # returned a result with an exception set" 14 s later, or be ignored to the end with --quiet.
    # The Python form's notice (not --quiet) or, with --quiet, the process's CPU time shows the
    # stepping under way; the helpers bound every wait so a hang fails, not blocks.
    argv = ["gas", "--n", "20000", "--steps", "1000000", "--backend", backend, *(["--quiet"] if quiet else [])]
    with on_a_terminal(argv, tmp_path, stdout_too=False) as (process, _):
        assert process.stderr is not None
        if quiet:
            wait_for_cpu_seconds(process.pid, 4.0)
        else:
            read_until(process.stderr.fileno(), b"Python form", timeout=60)
        process.send_signal(signal.SIGINT)
        status, err = finish(process, timeout=20)
    assert status == 130, err
    assert err.decode().rstrip().endswith("collisionlab: interrupted")
    assert b"Error" not in err


# --- issue 28: one option for the kernels' form, and compile time apart ---------------------------
def test_kernels_python_and_compiled_give_the_same_run_and_backend_stays_an_alias() -> None:
    argv = ["--n", "200", "--steps", "40", "--format", "json", "--quiet"]
    reports = {form: json.loads(run([*argv, "--kernels", form])[1]) for form in ("python", "compiled")}
    reports["alias"] = json.loads(run([*argv, "--backend", "numba"])[1])
    assert reports["python"]["backend"] == "python"
    assert reports["compiled"]["backend"] == reports["alias"]["backend"] == "numba"
    for key in ("collisions", "wall_collisions", "kinetic_energy_end"):
        assert reports["python"][key] == reports["compiled"][key] == reports["alias"][key]


def test_compile_seconds_is_reported_apart_and_zero_for_the_python_form() -> None:
    argv = ["--n", "100", "--steps", "10", "--format", "json"]
    assert json.loads(run([*argv, "--kernels", "python", "--quiet"])[1])["compile_seconds"] == 0
    assert json.loads(run([*argv, "--kernels", "compiled"])[1])["compile_seconds"] >= 0
    exact = ["--mode", "exact", "--n", "50", "--time", "0.5", "--format", "json", "--quiet"]
    assert json.loads(run(exact)[1])["compile_seconds"] >= 0  # run() checks the schema


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["--kernels", "fast"], ["--kernels", "invalid choice", "'auto', 'python', 'compiled'"]),
        (["--kernels", "python", "--backend", "numba"], ["--kernels", "--backend numba"]),
        (["--kernels", "python", "--mode", "exact"], ["--kernels", "compiled only"]),
    ],
)
def test_bad_kernels_are_refused_naming_the_flag(argv: list[str], words: list[str]) -> None:
    status, out, err = run(["--n", "100", *argv])
    assert status == 2 and out == "" and "Traceback" not in err
    line = err.strip().splitlines()[-1]
    assert all(word in line for word in words), line
