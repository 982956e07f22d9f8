"""Progress on stderr (``cli/progress.py``): a bar redrawn in place on a terminal; in a log, a
line every ``LOG_EVERY`` seconds of a long run, none for a short one, none with ``--quiet``.
Time is a clock the test moves, never the machine's."""

from __future__ import annotations

import io

import pytest

from collisionlab.cli import progress as progress_module
from collisionlab.cli.progress import LOG_EVERY, SHOW_AFTER, ProgressBar
from collisionlab.cli.streams import Streams
from tests.cli_helpers import run_cli


class Clock:
    """Seconds that pass only when the test says so."""

    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def _bar(terminal: bool, quiet: bool = False) -> tuple[ProgressBar, io.StringIO, Clock]:
    err, clock = io.StringIO(), Clock()
    streams = Streams(io.StringIO(), io.StringIO(), err, interactive=terminal, err_terminal=terminal)
    return ProgressBar(streams, "spheres", quiet=quiet, clock=clock), err, clock


def _run_for(bar: ProgressBar, clock: Clock, seconds: int, total: int = 1000) -> None:
    """``seconds`` of a run told to ``bar`` once a second, evenly to ``total``."""
    for second in range(1, seconds + 1):
        clock.now += 1.0
        bar(total * second // seconds, total)


def test_in_a_log_a_long_run_prints_a_line_every_interval() -> None:
    bar, err, clock = _bar(terminal=False)
    _run_for(bar, clock, 35)
    lines = err.getvalue().splitlines()
    assert len(lines) == int(35 // LOG_EVERY)  # 10 s, 20 s, 30 s
    assert lines[0] == "spheres: 285/1000 (28%), 10 s, about 25 s left"
    assert "\r" not in err.getvalue()


def test_in_a_log_a_short_run_prints_nothing() -> None:
    bar, err, clock = _bar(terminal=False)
    _run_for(bar, clock, int(LOG_EVERY) - 1)
    bar.close()
    assert err.getvalue() == ""


@pytest.mark.parametrize("terminal", [True, False])
def test_quiet_draws_nothing(terminal: bool) -> None:
    bar, err, clock = _bar(terminal, quiet=True)
    _run_for(bar, clock, 35)
    bar.close()
    assert err.getvalue() == ""


def test_on_a_terminal_the_bar_is_redrawn_in_place_after_a_moment() -> None:
    bar, err, clock = _bar(terminal=True)
    clock.now += SHOW_AFTER / 2
    bar(1, 1000)
    assert err.getvalue() == ""  # a moment: nothing
    _run_for(bar, clock, 3)
    bar.close()
    text = err.getvalue()
    assert text.count("\r") == 3 and text.endswith("1000/1000 (286/s)\n")  # in 3.5 s and text.count("\n") == 1


@pytest.mark.parametrize(
    ("argv", "marker"),
    [
        (["run", "examples/bouncing-ball.toml", "--steps", "300"], "/300 ("),
        (["demo", "spheres", "--steps", "300"], "/300 ("),
        (["gas", "--n", "200", "--steps", "30", "--backend", "python"], "gas steps: "),
    ],
)
def test_every_command_prints_its_progress_lines_in_a_log_unless_quiet(
    monkeypatch: pytest.MonkeyPatch, argv: list[str], marker: str
) -> None:
    # As if every call came an interval after the last: the command's progress reaches the log.
    monkeypatch.setattr(progress_module, "LOG_EVERY", 0.0)
    loud = run_cli(argv)
    assert loud.status == 0 and marker in loud.err and "\r" not in loud.err
    quiet = run_cli([*argv, "--quiet"])
    assert quiet.status == 0 and marker not in quiet.err


def test_the_environment_sets_the_interval_of_a_logs_lines(monkeypatch: pytest.MonkeyPatch) -> None:
    # COLLISIONLAB_LOG_EVERY=2.5: 11 s of a run give lines at 2.5 (at the clock's 3 s), 5.5 and
    # 8.5 s... the bar is told once a second, so a line at 3, 6 and 9 s: three lines
    monkeypatch.setenv("COLLISIONLAB_LOG_EVERY", "2.5")
    bar, err, clock = _bar(terminal=False)
    _run_for(bar, clock, 11)
    lines = err.getvalue().splitlines()
    assert [line.split(", ")[1] for line in lines] == ["3 s", "6 s", "9 s"]


@pytest.mark.parametrize("value", ["soon", "0", "-1", "nan", "inf", ""])
def test_a_bad_interval_in_the_environment_is_one_warning_and_the_default(
    monkeypatch: pytest.MonkeyPatch, value: str
) -> None:
    monkeypatch.setenv("COLLISIONLAB_LOG_EVERY", value)
    bar, err, clock = _bar(terminal=False)
    _run_for(bar, clock, 35)
    lines = err.getvalue().splitlines()
    assert lines[0] == f"warning: COLLISIONLAB_LOG_EVERY: expected seconds, a number > 0, got {value!r}; using 10"
    assert len(lines) == 1 + 3  # then the default: 10, 20 and 30 s
