"""Helpers for driving the command line in-process (through its streams) and as a subprocess."""

from __future__ import annotations

import contextlib
import io
import json
import os
import pty
import re
import select
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from collisionlab.cli import Streams, main
from tests.schema_check import check

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = REPO / "src" / "collisionlab" / "examples"
#: The scenario files among the examples (``sweep-*.toml`` are sweep files: tests/test_sweep_*.py).
EXAMPLE_NAMES = sorted(p.stem for p in EXAMPLES.glob("*.toml") if not p.name.startswith("sweep-"))
#: Examples too heavy to run in full in the test suite, and the steps the tests run them for
#: instead. ramp-pour (2,000 spheres, 3,500 steps) takes minutes to come to rest; its first 10
#: steps hold its first collisions (spheres that start 1 cm apart), so the tests still see
#: events and the ledger, in a few seconds a run. The tests run such an example with
#: ``heavy_options(name)`` (``--steps N --every N``: the first and last frames only, so its
#: golden files stay about 0.5 MB) or ``steps = N``, and the fuzz harness leaves it out.
HEAVY_EXAMPLES = {"ramp-pour": 10}
#: The console script of the venv the tests run in (the package is installed editable).
SCRIPT = Path(sys.executable).with_name("collisionlab")

COLLISION_LINE = re.compile(r"^collision at step (\d+) \(t = (\d+\.\d{3}) s\): (.+)$")


#: 600 spheres falling on a tilted plane: enough body-steps (x 400 steps) for compiled kernels.
PILE_ON_A_SLOPE = """
[simulation]
title = "a pile on a slope"
dt = 0.002
steps = {steps}
restitution = 0.5
gravity = [0, -9.81, 0]
mode = "{mode}"

[[gas]]
name = "ball"
shape = "sphere"
radius = 0.05
region = [[-1, 0.3, -1], [1, 1.0, 1]]
count = 600
kT = 0.01
seed = 3

[[static]]
name = "slope"
shape = "plane"
point = [0, 0, 0]
normal = [0.2, 1, 0]
"""


@dataclass
class Result:
    status: int
    out: str
    err: str

    @property
    def lines(self) -> list[str]:
        return self.out.splitlines()

    def collisions(self) -> list[tuple[int, str]]:
        """``(step, what)`` of every ``collision at step ...`` line of stdout."""
        found = []
        for line in self.lines:
            match = COLLISION_LINE.match(line)
            if match:
                found.append((int(match.group(1)), match.group(3)))
        return found

    def json(self) -> Any:
        return json.loads(self.out)


def run_cli(argv: list[str], stdin: str | io.StringIO = "", interactive: bool = False) -> Result:
    """``main(argv)`` with string streams; ``stdin`` is the typed answers."""
    source = io.StringIO(stdin) if isinstance(stdin, str) else stdin
    out, err = io.StringIO(), io.StringIO()
    status = main(argv, Streams(source, out, err, interactive))
    result = Result(status, out.getvalue(), err.getvalue())
    _check_json_output(argv, result)
    return result


def _check_json_output(argv: list[str], result: Result) -> None:
    """Every JSON document the CLI writes in a test follows the schema shipped for it."""
    if result.status != 0 or argv[:1] not in (["run"], ["demo"], ["gas"]) or {"--help", "-h", "--list"} & set(argv):
        return
    formats = [argv[i + 1] for i in range(len(argv) - 1) if argv[i] == "--format"]
    if formats[-1:] != ["json"]:
        return
    name = "gas" if argv[0] == "gas" else "run"
    outputs = [argv[i + 1] for i in range(len(argv) - 1) if argv[i] == "--output"]
    if outputs:  # argparse keeps the last one given (found by the fuzz suite: '--output "" --output o.txt')
        check(name, json.loads(Path(outputs[-1]).read_text(encoding="utf-8")))
    else:
        check(name, json.loads(result.out))


def typed(*answers: str) -> str:
    """Lines as typed at the prompts ("" is Enter, accepting the default)."""
    return "".join(a + "\n" for a in answers)


class InterruptingStdin(io.StringIO):
    """Answers ``lines`` and then raises KeyboardInterrupt, as Ctrl-C at the next prompt does."""

    def __init__(self, text: str) -> None:
        super().__init__(text)

    def readline(self, size: int | None = -1) -> str:
        line = super().readline()
        if not line:
            raise KeyboardInterrupt
        return line


def example(name: str) -> str:
    return str(EXAMPLES / f"{name}.toml")


def heavy_options(name: str) -> list[str]:
    """The command-line options that cut a heavy example short (:data:`HEAVY_EXAMPLES`); none
    for the others."""
    steps = HEAVY_EXAMPLES.get(name)
    return [] if steps is None else ["--steps", str(steps), "--every", str(steps)]


def files_in(folder: Path) -> list[str]:
    """Every entry of ``folder``, hidden ones (temporary files) included."""
    return sorted(os.listdir(folder))


def read_until(fd: int, marker: bytes, timeout: float = 20.0) -> bytes:
    """Read ``fd`` (a pseudo-terminal's master side, or a pipe) until ``marker`` appears;
    bounded by ``timeout`` so that a hung child fails the test instead of hanging it."""
    buffer = b""
    deadline = time.monotonic() + timeout
    while marker not in buffer:
        left = deadline - time.monotonic()
        if left <= 0:
            raise AssertionError(f"{marker!r} never came; got {buffer.decode(errors='replace')!r}")
        ready, _, _ = select.select([fd], [], [], min(left, 0.5))
        if ready:
            try:
                chunk = os.read(fd, 4096)
            except OSError:  # the pty's other side closed (the child ended)
                chunk = b""
            if not chunk:
                raise AssertionError(f"end of output before {marker!r}; got {buffer.decode(errors='replace')!r}")
            buffer += chunk
    return buffer


def _signal_state(pid: int) -> str:
    """What the kernel says of a hung child's signals and where each of its threads waits
    (Linux's /proc; elsewhere nothing), for the message of a test that timed out."""
    lines = []
    try:
        for task in sorted(os.listdir(f"/proc/{pid}/task")):
            status = Path(f"/proc/{pid}/task/{task}/status").read_text()
            wanted = [row for row in status.splitlines() if row.startswith(("State", "Sig", "ShdPnd"))]
            wchan = Path(f"/proc/{pid}/task/{task}/wchan").read_text()
            lines.append(f"thread {task} waits in {wchan!r}: " + ", ".join(" ".join(w.split()) for w in wanted))
    except OSError as error:
        lines.append(f"(no /proc: {error})")
    return "; ".join(lines)


def finish(process: subprocess.Popen[bytes], timeout: float = 20.0) -> tuple[int, bytes]:
    """Wait for ``process`` (bounded); kill it if it hangs. Returns the status and its stderr."""
    try:
        _, err = process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        state = _signal_state(process.pid)
        process.kill()
        _, err = process.communicate()
        raise AssertionError(f"the child did not end within {timeout} s; stderr {err!r}; {state}") from None
    return process.returncode, err or b""


@contextlib.contextmanager
def ignoring(signals: tuple[int, ...]) -> Iterator[None]:
    """Within: ``signals`` are ignored, so a child started then inherits the ignore (as
    ``nohup`` starts a command ignoring SIGHUP); restored after."""
    saved = {signum: signal.signal(signum, signal.SIG_IGN) for signum in signals}
    try:
        yield
    finally:
        for signum, previous in saved.items():
            signal.signal(signum, previous)


@contextlib.contextmanager
def on_a_terminal(
    argv: list[str], cwd: Path, stdout_too: bool = True, ignored: tuple[int, ...] = ()
) -> Iterator[tuple[subprocess.Popen[bytes], int]]:
    """The console script with a pseudo-terminal as its stdin (and stdout, unless ``stdout_too``
    is false: then a pipe), stderr a pipe, started ignoring the signals ``ignored``. Yields the
    process and the terminal's master end; on leaving, a child still running is killed and the
    terminal closed."""
    master, slave = pty.openpty()
    with ignoring(ignored):
        process = subprocess.Popen(
            [str(SCRIPT), *argv],
            stdin=slave,
            stdout=slave if stdout_too else subprocess.PIPE,
            stderr=subprocess.PIPE,
            cwd=cwd,
            close_fds=True,
            env={**os.environ, "TERM": "dumb"},
        )
    os.close(slave)
    try:
        yield process, master
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
        os.close(master)


def cpu_seconds(pid: int) -> float:
    """The CPU time the process ``pid`` has used so far, user and system (Linux's /proc)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def wait_for_cpu_seconds(pid: int, seconds: float, timeout: float = 180.0) -> None:
    """Until the process has used ``seconds`` of CPU (imports and kernels loaded: stepping);
    bounded by ``timeout`` (wall clock, generous for a loaded machine) so a hang fails."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if cpu_seconds(pid) >= seconds:
            return
        time.sleep(0.1)
    raise AssertionError(f"the process did not reach {seconds} s of CPU within {timeout} s")
