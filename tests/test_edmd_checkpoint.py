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

import argparse
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
from collisionlab.edmd.arrays import STATE_ARRAYS
from collisionlab.edmd.checkpoint import FORMAT, VERSION, CheckpointError, read_checkpoint, write_checkpoint
from collisionlab.edmd.observables import run_end
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


# Observed runs (--observe): the observer is saved with the world, and a resumed run goes on
# observing; its report is the observed run's done in one go, every field of it.

#: The report's fields that are wall-clock times or name the checkpoint (the rest must agree).
NOT_THE_RUN = ("seconds", "collisions_per_s", "compile_seconds", "checkpoint", "checkpoints_written",
               "resumed_from", "resumed_at")  # fmt: skip
OBSERVED = ["--n", "300", "--dim", "3", "--boundary", "periodic", "--fraction", "0.3", "--time", "3"]
#: A mixture's observed run, for the species' pair counts.
OBSERVED_MIXTURE = ["--n", "300", "--dim", "3", "--boundary", "periodic", "--fraction", "0.2", "--time", "2",
                    "--species", "big:0.5:1", "--species", "small:0.5:0.6"]  # fmt: skip


def assert_same_report(first: dict[str, Any], second: dict[str, Any]) -> None:
    """Every field but the wall-clock ones and the checkpoint's own: the same (floats: the same bits)."""
    names = (set(first) | set(second)) - set(NOT_THE_RUN)
    for name in sorted(names):
        assert first.get(name) == second.get(name), name


def _saved_along(
    tmp_path: Path, options: list[str], observe: tuple[str, ...], samples: int, every: float
) -> list[Path]:
    """The observed run of ``options`` (as the command makes it) done in one go, a checkpoint
    of it kept at every multiple of ``every`` (the command keeps the last only)."""
    from collisionlab.cli.gas_command import add_parser
    from collisionlab.cli.gas_common import exact_gas as _exact_gas
    from collisionlab.edmd.observables import ExactGas, observer_for, parse_species, run_on_world

    parser = argparse.ArgumentParser()
    add_parser(parser.add_subparsers())
    args = parser.parse_args(["gas", "--mode", "exact", *options])
    source: ExactGas = _exact_gas(args, tuple(parse_species(text) for text in args.species or ()))
    checked = source.checked()
    world = checked.world()
    observer = observer_for(checked, world, observe, samples)
    kept: list[Path] = []

    def save(energy_start: float, seconds: float) -> None:
        kept.append(tmp_path / f"at{len(kept)}.npz")
        write_checkpoint(kept[-1], source, world, energy_start, seconds, every, observer)

    run_on_world(checked, world, every=every, checkpoint=save, observer=observer)
    return kept


@pytest.mark.parametrize(("options", "observe", "every"), [(OBSERVED, "rdf,msd", 0.5), (OBSERVED_MIXTURE, "rdf", 0.3)])
def test_an_observed_run_resumed_reports_as_the_observed_run_done_in_one_go(
    tmp_path: Path, options: list[str], observe: str, every: float
) -> None:
    samples = 7
    plain = gas(*options, "--observe", observe, "--samples", str(samples))  # no checkpoint
    whole = tmp_path / "whole.npz"
    one_go = gas(*options, "--observe", observe, "--samples", str(samples), "--checkpoint", str(whole),
                 "--checkpoint-every", str(every))  # fmt: skip
    assert_same_report(plain, one_go)
    kept = _saved_along(tmp_path, options, tuple(observe.split(",")), samples, every)
    end = float(options[options.index("--time") + 1])
    assert [read_checkpoint(p).time for p in kept] == [every * (k + 1) for k in range(len(kept) - 1)] + [run_end(end)]
    # before the observation's origin (0.2 of the run), and mid-way through its samples
    taken = [read_checkpoint(p).observer for p in kept]
    before = [p for p, o in zip(kept, taken, strict=True) if o is not None and not o._origin_taken]
    within = [p for p, o in zip(kept, taken, strict=True) if o is not None and 0 < o._k < samples]
    assert before and len(within) >= 2
    for start in (before[0], within[0], within[-1]):
        continued = resume("--resume", str(start), "--checkpoint", str(tmp_path / f"on-{start.name}"))
        assert continued["resumed_at"] == read_checkpoint(start).time
        assert continued["rdf"]["samples"] == samples
        assert_same_report(continued, one_go)
        assert_same_state(tmp_path / f"on-{start.name}", whole)
    # the same options given again (the names in another order) are accepted; so is resuming the end
    again = resume("--resume", str(within[0]), "--observe", ",".join(reversed(observe.split(","))),
                   "--samples", str(samples), "--time", str(end), "--mode", "exact")  # fmt: skip
    assert_same_report(again, one_go)
    assert_same_report(resume("--resume", str(whole)), one_go)


def test_an_observed_checkpoint_keeps_the_whole_observer(tmp_path: Path) -> None:
    kept = _saved_along(tmp_path, OBSERVED, ("rdf", "msd"), 5, 1.0)
    observer = read_checkpoint(kept[1]).observer  # at time 2: samples taken, more to come
    assert observer is not None and observer.observe == ("rdf", "msd") and observer.samples == 5
    assert 0 < observer._k < 5 and observer._rdf_samples == observer._k == len(observer._msd)
    assert observer._counts.sum() > 0 and observer._last <= 2.0
    fields, arrays = observer.saved()
    with np.load(kept[1], allow_pickle=False) as members:
        header = json.loads(members["header"].tobytes())
        for name, array in arrays.items():
            assert members[name].tobytes() == np.ascontiguousarray(array).tobytes(), name
    assert header["observer"] == fields
    assert header["version"] == VERSION and _header(kept[1])["observer"]["names"] == ["A"]


@pytest.fixture(scope="module")
def observed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("observed") / "observed.npz"
    gas("--n", "100", "--dim", "2", "--boundary", "periodic", "--time", "1", "--observe", "rdf,msd",
        "--samples", "4", "--checkpoint", str(path), "--checkpoint-every", "0.5")  # fmt: skip
    return path


def test_resume_of_an_observed_run_keeps_its_observation(observed: Path, saved: Path, tmp_path: Path) -> None:
    for argv, message in (
        (["--time", "2"], "--time: an observed run ends at the time it was started with, 1.0"),
        (["--observe", "msd"], "--observe: contradicts the checkpoint, whose run observes rdf,msd"),
        (["--observe", "rdf,foo"], "--observe: must be a comma list of rdf, msd"),
        (["--samples", "5"], "--samples: contradicts the checkpoint, whose run observes rdf,msd at 4 samples"),
    ):
        result = run_cli(["gas", "--resume", str(observed), *argv, "--checkpoint", str(tmp_path / "x.npz")])
        assert result.status == 2 and result.err.count("\n") == 1, result.err
        assert result.err.startswith(f"collisionlab gas: {message}"), result.err
    for argv, message in (  # a run not observed cannot start observing when resumed
        (["--observe", "rdf"], "--observe: the checkpoint's run was not observed"),
        (["--samples", "5"], "--samples: needs --observe"),
    ):
        result = run_cli(["gas", "--resume", str(saved), *argv])
        assert result.status == 2 and result.err.count("\n") == 1, result.err
        assert result.err.startswith(f"collisionlab gas: {message}"), result.err
    result = run_cli(
        ["gas", "--mode", "exact", "--n", "100", "--observe", "rdf", "--checkpoint", str(tmp_path / "w.npz")]
    )
    assert result.status == 2 and result.err.startswith("collisionlab gas: --observe: needs --boundary periodic")
    assert not (tmp_path / "x.npz").exists() and not (tmp_path / "w.npz").exists()


def _resigned(header: dict[str, Any], path: Path, target: Path, drop: str = "", **changed: Any) -> None:
    """``path`` rewritten with ``header`` and the arrays ``changed`` (``drop`` left out), its
    checksum made again: only the reader's checks can refuse it."""
    from collisionlab.edmd.checkpoint import _digest

    with np.load(path, allow_pickle=False) as members:
        arrays = {name: members[name] for name in members.files if name not in ("header", drop)}
    arrays.update(changed)
    header = {**header, "sha256": _digest(header, arrays)}
    np.savez(target, header=np.frombuffer(json.dumps(header).encode(), dtype=np.uint8), **arrays)


def test_a_mixture_whose_radii_disagree_is_refused(tmp_path: Path) -> None:
    # A mixture's P holds each ball's radius after its parameters (the loop reads them there, and
    # reads past a P without them): a P cut short, a flag that says one kind, or a radius that is
    # not F's are refused, even with a valid checksum.
    path = tmp_path / "mix.npz"
    gas("--n", "100", "--dim", "2", "--time", "0.5", "--species", "a:0.5:1", "--species", "b:0.5:0.5",
        "--checkpoint", str(path))  # fmt: skip
    header = _header(path)
    with np.load(path, allow_pickle=False) as members:
        p = members["P"]
    assert p.shape == (L.NP + 100,)
    one_kind, other_radius = p.copy(), p.copy()
    one_kind[L.P_MIXED] = 0.0
    other_radius[L.P_RADII + 7] += 0.25
    bad = tmp_path / "bad.npz"
    for changed, says in (
        (p[: L.NP], "array P has shape"),
        (one_kind, "array P has shape"),
        (other_radius, "mixture flag or radii disagree"),
    ):
        _resigned(header, path, bad, P=changed)
        assert says in _refused(bad)


def test_bad_observers_are_refused(observed: Path, tmp_path: Path) -> None:
    header = _header(observed)
    assert header["observer"]["k"] == 4 and header["observer"]["observe"] == ["rdf", "msd"]
    bad = tmp_path / "bad.npz"
    with np.load(observed, allow_pickle=False) as members:
        msd, kinds = members["observer_msd"], members["observer_kinds"]
    for changes, arrays, says in (
        ({"k": 5}, {}, "sample counts"),
        ({"k": 3}, {}, "sample counts"),  # rdf_samples 4
        ({"samples": 0}, {}, "observer.samples"),
        ({"observe": ["rdf", "g"]}, {}, "observer.observe"),
        ({"end": 2.0}, {}, "'end'"),
        ({"names": ["B"]}, {}, "species"),
        ({"last": None}, {}, "'last'"),
        ({"last": 5.0}, {}, "'last'"),
        ({"speed": -1.0}, {}, "'speed'"),
        ({"origin_taken": False}, {}, "origin_taken"),
        ({}, {"observer_msd": msd[:2]}, "observer_msd has shape"),
        ({}, {"observer_kinds": kinds + 1}, "species"),
        ({}, {"observer_counts": np.zeros(3)}, "observer_counts is float64"),
    ):
        _resigned({**header, "observer": {**header["observer"], **changes}}, observed, bad, **arrays)
        assert says in _refused(bad), changes or list(arrays)
    _resigned(header, observed, bad, drop="observer_ref")
    assert "no observer_ref" in _refused(bad)
    _resigned({k: v for k, v in header.items() if k != "observer"}, observed, bad)
    assert "lacks 'observer'" in _refused(bad)
    _resigned({**header, "version": 1, "observer": None}, observed, bad)  # the version before observers
    assert "version 1; this collisionlab reads version 2 only" in _refused(bad)
