"""Checkpoints of the exact gas: ``collisionlab gas --mode exact --checkpoint FILE`` and
``collisionlab gas --resume FILE --time T``.

The oracle is the run done in one go: a run split at a checkpoint and continued must end with
the same bits in every array of its state (positions, velocities, each ball's own time, the
event calendar, the counters and accumulators) and the same numbers in its JSON as the run that
never stopped, and as the same run without any checkpoint (the scenario's run on the engine's
world, or the mixture's). Files that are not whole checkpoints of this version are refused with
one line and exit 65.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from collisionlab.edmd import layout as L
from collisionlab.edmd.checkpoint import FORMAT, VERSION, CheckpointError, read_checkpoint, write_checkpoint
from collisionlab.edmd.world import STATE_ARRAYS
from tests.cli_helpers import finish, run_cli

#: The report's numbers that depend on the whole run (the rest: wall-clock times, memory and
#: the checkpoint's own fields).
RUN_FIELDS = (
    "n",
    "dim",
    "fraction",
    "boundary",
    "seed",
    "restitution",
    "gravity",
    "tc",
    "sim_time",
    "collisions",
    "wall_collisions",
    "events",
    "kT",
    "compressibility",
    "collision_rate",
    "energy_drift",
    "energy_lost_in_collisions",
    "max_overlap",
    "compressibility_walls",
    "wall_momentum",
    "compressibility_theory",
    "collision_rate_enskog",
    "species",
    "pair_collision_rates",
)

#: Small runs: 2D and 3D, walls and periodic, one kind of ball and mixtures, elastic and not,
#: gravity (walls only).
CASES = {
    "2d-walls": ["--n", "200", "--dim", "2"],
    "3d-periodic": ["--n", "300", "--dim", "3", "--boundary", "periodic", "--fraction", "0.3"],
    "3d-walls-inelastic": ["--n", "200", "--dim", "3", "--restitution", "0.8"],
    "2d-gravity": ["--n", "150", "--dim", "2", "--gravity", "1", "--restitution", "0.9"],
    "3d-mixture-periodic": [
        "--n", "300", "--dim", "3", "--boundary", "periodic", "--fraction", "0.15",
        "--species", "big:0.5:1", "--species", "small:0.5:0.5",
    ],
    "2d-mixture-gravity": [
        "--n", "150", "--dim", "2", "--gravity", "0.5", "--restitution", "0.9",
        "--species", "a:0.3:1:2", "--species", "b:0.7:0.6",
    ],
}  # fmt: skip


def gas(*argv: str) -> Any:
    """``collisionlab gas --mode exact ... --format json --quiet``: its report (exit 0)."""
    result = run_cli(["gas", "--mode", "exact", *argv, "--format", "json", "--quiet"])
    assert result.status == 0, result.err
    return result.json()


def resume(*argv: str) -> Any:
    result = run_cli(["gas", *argv, "--format", "json", "--quiet"])
    assert result.status == 0, result.err
    return result.json()


def state(path: Path) -> dict[str, np.ndarray]:
    """Every array of a checkpoint's state, and where the balls are at its time."""
    with np.load(path, allow_pickle=False) as members:
        arrays = {name: members[name] for name in STATE_ARRAYS}
    world = read_checkpoint(path).world
    arrays["positions"], arrays["velocities"] = world.state()
    return arrays


def assert_same_state(first: Path, second: Path) -> None:
    a, b = state(first), state(second)
    for name in a:
        assert a[name].dtype == b[name].dtype and a[name].shape == b[name].shape, name
        assert a[name].tobytes() == b[name].tobytes(), f"{name} differs"


def assert_same_run(first: dict[str, Any], second: dict[str, Any]) -> None:
    for field in RUN_FIELDS:
        assert first.get(field) == second.get(field), field  # == on floats: the same bits


@pytest.mark.parametrize("case", sorted(CASES))
def test_a_resumed_run_ends_as_the_run_done_in_one_go(tmp_path: Path, case: str) -> None:
    options = CASES[case]
    whole, part = tmp_path / "whole.npz", tmp_path / "part.npz"
    plain = gas(*options, "--time", "3")  # no checkpoint: the scenario's run (or the mixture's)
    one_go = gas(*options, "--time", "3", "--checkpoint", str(whole), "--checkpoint-every", "0.7")
    first = gas(*options, "--time", "1.3", "--checkpoint", str(part), "--checkpoint-every", "0.7")
    assert first["checkpoints_written"] == 2 and first["sim_time"] == pytest.approx(1.3)
    assert read_checkpoint(part).time == first["sim_time"]  # the end's, written before measuring
    continued = resume("--resume", str(part), "--time", "3")
    assert continued["resumed_from"] == str(part) and continued["resumed_at"] == first["sim_time"]
    assert continued["checkpoint"] == str(part) and continued["checkpoints_written"] == 4  # 1.4, 2.1, 2.8, end
    assert continued["collisions"] > first["collisions"] > 0
    assert_same_run(continued, one_go)
    assert_same_run(plain, one_go)
    assert_same_state(part, whole)


def test_a_run_resumed_twice_and_without_time_ends_as_one_run(tmp_path: Path) -> None:
    options = CASES["3d-periodic"]
    whole, part = tmp_path / "whole.npz", tmp_path / "part.npz"
    one_go = gas(*options, "--time", "2", "--checkpoint", str(whole))
    assert one_go["checkpoints_written"] == 1  # without --checkpoint-every: the end's only
    gas(*options, "--time", "0.5", "--checkpoint", str(part))
    resume("--resume", str(part), "--time", "1.25")
    again = resume("--resume", str(part), "--time", "2")
    assert_same_run(again, one_go)
    assert_same_state(part, whole)
    # --time left out: the run's own (2, the last given); resuming a finished run changes nothing
    done = resume("--resume", str(part), "--checkpoint", str(tmp_path / "copy.npz"))
    assert_same_run(done, one_go)
    assert_same_state(tmp_path / "copy.npz", whole)


def test_a_run_killed_after_a_checkpoint_resumes_to_the_same_end(tmp_path: Path) -> None:
    options = ["--n", "400", "--dim", "3", "--boundary", "periodic", "--fraction", "0.3"]
    saved = tmp_path / "killed.npz"
    # A run far longer than the test waits: killed (SIGKILL) once its first checkpoint exists,
    # maybe while it writes the next one.
    child = subprocess.Popen(
        [sys.executable, "-m", "collisionlab", "gas", "--mode", "exact", *options, "--time", "100000",
         "--checkpoint", str(saved), "--checkpoint-every", "0.25", "--quiet"],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
    )  # fmt: skip
    try:
        deadline = time.monotonic() + 300.0  # (a bound on a hang, not a timing assertion)
        while not saved.exists() and child.poll() is None and time.monotonic() < deadline:
            time.sleep(0.01)
    finally:
        child.send_signal(signal.SIGKILL)
    status, err = finish(child)
    assert status == -signal.SIGKILL, err
    kept = read_checkpoint(saved)  # whole: read and checked
    assert kept.time > 0.0 and kept.time % 0.25 == 0.0
    leftovers = [p.name for p in tmp_path.iterdir() if p.name != saved.name]
    # only a kill during a write can leave its hidden temporary file
    assert all(name.startswith(f".{saved.name}.") and name.endswith(".tmp") for name in leftovers)
    total = str(kept.time + 1.0)
    continued = resume("--resume", str(saved), "--time", total)
    one_go = gas(*options, "--time", total, "--checkpoint", str(tmp_path / "whole.npz"))
    plain = gas(*options, "--time", total)
    assert_same_run(continued, one_go)
    assert_same_run(plain, one_go)
    assert_same_state(saved, tmp_path / "whole.npz")


def test_a_run_stopped_by_sigterm_keeps_its_last_checkpoint(tmp_path: Path) -> None:
    # Handled as Ctrl-C (exit 143) between two calls of the loop, however short the calls
    # between checkpoints are; the last checkpoint is whole and no temporary file is left.
    saved = tmp_path / "stopped.npz"
    child = subprocess.Popen(
        [sys.executable, "-m", "collisionlab", "gas", "--mode", "exact", "--n", "300", "--dim", "2", "--time",
         "100000", "--checkpoint", str(saved), "--checkpoint-every", "0.25", "--quiet"],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
    )  # fmt: skip
    try:
        deadline = time.monotonic() + 300.0  # (a bound on a hang, not a timing assertion)
        while not saved.exists() and child.poll() is None and time.monotonic() < deadline:
            time.sleep(0.01)
    finally:
        child.send_signal(signal.SIGTERM)
    status, err = finish(child)
    assert status == 128 + signal.SIGTERM and b"Traceback" not in err, err
    assert read_checkpoint(saved).time > 0.0
    assert sorted(p.name for p in tmp_path.iterdir()) == [saved.name]


def test_a_normal_run_leaves_only_its_checkpoint(tmp_path: Path) -> None:
    target = tmp_path / "run.npz"
    target.write_text("an older file, replaced whole")
    report = gas("--n", "100", "--dim", "2", "--time", "1", "--checkpoint", str(target), "--checkpoint-every", "0.3")
    assert report["checkpoints_written"] == 4  # 0.3, 0.6, 0.9 and the end
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.npz"]
    assert read_checkpoint(target).time == report["sim_time"]


def test_a_failed_write_leaves_the_previous_checkpoint(tmp_path: Path) -> None:
    target = tmp_path / "run.npz"
    gas("--n", "100", "--dim", "2", "--time", "1", "--checkpoint", str(target))
    before = target.read_bytes()
    checkpoint = read_checkpoint(target)

    class Broken(RuntimeError):
        pass

    def fail(stream: Any) -> None:
        stream.write(b"half a file")
        raise Broken

    from collisionlab.edmd import checkpoint as module

    with pytest.raises(Broken):
        module._write_atomically(str(target), fail)
    assert target.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == ["run.npz"]
    write_checkpoint(target, checkpoint.gas, checkpoint.world, checkpoint.energy_start, 0.0, None)
    assert read_checkpoint(target).time == checkpoint.time


def _header(path: Path) -> dict[str, Any]:
    with np.load(path, allow_pickle=False) as members:
        return dict(json.loads(members["header"].tobytes()))


def _rewrite(path: Path, target: Path, header: dict[str, Any], drop: str = "") -> None:
    with np.load(path, allow_pickle=False) as members:
        arrays = {name: members[name] for name in members.files if name not in ("header", drop)}
    np.savez(target, header=np.frombuffer(json.dumps(header).encode(), dtype=np.uint8), **arrays)


@pytest.fixture(scope="module")
def saved(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("saved") / "good.npz"
    gas("--n", "100", "--dim", "2", "--time", "1", "--checkpoint", str(path))
    return path


def _refused(path: Path, *extra: str) -> str:
    result = run_cli(["gas", "--resume", str(path), *extra])
    assert result.status == 65 and result.out == ""
    assert result.err.count("\n") == 1 and "Traceback" not in result.err, result.err
    assert result.err.startswith(f"collisionlab gas: --resume: {path}: ")
    return result.err


def test_truncated_files_are_refused(saved: Path, tmp_path: Path) -> None:
    data = saved.read_bytes()
    for size in (0, 10, len(data) // 2, len(data) - 1):
        cut = tmp_path / f"cut{size}.npz"
        cut.write_bytes(data[:size])
        _refused(cut)


def test_corrupt_files_are_refused(saved: Path, tmp_path: Path) -> None:
    data = bytearray(saved.read_bytes())
    data[len(data) // 2] ^= 0xFF  # a bit flipped inside an array: the zip's CRC or the checksum
    flipped = tmp_path / "flipped.npz"
    flipped.write_bytes(bytes(data))
    assert "corrupt" in _refused(flipped)
    # a number changed and saved as a valid zip: only the checksum tells
    with np.load(saved, allow_pickle=False) as members:
        arrays = {name: members[name] for name in members.files}
    arrays["F"] = arrays["F"].copy()
    arrays["F"][0, L.V] += 1e-9
    changed = tmp_path / "changed.npz"
    np.savez(changed, **arrays)
    assert "checksum" in _refused(changed)
    with pytest.raises(CheckpointError, match="checksum"):
        read_checkpoint(changed)


def test_other_versions_and_other_files_are_refused(saved: Path, tmp_path: Path) -> None:
    header = _header(saved)
    assert (header["format"], header["version"]) == (FORMAT, VERSION)
    newer = tmp_path / "newer.npz"
    _rewrite(saved, newer, {**header, "version": VERSION + 1})
    assert f"version {VERSION + 1}" in _refused(newer)
    foreign = tmp_path / "foreign.npz"
    _rewrite(saved, foreign, {**header, "format": "something else"})
    assert "not a collisionlab checkpoint" in _refused(foreign)
    incomplete = tmp_path / "incomplete.npz"
    _rewrite(saved, incomplete, header, drop="NB")
    assert "no NB" in _refused(incomplete)
    text = tmp_path / "text.npz"
    text.write_text("time,a,b\n")
    assert "not a collisionlab checkpoint" in _refused(text)
    plain = tmp_path / "plain.npz"
    np.savez(plain, x=np.zeros(3))
    assert "not a collisionlab checkpoint" in _refused(plain)
    zipped = tmp_path / "zipped.npz"
    with zipfile.ZipFile(zipped, "w") as archive:
        archive.writestr("header.npy", b"not an array")
    _refused(zipped)


def test_resume_refuses_options_that_contradict_its_checkpoint(saved: Path, tmp_path: Path) -> None:
    for option, value in (("--n", "101"), ("--dim", "3"), ("--seed", "1"), ("--boundary", "periodic"),
                          ("--restitution", "0.5"), ("--fraction", "0.3"), ("--species", "a:1:1")):  # fmt: skip
        result = run_cli(["gas", "--resume", str(saved), option, value, "--checkpoint", str(tmp_path / "x.npz")])
        assert result.status == 2 and result.err.count("\n") == 1, result.err
        assert result.err.startswith(f"collisionlab gas: {option}: contradicts the checkpoint"), result.err
    # the checkpoint's own values, and the options that may change, are accepted
    report = resume("--resume", str(saved), "--n", "100", "--dim", "2", "--mode", "exact", "--time", "1.5",
                    "--checkpoint", str(tmp_path / "y.npz"), "--checkpoint-every", "0.2")  # fmt: skip
    assert report["sim_time"] == pytest.approx(1.5) and report["checkpoints_written"] == 3  # 1.2, 1.4, end
    for argv, flag in (
        (["--time", "0.5"], "--time"),  # the total time: before the checkpoint's
        (["--mode", "stepped"], "--resume"),
        (["--events", str(tmp_path / "e.csv")], "--events"),
        (["--checkpoint", str(tmp_path / "no" / "x.npz")], "--checkpoint"),
    ):
        result = run_cli(["gas", "--resume", str(saved), *argv])
        assert result.status == 2 and result.err.startswith(f"collisionlab gas: {flag}: "), result.err


def test_checkpoint_options_are_checked(tmp_path: Path) -> None:
    target = str(tmp_path / "c.npz")
    for argv, flag in (
        (["gas", "--checkpoint", target], "--checkpoint"),  # stepped mode
        (["gas", "--mode", "exact", "--checkpoint-every", "1"], "--checkpoint-every"),
        (["gas", "--mode", "exact", "--checkpoint", target, "--checkpoint-every", "0"], "--checkpoint-every"),
        (["gas", "--mode", "exact", "--checkpoint", target, "--trajectory", str(tmp_path / "t.xyz")], "--trajectory"),
    ):
        result = run_cli(argv)
        assert result.status == 2 and result.err.startswith(f"collisionlab gas: {flag}: "), result.err
    missing = run_cli(["gas", "--resume", str(tmp_path / "missing.npz")])
    assert missing.status == 1 and missing.err.count("\n") == 1 and "cannot read" in missing.err
    assert not os.listdir(tmp_path)
