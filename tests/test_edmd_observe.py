"""``collisionlab gas --mode exact --observe rdf,msd``: g(r) against freud's on the same
positions, the ideal-gas limit, Z from g's contact value against the collisions', the MSD of
free flight (closed form), the self-diffusion against Enskog's, and the command line's errors."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from collisionlab.edmd.observables import ExactGas, observer_for, run_end, run_on_world
from collisionlab.edmd.structure import BIN_WIDTH, pair_histogram, rdf_from_counts
from collisionlab.edmd.theory import carnahan_starling
from tests.cli_helpers import run_cli

#: Z from g(sigma) against Z from the collisions over the same window (the issue's bound).
CONTACT_AGREEMENT = 0.01
#: D / D_Enskog at volume fraction 0.3: Alder, Gass and Wainwright (1970) find about 1.2-1.3 at
#: eta 0.25-0.37; a finite periodic box lowers D (Yeh and Hummer 2004): a band around it.
DIFFUSION_BAND = (0.9, 1.5)


def _equilibrated(n: int, dim: int, fraction: float, time: float, seed: int = 0) -> tuple[np.ndarray, float]:
    world = ExactGas(n=n, dim=dim, fraction=fraction, boundary="periodic", time=time, seed=seed).world()
    world.run(time)
    return world.state()[0], float(world.sides[0])


def test_rdf_matches_freud_on_the_same_positions() -> None:
    freud = pytest.importorskip("freud")
    pos, side = _equilibrated(500, 3, 0.3, 2.0)
    width = BIN_WIDTH * 2.0
    bins = int(0.5 * side / width)
    counts = np.zeros((1, bins), dtype=np.int64)
    pair_histogram(pos, np.zeros(len(pos), dtype=np.int64), 1, np.full(3, side), width, counts)
    ours = rdf_from_counts(counts, 1, width, side**3, 3, [len(pos)])[0]
    box = freud.box.Box.cube(side)
    rdf = freud.density.RDF(bins=bins, r_max=bins * width)
    rdf.compute(system=(box, pos - 0.5 * side))
    # freud normalises by N^2 / V (measured: ours / freud = N / (N - 1) in every bin), we by
    # N (N - 1) / V (N (N - 1) / 2 unordered pairs). freud works in single precision: a pair
    # within ~1e-6 of a bin edge may fall in the neighbouring bin, so the counts (freud's count
    # each pair from both ends) agree to a pair or two per bin and in total exactly.
    n = len(pos)
    freud_counts = np.asarray(rdf.bin_counts) / 2
    assert freud_counts.sum() == counts.sum()
    assert np.max(np.abs(np.cumsum(freud_counts) - np.cumsum(counts[0]))) <= 2
    np.testing.assert_allclose(ours * (n - 1) / n, rdf.rdf, rtol=2e-3)
    assert np.all(ours[: int(2.0 / width) - 1] == 0.0)  # no pair closer than a diameter


def test_rdf_of_a_mixture_matches_a_brute_force_histogram() -> None:
    """An independent O(N^2) numpy histogram of each pair of species (2D, walls of no kind)."""
    rng = np.random.default_rng(3)
    side, n, width, bins = 20.0, 300, 0.1, 100
    pos = rng.uniform(0.0, side, size=(n, 2))
    kinds = rng.integers(0, 2, size=n)
    counts = np.zeros((3, bins), dtype=np.int64)
    pair_histogram(pos, kinds, 2, np.full(2, side), width, counts)
    d = pos[:, None, :] - pos[None, :, :]
    d -= side * np.round(d / side)
    r = np.sqrt((d**2).sum(axis=2))
    i, j = np.triu_indices(n, 1)
    for row, (a, b) in enumerate([(0, 0), (0, 1), (1, 1)]):
        pick = ((kinds[i] == a) & (kinds[j] == b)) | ((kinds[i] == b) & (kinds[j] == a))
        expected = np.histogram(r[i, j][pick], bins=bins, range=(0.0, bins * width))[0]
        assert counts[row].tolist() == expected.tolist()


def test_ideal_gas_limit_g_is_one() -> None:
    gas = ExactGas(n=1000, dim=3, fraction=0.005, boundary="periodic", time=40.0).checked()
    world = gas.world()
    observer = observer_for(gas, world, ("rdf",), 20)
    report = run_on_world(gas, world, observer=observer)
    r = np.array(report["rdf"]["r"])
    g = np.array(report["rdf"]["pairs"][0]["g"])
    assert np.all(g[r < 2.0 - BIN_WIDTH] == 0.0)
    beyond = r > 4.0  # coarse shells (about 20,000 pairs each per sample): their mean
    assert float(g[beyond].mean()) == pytest.approx(1.0, abs=0.01)
    # each bin: Poisson scatter, 5 standard deviations
    expected = 20 * 1000 * 999 / 2 * (4 * math.pi * r[beyond] ** 2 * 0.04) / float(world.sides.prod())
    assert np.all(np.abs(g[beyond] - 1.0) < 5.0 / np.sqrt(expected))


def test_contact_value_gives_the_collision_compressibility_and_diffusion_is_near_enskog() -> None:
    """N = 4,000 spheres at 0.3, time 20, 50 samples over the last 16: about 6 s."""
    gas = ExactGas(n=4000, dim=3, fraction=0.3, boundary="periodic", time=20.0).checked()
    world = gas.world()
    report = run_on_world(gas, world, observer=observer_for(gas, world, ("rdf", "msd"), 50))
    z_contact, z_window = report["compressibility_contact"], report["compressibility_window"]
    assert z_contact == pytest.approx(z_window, rel=CONTACT_AGREEMENT)
    assert z_contact == pytest.approx(carnahan_starling(0.3), rel=CONTACT_AGREEMENT)
    contact = report["rdf"]["pairs"][0]["contact"]
    assert 1 + 4 * 0.3 * contact == pytest.approx(z_contact, rel=1e-12)
    ratio = report["diffusion"] / report["diffusion_enskog"]
    assert DIFFUSION_BAND[0] < ratio < DIFFUSION_BAND[1]


def test_msd_of_free_flight_is_ballistic() -> None:
    """No collision: every ball flies straight on, MSD(t) = <v^2> t^2 exactly (through the
    periodic faces: the unwrapping adds up nearest-image steps)."""
    gas = ExactGas(n=8, dim=3, fraction=1e-4, boundary="periodic", time=100.0).checked()
    world = gas.world()
    velocities = world.velocities
    report = run_on_world(gas, world, observer=observer_for(gas, world, ("msd",), 10))
    assert report["collisions"] == 0
    speed2 = float(np.einsum("ij,ij->", velocities, velocities)) / gas.n
    t = np.array(report["msd"]["t"])
    assert np.max(np.sqrt(speed2) * t) > float(world.sides[0])  # they cross the box
    np.testing.assert_allclose(report["msd"]["msd"], speed2 * t**2, rtol=1e-9)


def test_cli_observe_json_and_table() -> None:
    argv = ["gas", "--mode", "exact", "--n", "500", "--dim", "2", "--boundary", "periodic", "--time", "2",
            "--observe", "rdf,msd", "--samples", "5"]  # fmt: skip
    result = run_cli([*argv, "--format", "json", "--quiet"])  # (checked against the gas schema)
    assert result.status == 0, result.err
    report = result.json()
    assert report["rdf"]["samples"] == 5 and len(report["msd"]["t"]) == 5
    assert report["rdf"]["pairs"][0]["species"] == ["A", "A"]
    assert report["diffusion"] is not None and report["diffusion_enskog"] > 0
    # the same run as without --observe (observing stops the loop, never changes it)
    plain = run_cli([*argv[:-4], "--format", "json", "--quiet"]).json()
    assert (report["collisions"], report["compressibility"]) == (plain["collisions"], plain["compressibility"])
    table = run_cli([*argv, "--quiet"])
    assert table.status == 0 and "Z from g(sigma)" in table.out and "self-diffusion" in table.out


@pytest.mark.parametrize(("time", "samples"), [(2.0, 3), (0.7, 7), (10.0, 100)])
def test_the_last_sample_is_the_run_end_and_every_sample_is_taken(time: float, samples: int) -> None:
    # 0.4 + 1.6 * 3 / 3 rounds to 2.0000000000000004, past the run's end (2.0): that sample
    # was lost (2 of 3 taken) until the last sample time became the end itself.
    gas = ExactGas(n=50, dim=2, fraction=0.2, boundary="periodic", time=time).checked()
    world = gas.world()
    observer = observer_for(gas, world, ("rdf", "msd"), samples)
    assert observer.sample_times[-1] == run_end(time)
    report = run_on_world(gas, world, observer=observer)
    assert report["rdf"]["samples"] == samples and len(report["msd"]["t"]) == samples


def test_cli_observe_with_a_trajectory_writes_the_frames_it_writes_without(tmp_path: Path) -> None:
    # Observing stops the loop at its samples and the trajectory at its frames; neither changes
    # the run: the frames are byte for byte those of the same run without --observe.
    argv = ["gas", "--mode", "exact", "--n", "300", "--boundary", "periodic", "--time", "2", "--frames", "5",
            "--species", "big:0.5:1", "--species", "small:0.5:0.5", "--format", "json", "--quiet"]  # fmt: skip
    observed = run_cli([*argv, "--observe", "rdf,msd", "--samples", "3", "--trajectory", str(tmp_path / "o.xyz")])
    assert observed.status == 0, observed.err
    plain = run_cli([*argv, "--trajectory", str(tmp_path / "p.xyz")])
    assert plain.status == 0, plain.err
    report = observed.json()
    assert report["rdf"]["samples"] == 3 and len(report["msd"]["t"]) == 3
    assert report["trajectory_frames"] == 5 and report["collisions"] == plain.json()["collisions"] > 0
    written = (tmp_path / "o.xyz").read_bytes()
    assert written.count(b"Lattice=") == 5 and written == (tmp_path / "p.xyz").read_bytes()


def test_cli_observe_of_a_mixture() -> None:
    result = run_cli(["gas", "--mode", "exact", "--n", "400", "--boundary", "periodic", "--time", "2",
                      "--species", "big:0.5:1", "--species", "small:0.5:0.5", "--observe", "rdf",
                      "--samples", "4", "--format", "json", "--quiet"])  # fmt: skip
    assert result.status == 0, result.err
    pairs = result.json()["rdf"]["pairs"]
    assert [p["species"] for p in pairs] == [["big", "big"], ["big", "small"], ["small", "small"]]
    assert [p["sigma"] for p in pairs] == [2.0, 1.5, 1.0]


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--observe", "rdf,foo"], "collisionlab gas: --observe: must be a comma list of rdf, msd (got 'foo')"),
        (["--observe", "rdf", "--boundary", "walls"], "collisionlab gas: --observe: needs --boundary periodic"),
        (["--samples", "5"], "collisionlab gas: --samples: needs --observe rdf,msd"),
        (["--observe", "msd", "--samples", "0"], "collisionlab gas: --samples: must be 1 to 100,000 (got 0)"),
        (
            ["--observe", "msd", "--boundary", "walls", "--checkpoint", "c.npz"],
            "collisionlab gas: --observe: needs --boundary periodic",
        ),
        (["--samples", "5", "--checkpoint", "c.npz"], "collisionlab gas: --samples: needs --observe rdf,msd"),
    ],
)
def test_cli_observe_errors(extra: list[str], message: str, tmp_path: object) -> None:
    result = run_cli(["gas", "--mode", "exact", "--n", "200", "--boundary", "periodic", "--time", "1", *extra])
    assert result.status == 2
    assert result.err.startswith(message) and result.err.count("\n") == 1, result.err
