"""``collisionlab gas --trajectory FILE --frames K``: GSD and extended XYZ frames, read back with
``gsd.hoomd`` and ``ase.io`` and compared with the same gas run apart (collisionlab.trajectory)."""

from __future__ import annotations

import errno
import json
import signal
import sys
from pathlib import Path

import numpy as np
import pytest

from collisionlab.edmd.observables import ExactGas
from collisionlab.engine import WorldParams
from collisionlab.engine.world import World
from collisionlab.particles import gas_scenario
from collisionlab.trajectory import frame_steps, steps_for_frames, trajectory_format
from tests.cli_helpers import finish, on_a_terminal, run_cli, wait_for_cpu_seconds
from tests.schema_check import check

gsd_hoomd = pytest.importorskip("gsd.hoomd")
ase_io = pytest.importorskip("ase.io")

FRAMES = 5


def exact_gas(dim: int, boundary: str) -> ExactGas:
    return ExactGas(n=120 if dim == 2 else 150, dim=dim, boundary=boundary, time=2.0, seed=3).checked()


def exact_expected(gas: ExactGas, frames: int) -> list[tuple[float, np.ndarray, np.ndarray]]:
    """Time, positions and velocities at the frames' times, from the event-driven world itself
    (not the engine's world the command runs)."""
    world = gas.world()
    out = []
    for k in range(frames):
        if k > 0:  # (at 0 the frame is the start, before a ball touching a wall at 0 bounces)
            world.run(gas.time * k / (frames - 1), bring=False)
        positions, velocities = world.state()
        out.append((world.time, positions, velocities))
    return out


def run_exact(tmp_path: Path, name: str, dim: int, boundary: str, frames: int = FRAMES) -> tuple[Path, dict]:
    path = tmp_path / name
    gas = exact_gas(dim, boundary)
    result = run_cli(
        ["gas", "--mode", "exact", "--n", str(gas.n), "--dim", str(dim), "--boundary", boundary, "--time", "2",
         "--seed", "3", "--trajectory", str(path), "--frames", str(frames), "--format", "json", "--quiet"]
    )  # fmt: skip
    assert result.status == 0, result.err
    report = json.loads(result.out)
    assert report["trajectory"] == str(path) and report["trajectory_frames"] == frames
    return path, report


def periodic_difference(a: np.ndarray, b: np.ndarray, side: float) -> np.ndarray:
    d = a - b
    return d - side * np.round(d / side)


@pytest.mark.parametrize(("dim", "boundary"), [(2, "walls"), (2, "periodic"), (3, "periodic"), (3, "walls")])
def test_gsd_frames_are_the_run_at_equal_times(tmp_path: Path, dim: int, boundary: str) -> None:
    gas = exact_gas(dim, boundary)
    path, report = run_exact(tmp_path, "run.gsd", dim, boundary)
    expected = exact_expected(gas, FRAMES)
    side = float(gas.scenario().box.sides[0])  # type: ignore[union-attr]
    with gsd_hoomd.open(str(path), "r") as trajectory:
        assert len(trajectory) == FRAMES
        for k, (frame, (time, positions, velocities)) in enumerate(zip(trajectory, expected, strict=True)):
            assert frame.configuration.step == k  # event-driven: the frame's index
            assert frame.log["time"][0] == pytest.approx(time, rel=1e-12, abs=1e-12)
            assert frame.configuration.dimensions == dim
            box = [side, side, side if dim == 3 else 0.0, 0.0, 0.0, 0.0]
            np.testing.assert_allclose(frame.configuration.box, box, rtol=1e-6)
            assert gas.n == frame.particles.N and list(frame.particles.types) == ["A"]
            assert frame.particles.typeid.tolist() == [0] * gas.n
            np.testing.assert_allclose(frame.particles.diameter, 2.0)
            position = frame.particles.position.astype(np.float64)
            # GSD's box is centred on the origin: collisionlab's [0, L] shifted by -L/2
            assert np.all(position[:, :dim] >= -side / 2) and np.all(position[:, :dim] < side / 2)
            shifted = position[:, :dim] + side / 2
            if boundary == "periodic":
                np.testing.assert_allclose(periodic_difference(shifted, positions, side), 0.0, atol=1e-5 * side)
            else:
                np.testing.assert_allclose(shifted, positions, atol=1e-5 * side)
            np.testing.assert_allclose(frame.particles.velocity[:, :dim], velocities, rtol=1e-6, atol=1e-6)
            if dim == 2:
                assert not frame.particles.position[:, 2].any() and not frame.particles.velocity[:, 2].any()
    assert frame.log["time"][0] == pytest.approx(report["sim_time"], rel=1e-12)
    # the last frame is the state the report measures: kT = m v^2 / d per ball
    assert float((velocities**2).sum()) / (dim * gas.n) == pytest.approx(report["kT"], rel=1e-12)


@pytest.mark.parametrize(("dim", "boundary"), [(2, "walls"), (3, "periodic")])
def test_xyz_frames_read_back_with_ase_to_the_last_bit(tmp_path: Path, dim: int, boundary: str) -> None:
    gas = exact_gas(dim, boundary)
    path, report = run_exact(tmp_path, "run.xyz", dim, boundary)
    expected = exact_expected(gas, FRAMES)
    side = float(gas.scenario().box.sides[0])  # type: ignore[union-attr]
    frames = ase_io.read(str(path), index=":")
    assert len(frames) == FRAMES
    for k, (atoms, (time, positions, velocities)) in enumerate(zip(frames, expected, strict=True)):
        assert atoms.info["Step"] == k and atoms.info["Time"] == pytest.approx(time, rel=1e-12, abs=1e-12)
        assert len(atoms) == gas.n
        lattice = np.diag([side, side, side if dim == 3 else 0.0])
        np.testing.assert_array_equal(atoms.cell.array, lattice)
        assert atoms.pbc.tolist() == [boundary == "periodic" and k < dim for k in range(3)]
        assert atoms.arrays["id"].tolist() == list(range(gas.n))
        np.testing.assert_array_equal(atoms.arrays["radius"], 1.0)
        np.testing.assert_allclose(atoms.positions[:, :dim], positions, rtol=0, atol=1e-9)
        np.testing.assert_allclose(atoms.arrays["velo"][:, :dim], velocities, rtol=1e-9, atol=1e-12)
        if dim == 2:
            assert not atoms.positions[:, 2].any()
    assert float((atoms.arrays["velo"] ** 2).sum()) / (dim * gas.n) == pytest.approx(report["kT"], rel=1e-12)
    species = path.read_text().splitlines()[2].split()[0]
    assert species == "A"  # ASE reads Z = 0 (its dummy element); OVITO the species' name


def test_one_frame_is_the_end(tmp_path: Path) -> None:
    path, report = run_exact(tmp_path, "end.xyz", 2, "periodic", frames=1)
    (atoms,) = ase_io.read(str(path), index=":")
    assert atoms.info["Time"] == pytest.approx(report["sim_time"]) and atoms.info["Step"] == 0


@pytest.mark.parametrize("name", ["stepped.gsd", "stepped.xyz"])
def test_the_stepped_gas_writes_its_steps(tmp_path: Path, name: str) -> None:
    path = tmp_path / name
    result = run_cli(
        ["gas", "--n", "100", "--dim", "2", "--steps", "40", "--kernels", "python", "--trajectory", str(path),
         "--frames", "5", "--quiet"]
    )  # fmt: skip
    assert result.status == 0, result.err
    assert f"trajectory       {path} (5 frames)" in result.out
    gas = gas_scenario(100, 2, 0)
    world = World(gas.scenario(40), WorldParams(compiled=False), events=False)
    if name.endswith(".gsd"):
        with gsd_hoomd.open(str(path), "r") as trajectory:
            steps = [int(f.configuration.step) for f in trajectory]
            positions = [f.particles.position[:, :2] + gas.side / 2 for f in trajectory]
            times = [float(f.log["time"][0]) for f in trajectory]
        tolerance = 1e-5 * gas.side
    else:
        frames = ase_io.read(str(path), index=":")
        steps = [a.info["Step"] for a in frames]
        positions = [a.positions[:, :2] for a in frames]
        times = [a.info["Time"] for a in frames]
        tolerance = 1e-12
    assert steps == [0, 10, 20, 30, 40]
    for step, time, found in zip(steps, times, positions, strict=True):
        world.advance(step - world.step_index)
        assert time == pytest.approx(step * gas.dt, rel=1e-12)
        np.testing.assert_allclose(found, world.position_array[:, :2], atol=tolerance)


def test_bad_trajectory_flags_are_one_line_naming_the_flag(tmp_path: Path) -> None:
    base = ["gas", "--mode", "exact", "--n", "50", "--time", "0.5", "--quiet"]
    cases = [
        ([*base, "--trajectory", str(tmp_path / "run.dcd")], "--trajectory", ".gsd"),
        ([*base, "--trajectory", str(tmp_path / "run.xyz"), "--frames", "0"], "--frames", "from 1 to 1,000,000"),
        ([*base, "--trajectory", str(tmp_path / "run.xyz"), "--frames", "1000001"], "--frames", "from 1"),
        ([*base, "--frames", "3"], "--frames", "--trajectory"),
        ([*base, "--trajectory", str(tmp_path / "no" / "run.xyz")], "--trajectory", "does not exist"),
        (["gas", "--n", "50", "--steps", "10", "--trajectory", str(tmp_path / "a.xyz"), "--frames", "4"],
         "--frames", "divide"),
    ]  # fmt: skip
    for argv, flag, words in cases:
        result = run_cli(argv)
        assert result.status == 2, (argv, result.err)
        assert result.err.count("\n") == 1 and f": {flag}: " in result.err and words in result.err, result.err
    assert list(tmp_path.iterdir()) == []


def test_gsd_without_the_extra_is_one_line(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "gsd", None)
    monkeypatch.setitem(sys.modules, "gsd.hoomd", None)
    result = run_cli(["gas", "--mode", "exact", "--n", "50", "--trajectory", str(tmp_path / "run.gsd"), "--quiet"])
    assert result.status == 1
    extra = "pip install 'collisionlab[trajectory]'"
    assert result.err == f"collisionlab: GSD trajectories need the 'trajectory' extra: {extra}\n"
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", ["run.gsd", "run.xyz"])
def test_a_failed_write_leaves_no_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, name: str) -> None:
    from collisionlab import trajectory

    writer = trajectory._GsdWriter if name.endswith(".gsd") else trajectory._XyzWriter
    write = writer.__call__
    calls = []

    def failing(self, *args):  # type: ignore[no-untyped-def]
        calls.append(args[0])
        if len(calls) == 3:
            raise OSError(errno.ENOSPC, "No space left on device")
        write(self, *args)

    monkeypatch.setattr(writer, "__call__", failing)
    (tmp_path / name).write_text("before\n")
    result = run_cli(["gas", "--mode", "exact", "--n", "50", "--time", "1", "--trajectory", str(tmp_path / name),
                      "--frames", "5", "--quiet"])  # fmt: skip
    assert result.status == 1
    assert result.err == f"collisionlab gas: --trajectory: cannot write {tmp_path / name}: No space left on device\n"
    assert [p.name for p in tmp_path.iterdir()] == [name] and (tmp_path / name).read_text() == "before\n"


def test_frame_steps_and_formats() -> None:
    assert frame_steps(1000, 11) == list(range(0, 1001, 100))
    assert steps_for_frames(1000, 3) == 1000 and steps_for_frames(1000, 4) == 1002
    assert trajectory_format("a.XYZ") == "xyz"


@pytest.mark.parametrize("name", ["run.gsd", "run.xyz"])
def test_ctrl_c_mid_run_leaves_no_trajectory(tmp_path: Path, name: str) -> None:
    # The first frame is written at once, the next 100 time units later (seconds): Ctrl-C falls
    # between them, with a file open and part written.
    argv = ["gas", "--mode", "exact", "--n", "20000", "--time", "100000", "--trajectory", name, "--frames", "1001"]
    with on_a_terminal([*argv, "--quiet"], tmp_path, stdout_too=False) as (process, _):
        wait_for_cpu_seconds(process.pid, 5.0)
        process.send_signal(signal.SIGINT)
        code, err = finish(process, timeout=30)
    assert code == 130, err
    assert list(tmp_path.iterdir()) == []


MIXTURE = ["big:0.5:1", "small:0.5:0.5:0.3"]


def mixture_gas(dim: int, boundary: str) -> ExactGas:
    from collisionlab.edmd.observables import parse_species

    species = tuple(parse_species(text) for text in MIXTURE)
    return ExactGas(n=120 if dim == 2 else 150, dim=dim, boundary=boundary, time=2.0, seed=3, species=species).checked()


def run_mixture(tmp_path: Path, name: str, dim: int, boundary: str, extra: tuple[str, ...] = ()) -> tuple[Path, dict]:
    path = tmp_path / name
    gas = mixture_gas(dim, boundary)
    argv = ["gas", "--mode", "exact", "--n", str(gas.n), "--dim", str(dim), "--boundary", boundary, "--time", "2",
            "--seed", "3", "--format", "json", "--quiet", *extra]  # fmt: skip
    for text in MIXTURE:
        argv += ["--species", text]
    if name:
        argv += ["--trajectory", str(path), "--frames", str(FRAMES)]
    result = run_cli(argv)
    assert result.status == 0, result.err
    return path, json.loads(result.out)


def mixture_expected(gas: ExactGas) -> list[tuple[float, np.ndarray, np.ndarray]]:
    """Time, positions and velocities at the frames' times, from the mixture's own world."""
    from collisionlab.edmd.observables import frame_times

    world = gas.world()
    out = []
    for time in frame_times(gas.time, FRAMES):
        if time > 0:
            world.run(time, bring=False)
        positions, velocities = world.state()
        out.append((world.time, positions, velocities))
    return out


@pytest.mark.parametrize(("dim", "boundary"), [(2, "walls"), (3, "periodic")])
def test_a_mixture_gsd_holds_each_balls_species_and_diameter(tmp_path: Path, dim: int, boundary: str) -> None:
    gas = mixture_gas(dim, boundary)
    path, report = run_mixture(tmp_path, "mix.gsd", dim, boundary)
    assert report["trajectory"] == str(path) and report["trajectory_frames"] == FRAMES
    check("gas", report)
    kinds, radii, _, counts = gas.mixture()
    assert sorted(set(radii.tolist())) == [0.5, 1.0] and min(counts) > 0
    side = float(gas.world().sides[0])
    with gsd_hoomd.open(str(path), "r") as trajectory:
        assert len(trajectory) == FRAMES
        for k, (frame, (time, positions, velocities)) in enumerate(zip(trajectory, mixture_expected(gas), strict=True)):
            assert frame.configuration.step == k and frame.configuration.dimensions == dim
            assert frame.log["time"][0] == pytest.approx(time, rel=1e-12, abs=1e-12)
            assert list(frame.particles.types) == ["big", "small"]
            assert frame.particles.typeid.tolist() == kinds.tolist()
            np.testing.assert_array_equal(frame.particles.diameter, (2.0 * radii).astype(np.float32))
            shifted = frame.particles.position.astype(np.float64)[:, :dim] + side / 2
            if boundary == "periodic":
                np.testing.assert_allclose(periodic_difference(shifted, positions, side), 0.0, atol=1e-5 * side)
            else:
                np.testing.assert_allclose(shifted, positions, atol=1e-5 * side)
            np.testing.assert_allclose(frame.particles.velocity[:, :dim], velocities, rtol=1e-6, atol=1e-6)
    assert frame.log["time"][0] == pytest.approx(report["sim_time"], rel=1e-12)
    # the frames' stops do not change the run: the same numbers as without a trajectory
    _, plain = run_mixture(tmp_path, "", dim, boundary)
    for key in ("collisions", "events", "compressibility", "kT", "species", "pair_collision_rates"):
        assert report[key] == plain[key], key


def test_a_mixture_xyz_reads_back_with_ase_to_the_last_bit(tmp_path: Path) -> None:
    gas = mixture_gas(3, "walls")
    path, report = run_mixture(tmp_path, "mix.xyz", 3, "walls")
    kinds, radii, _, _ = gas.mixture()
    frames = ase_io.read(str(path), index=":")
    assert len(frames) == FRAMES
    for k, (atoms, (time, positions, velocities)) in enumerate(zip(frames, mixture_expected(gas), strict=True)):
        assert atoms.info["Step"] == k and atoms.info["Time"] == pytest.approx(time, rel=1e-12, abs=1e-12)
        assert atoms.arrays["id"].tolist() == list(range(gas.n))
        assert atoms.arrays["typeid"].tolist() == kinds.tolist()
        np.testing.assert_array_equal(atoms.arrays["radius"], radii)
        np.testing.assert_array_equal(atoms.positions, positions)
        np.testing.assert_array_equal(atoms.arrays["velo"], velocities)
    # the species column (OVITO's particle type; ASE keeps Z = 0 and the type ids)
    lines = path.read_text().splitlines()
    names = [line.split()[0] for line in lines[2 : 2 + gas.n]]
    assert names == [["big", "small"][k] for k in kinds]
    assert float(report["sim_time"]) == pytest.approx(frames[-1].info["Time"], rel=1e-12)


def test_a_trajectory_refuses_a_species_name_with_a_space(tmp_path: Path) -> None:
    result = run_cli(["gas", "--mode", "exact", "--n", "50", "--time", "0.5", "--species", "a b:0.5:1",
                      "--species", "c:0.5:0.5", "--trajectory", str(tmp_path / "run.xyz"), "--quiet"])  # fmt: skip
    assert result.status == 2 and result.err.count("\n") == 1 and ": --species: " in result.err, result.err
    assert list(tmp_path.iterdir()) == []
