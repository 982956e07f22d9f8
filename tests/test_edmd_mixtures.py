"""Mixtures in the event-driven engine: the unequal-mass collision, lists and cells sized for
mixed radii, the equations of state of binary mixtures, and ``--species`` on the command line.

Oracles independent of the code under test: the textbook elastic collision in one dimension
(momentum and energy kept, worked by hand), a brute-force O(N^2) overlap check of every pair,
and closed forms from the literature: Boublik-Mansoori-Carnahan-Starling-Leland (BMCSL) in 3D,
Santos, Yuste and Lopez de Haro (Mol. Phys. 96, 1 (1999)) on Henderson in 2D, each reduced by
hand to Carnahan-Starling / Henderson for one kind and to the exact second virial coefficient.
"""

from __future__ import annotations

import io
import json
import math
from pathlib import Path

import numpy as np
import pytest

from collisionlab.cli import main
from collisionlab.cli.streams import Streams
from collisionlab.edmd import EventDrivenWorld
from collisionlab.edmd.observables import ExactGas, Species, parse_species, species_counts
from collisionlab.edmd.theory import (
    bmcsl,
    carnahan_starling,
    disc_mixture,
    enskog_collision_rate,
    enskog_pair_rates,
    henderson,
    mixture_contact_values,
    number_density,
)
from collisionlab.errors import InvalidInputError
from collisionlab.tolerances import START_GAP
from tests.cli_helpers import run_cli

#: Rounding of a few operations on numbers of order 1.
ROUNDING = 1e-12
#: The deepest overlap a run may leave, in length units (the engine's: rounding, 1e-14 measured).
OVERLAP = 1e-9
BINARY = (Species("big", 0.5, 1.0), Species("small", 0.5, 0.5))


# --- the collision of unequal balls ----------------------------------------------------------
def test_unequal_masses_collide_as_the_textbook_says() -> None:
    # Head on along x: m1 = 1 at +1, m2 = 3 at -1; radii 1 and 0.5, centres 4 apart: the gap of
    # 4 - 1.5 = 2.5 closes at speed 2 at t = 1.25. Elastic in 1D:
    # v1' = ((m1 - m2) v1 + 2 m2 v2) / (m1 + m2) = (-2 - 6) / 4 = -2
    # v2' = ((m2 - m1) v2 + 2 m1 v1) / (m1 + m2) = (-2 + 2) / 4 = 0
    # impulse j = 2 mu v_rel = 2 (3/4) 2 = 3; virial r . dp = 1.5 * 3 = 4.5
    w = EventDrivenWorld(
        [[2.0, 5.0], [6.0, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], [10.0, 10.0],
        radius=[1.0, 0.5], mass=[1.0, 3.0], periodic=False,
    )  # fmt: skip
    events: list[np.ndarray] = []
    w.run(1.3, sink=lambda block: events.append(block.copy()))
    v = w.velocities
    assert v[0, 0] == pytest.approx(-2.0, abs=ROUNDING) and v[1, 0] == pytest.approx(0.0, abs=ROUNDING)
    (row,) = np.concatenate(events)
    assert row[0] == pytest.approx(1.25, abs=ROUNDING) and row[3] == pytest.approx(3.0, abs=ROUNDING)
    assert w.tally().virial == pytest.approx(4.5, abs=ROUNDING)
    assert w.tally().species_collisions == ((0, 1), (1, 0))
    momentum = (w.masses[:, None] * v).sum(axis=0)
    assert momentum[0] == pytest.approx(1.0 - 3.0, abs=ROUNDING)  # kept: 1 * 1 + 3 * (-1)
    assert w.kinetic_energy() == pytest.approx(0.5 * 1 + 0.5 * 3, abs=ROUNDING)  # kept: 2


def test_an_inelastic_unequal_collision_loses_what_theory_says() -> None:
    # e = 0.5, oblique: the loss is (1 - e^2)/2 mu v_n^2, mu = m1 m2 / (m1 + m2) = 2/3
    e = 0.5
    w = EventDrivenWorld(
        [[3.0, 5.0], [7.0, 5.6]], [[1.0, 0.0], [-1.0, 0.0]], [12.0, 12.0],
        radius=[1.0, 1.5], mass=[1.0, 2.0], restitution=e, periodic=False,
    )  # fmt: skip
    p0 = (w.masses[:, None] * w.velocities).sum(axis=0)
    e0 = w.kinetic_energy()
    w.run(1.5)
    tally = w.tally()
    assert tally.pair_collisions == 1
    # at contact |dr| = 2.5: dx = sqrt(2.5^2 - 0.6^2), normal speed v_n = 2 dx / 2.5
    vn = 2.0 * math.sqrt(2.5**2 - 0.36) / 2.5
    lost = 0.5 * (1.0 - e * e) * (2.0 / 3.0) * vn * vn
    assert e0 - w.kinetic_energy() == pytest.approx(lost, rel=ROUNDING)
    assert tally.energy_lost == pytest.approx(lost, rel=ROUNDING)
    p1 = (w.masses[:, None] * w.velocities).sum(axis=0)
    assert np.allclose(p1, p0, atol=ROUNDING, rtol=0.0)


# --- lists and cells with mixed radii: no collision missed -----------------------------------
def _deepest_overlap_by_brute_force(world: EventDrivenWorld) -> float:
    """The deepest overlap of any two balls (every pair, nearest image) or ball and wall."""
    pos, radii, sides = world.positions, world.radii, world.sides
    d = pos[:, None, :] - pos[None, :, :]
    if world.periodic:
        d -= np.round(d / sides) * sides
    dist = np.sqrt((d * d).sum(axis=2))
    depth = radii[:, None] + radii[None, :] - dist
    np.fill_diagonal(depth, -np.inf)
    worst = float(depth.max())
    if not world.periodic:
        worst = max(worst, float((radii[:, None] - pos).max()), float((pos + radii[:, None] - sides).max()))
    return worst


@pytest.mark.parametrize(
    ("dim", "boundary", "ratio"), [(3, "periodic", 0.3), (2, "walls", 0.25), (3, "walls", 0.5), (2, "periodic", 0.6)]
)
def test_mixed_radii_leave_no_overlap_checked_pair_by_pair(dim: int, boundary: str, ratio: float) -> None:
    # A few large balls among many small, fast ones: the lists must reach the sum of the two
    # largest radii, and the small balls' skins be their own. Checked at many moments. (Fraction
    # 0.1: the start's lattice is spaced for the largest balls.)
    species = (Species("large", 0.2, 1.0), Species("small", 0.8, ratio))
    world = ExactGas(n=600, dim=dim, fraction=0.1, boundary=boundary, species=species).world()
    collisions = 0
    for t in np.linspace(0.5, 10.0, 20):
        world.run(float(t))
        assert _deepest_overlap_by_brute_force(world) < OVERLAP
    collisions = world.tally().pair_collisions
    assert collisions > 1_000 and world.tally().max_contact_overlap < OVERLAP
    assert world.kinetic_energy() == pytest.approx(0.5 * dim * 600, rel=ROUNDING)  # elastic: kept


def test_a_mixture_under_gravity_with_e_below_one_settles_without_overlap() -> None:
    species = (Species("a", 0.5, 1.0), Species("b", 0.5, 0.6))
    world = ExactGas(n=300, dim=2, fraction=0.1, gravity=1.0, restitution=0.7, species=species).world()
    world.run(30.0)
    assert _deepest_overlap_by_brute_force(world) < OVERLAP
    assert world.kinetic_energy() < 0.05 * 300  # from kT = 1 a ball: most of it dissipated


# --- a mixture too dense for a lattice ----------------------------------------------------------
def _closest_by_brute_force(world: EventDrivenWorld) -> float:
    """The smallest ``d_ij / (r_i + r_j)`` over every pair (nearest images), and ``d / r`` from
    every wall, by an O(N^2) sweep of numpy."""
    pos, radii, sides = world.positions, world.radii, world.sides
    d = pos[:, None, :] - pos[None, :, :]
    if world.periodic:
        d -= np.round(d / sides) * sides
    ratio = np.sqrt((d * d).sum(axis=2)) / (radii[:, None] + radii[None, :])
    np.fill_diagonal(ratio, np.inf)
    closest = float(ratio.min())
    if not world.periodic:
        closest = min(closest, float((pos / radii[:, None]).min()), float(((sides - pos) / radii[:, None]).min()))
    return closest


@pytest.mark.parametrize(
    ("dim", "boundary", "fraction"), [(3, "periodic", 0.5), (3, "walls", 0.45), (2, "walls", 0.65)]
)
def test_a_mixture_too_dense_for_a_lattice_starts_spread_apart(dim: int, boundary: str, fraction: float) -> None:
    # A lattice spaced for the largest balls holds radii 1 and 0.5, half each, only up to
    # 0.74 / ((1 + 1/8) / 2) = 0.42 (3D, fcc) and 0.785 / ((1 + 1/4) / 2) = 0.49 (2D): these start
    # spread apart, no pair closer than (r_i + r_j)(1 + START_GAP / 2), in the box of the
    # fraction asked, and then run without overlap, keeping their energy (elastic).
    n = 600
    world = ExactGas(n=n, dim=dim, fraction=fraction, boundary=boundary, species=BINARY).world()
    assert _closest_by_brute_force(world) >= 1.0 + START_GAP / 2
    ball = (4.0 / 3.0 if dim == 3 else 1.0) * math.pi * world.radii**dim
    assert float(ball.sum() / world.sides.prod()) == pytest.approx(fraction, rel=ROUNDING)
    assert np.unique(world.radii, return_counts=True)[1].tolist() == [n // 2, n // 2]
    world.run(2.0)
    assert world.tally().pair_collisions > 10 * n
    assert _deepest_overlap_by_brute_force(world) < OVERLAP
    assert world.kinetic_energy() == pytest.approx(0.5 * dim * n, rel=ROUNDING)


def test_a_dense_disc_mixture_started_spread_apart_meets_its_equation_of_state() -> None:
    # Fraction 0.55 in 2D is past the lattice (0.49, above). From the spread start, relaxed for
    # 2 time units and measured over 300 (about 1.3 M collisions): Z against Santos, Yuste and
    # Lopez de Haro's equation, whose own error grows with density (measured here: -0.78%; at
    # 0.6 -1.15%), and equipartition (measured 0.05%).
    result = _binary(2, 2000, 0.55, 2.0, 300.0)
    assert result["z"] == pytest.approx(result["theory"], rel=0.02)
    assert result["kt_small"] == pytest.approx(result["kt_big"], rel=0.01)


def test_a_mixture_denser_than_it_packs_is_refused_in_one_line() -> None:
    species = ["--species", "big:0.5:1", "--species", "small:0.5:0.5"]
    status, out, err = _cli(
        ["--mode", "exact", "--n", "600", "--dim", "3", "--fraction", "0.74", "--time", "1", *species]
    )
    assert status != 0 and out == ""
    assert err.count("\n") == 1 and err.startswith("collisionlab gas: --fraction: too dense to start this mixture")
    assert "Traceback" not in err


def test_a_dense_mixture_in_too_narrow_a_periodic_box_is_refused_in_one_line() -> None:
    # 20 balls of radii 1 and 0.5 at 0.6 in 2D: side sqrt(20 pi (1 + 1/4) / 2 / 0.6) = 8.09, and a
    # periodic box must be 4 largest diameters (8) wide; at 0.65 it is 7.78: refused, not spread.
    argv = ["--mode", "exact", "--n", "20", "--dim", "2", "--boundary", "periodic", "--time", "1"]
    argv += ["--species", "big:0.5:1", "--species", "small:0.5:0.5"]
    status, out, err = _cli([*argv, "--fraction", "0.65"])
    assert status != 0 and out == "" and err.count("\n") == 1
    assert err.startswith("collisionlab gas: --fraction: too dense to start this mixture: a periodic box must be")
    status, _, _ = _cli([*argv, "--fraction", "0.6"])
    assert status == 0


# --- theory ------------------------------------------------------------------------------------
def test_mixture_equations_reduce_to_one_kind_by_hand() -> None:
    for eta in (0.1, 0.3, 0.45):
        assert bmcsl([1.0], [2.0], eta) == pytest.approx(carnahan_starling(eta), rel=ROUNDING)
        assert bmcsl([0.5, 0.5], [2.0, 2.0], eta) == pytest.approx(carnahan_starling(eta), rel=ROUNDING)
        assert disc_mixture([0.3, 0.7], [1.0, 1.0], eta) == pytest.approx(henderson(eta), rel=ROUNDING)
    # Enskog per pair, one kind: the one-kind rate of theory.enskog_collision_rate
    for dim in (2, 3):
        (row,) = enskog_pair_rates([1.0], [2.0], [1.0], 0.3, dim, 1.0)
        assert row[0] == pytest.approx(enskog_collision_rate(0.3, dim, 1.0, 1.0, 1.0), rel=ROUNDING)


def test_bmcsl_at_a_point_worked_by_hand() -> None:
    # x = (1/2, 1/2), sigma = (2, 1), eta = 0.3: <s^3> = 4.5, rho = 0.3 / (pi/6 * 4.5) = 0.4 / pi;
    # xi_k = (pi/6) rho <s^k> = <s^k> / 15: xi_0 = 1/15, xi_1 = 0.1, xi_2 = 1/6, xi_3 = 0.3;
    # Z = 15 [ (1/15)/0.7 + 3 (0.1)(1/6)/0.49 + 2.7 (1/216)/0.343 ]
    #   = 1/0.7 + 0.75/0.49 + 40.5/(216 * 0.343) = 1.4285714 + 1.5306122 + 0.5466472 = 3.5058309
    expected = 1 / 0.7 + 0.75 / 0.49 + 40.5 / (216 * 0.343)
    assert bmcsl([0.5, 0.5], [2.0, 1.0], 0.3) == pytest.approx(expected, rel=ROUNDING)
    assert expected == pytest.approx(3.5058309, abs=1e-7)


def test_2d_mixture_has_the_exact_second_virial_coefficient() -> None:
    # Z = 1 + B2 rho + ..., B2 = (pi/2) sum x_a x_b sigma_ab^2 (exact for discs): at eta -> 0,
    # (Z - 1) / eta -> 1 + <s>^2 / <s^2>. Here x = (0.3, 0.7), s = (2, 1): <s> = 1.3, <s^2> = 1.9.
    eta = 1e-7
    slope = (disc_mixture([0.3, 0.7], [2.0, 1.0], eta) - 1.0) / eta
    assert slope == pytest.approx(1.0 + 1.3**2 / 1.9, rel=1e-6)


@pytest.mark.parametrize("dim", [2, 3])
def test_contact_values_give_the_equation_of_state_through_the_virial(dim: int) -> None:
    # Z = 1 + (2 pi / 3) rho sum x_a x_b s_ab^3 g_ab (3D), 1 + (pi / 2) rho sum x_a x_b s_ab^2 g_ab (2D)
    x, s = [0.2, 0.5, 0.3], [2.0, 1.0, 0.6]
    for eta in (0.1, 0.3, 0.45):
        g = mixture_contact_values(x, s, eta, dim)
        rho = number_density(x, s, eta, dim)
        total = sum(x[a] * x[b] * ((s[a] + s[b]) / 2) ** dim * g[a][b] for a in range(3) for b in range(3))
        virial = 1.0 + (2.0 * math.pi / 3.0 if dim == 3 else math.pi / 2.0) * rho * total
        eos = bmcsl(x, s, eta) if dim == 3 else disc_mixture(x, s, eta)
        assert virial == pytest.approx(eos, rel=ROUNDING)


# --- a binary mixture against its equation of state ------------------------------------------
def _binary(dim: int, n: int, fraction: float, relax: float, window: float) -> dict[str, float]:
    gas = ExactGas(n=n, dim=dim, fraction=fraction, boundary="periodic", species=BINARY).checked()
    world = gas.world()
    world.run(relax)
    a, energy_a = world.tally(), world.species_mean_energy() * relax
    world.run(relax + window)
    b, energy_b = world.tally(), world.species_mean_energy() * (relax + window)
    counts = species_counts(gas.species, n)
    kts = [2.0 * (energy_b[k] - energy_a[k]) / window / (dim * counts[k]) for k in range(2)]
    kt = sum(c * k for c, k in zip(counts, kts, strict=True)) / n
    z = 1.0 + (b.virial - a.virial) / (dim * n * kt * window)
    x = [c / n for c in counts]
    theory = bmcsl(x, [2.0, 1.0], fraction) if dim == 3 else disc_mixture(x, [2.0, 1.0], fraction)
    masses = [sp.mass_in(dim) for sp in gas.species]
    enskog = enskog_pair_rates(x, [2.0, 1.0], masses, fraction, dim, kt)
    hits = [[b.species_collisions[i][j] - a.species_collisions[i][j] for j in range(2)] for i in range(2)]
    ratios = [hits[i][j] / (counts[i] * window) / enskog[i][j] for i in range(2) for j in range(2)]
    return {"z": z, "theory": theory, "kt_big": kts[0], "kt_small": kts[1], "rate_ratios": ratios}


@pytest.mark.parametrize(("dim", "n", "window"), [(3, 2000, 200.0), (2, 2000, 300.0)])
def test_a_binary_mixture_meets_its_equation_of_state_and_equipartition(dim: int, n: int, window: float) -> None:
    # Size ratio 0.5, half of each by number, total fraction 0.3, periodic, at N = 2,000 (the
    # issue's N = 4,000 and 0.5% is bench/bench_edmd.py --mixtures). The species' energy partition
    # fluctuates slowly (mass ratio 8 in 3D: block means over 5 time units scatter by 2%,
    # measured), so the kT ratio over a window of 40 scattered by 0.6% between seeds: over 200
    # it is about 0.25%, and 1% is a real test; Z scattered by 0.1-0.3% over 40.
    result = _binary(dim, n, 0.3, 2.0, window)
    assert result["z"] == pytest.approx(result["theory"], rel=0.005)
    assert result["kt_small"] == pytest.approx(result["kt_big"], rel=0.01)
    # Enskog per pair of species: within 2% (Enskog's own error at 0.3 is about 1%, measured)
    assert result["rate_ratios"] == pytest.approx([1.0] * 4, rel=0.02)


# --- the command line --------------------------------------------------------------------------
def _cli(argv: list[str]) -> tuple[int, str, str]:
    streams = Streams(stdin=io.StringIO(), stdout=io.StringIO(), stderr=io.StringIO(), interactive=False)
    status = main(["gas", *argv], streams)
    return status, streams.stdout.getvalue(), streams.stderr.getvalue()  # type: ignore[attr-defined]


def test_parse_species() -> None:
    assert parse_species("big:0.5:1") == Species("big", 0.5, 1.0, None)
    assert parse_species("s:0.25:0.5:3").mass == 3.0
    assert Species("s", 0.5, 0.5).mass_in(3) == 0.125 and Species("s", 0.5, 0.5).mass_in(2) == 0.25
    assert species_counts((Species("a", 1 / 3, 1.0), Species("b", 2 / 3, 1.0)), 100) == [33, 67]


@pytest.mark.parametrize(
    ("species", "words"),
    [
        (["a:0.5:1", "b:0.4:0.5"], "sum to 1"),
        (["a:0.5:0", "b:0.5:1"], "RADIUS must be > 0"),
        (["a:0.5:-1", "b:0.5:1"], "RADIUS must be > 0"),
        (["a:nan:1", "b:0.5:1"], "finite"),
        (["a:0.5:nan", "b:0.5:1"], "finite"),
        (["a:0.5:1", "a:0.5:1"], "each NAME once"),
        (["a:0.5", "b:0.5:1"], "3 or 4 fields"),
        (["a:0.5:1:2:3", "b:0.5:1"], "3 or 4 fields"),
        (["a:0.5:1:0", "b:0.5:1"], "MASS must be > 0"),
        (["a:half:1", "b:0.5:1"], "must be a number"),
        ([":0.5:1", "b:0.5:1"], "name"),
    ],
)
def test_bad_species_say_so_in_one_line(species: list[str], words: str) -> None:
    argv = ["--mode", "exact", "--n", "100", "--time", "0.1"]
    for text in species:
        argv += ["--species", text]
    status, out, err = _cli(argv)
    assert status == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("collisionlab gas: --species: ") and words in err
    assert "NAME:FRACTION:RADIUS[:MASS]" in err and "Traceback" not in err


def test_species_need_the_exact_mode_and_take_a_trajectory(tmp_path: Path) -> None:
    status, _, err = _cli(["--n", "100", "--species", "a:1:1"])
    assert status == 2 and "--species" in err and "--mode exact" in err
    path = tmp_path / "t.xyz"  # (tests/test_gas_trajectory.py reads a mixture's frames back)
    argv = ["--mode", "exact", "--n", "100", "--time", "0.1", "--species", "a:1:1", "--trajectory", str(path)]
    status, _, err = _cli([*argv, "--quiet"])
    assert status == 0 and err == "" and path.exists()


def test_the_json_reports_each_species_and_each_pair() -> None:
    result = run_cli(
        [
            "gas",
            "--mode",
            "exact",
            "--n",
            "1000",
            "--dim",
            "3",
            "--boundary",
            "periodic",
            "--fraction",
            "0.3",
            "--time",
            "4",
            "--format",
            "json",
            "--species",
            "big:0.5:1",
            "--species",
            "small:0.5:0.5",
        ]
    )  # fmt: skip  (run_cli checks the output against the shipped gas schema)
    assert result.status == 0, result.err
    report = result.json()
    big, small = report["species"]
    assert (big["name"], big["count"], big["radius"], big["mass"]) == ("big", 500, 1.0, 1.0)
    assert (small["name"], small["count"], small["radius"], small["mass"]) == ("small", 500, 0.5, 0.125)
    # the time-averaged kTs, weighted by count, give the mean kinetic energy (kT 1 at the start, elastic)
    assert 0.5 * (big["kT"] + small["kT"]) == pytest.approx(1.0, rel=1e-9)
    pairs = {tuple(p["species"]): p for p in report["pair_collision_rates"]}
    assert set(pairs) == {("big", "big"), ("big", "small"), ("small", "big"), ("small", "small")}
    total = sum(p["collisions"] for key, p in pairs.items() if key != ("small", "big"))
    assert total == report["collisions"]
    assert pairs["big", "small"]["collisions"] == pairs["small", "big"]["collisions"]
    # one ball's rate summed over partners is the collision rate per ball (averaged over species)
    per_ball = (pairs["big", "big"]["rate"] + pairs["big", "small"]["rate"] + pairs["small", "big"]["rate"]
                + pairs["small", "small"]["rate"]) / 2  # fmt: skip
    assert per_ball == pytest.approx(report["collision_rate"], rel=1e-12)
    for p in pairs.values():  # a short run from the lattice: loosely (closely in the test above)
        assert p["rate"] == pytest.approx(p["rate_enskog"], rel=0.25)
    assert report["compressibility_theory"] == pytest.approx(bmcsl([0.5, 0.5], [2.0, 1.0], 0.3), rel=ROUNDING)
    assert report["max_overlap"] < OVERLAP and abs(report["energy_drift"]) < 1e-12


def test_the_table_and_the_events_file_of_a_mixture(tmp_path: object) -> None:
    from pathlib import Path

    events = Path(str(tmp_path)) / "e.csv"
    status, out, err = _cli(
        ["--mode", "exact", "--n", "200", "--dim", "2", "--time", "2", "--species", "a:0.25:1", "--species",
         "b:0.75:0.5:2", "--events", str(events)]
    )  # fmt: skip
    assert status == 0, err
    assert "species a        50 balls, radius 1, mass 1, kT" in out and "rate b -> a" in out
    lines = events.read_text().splitlines()
    assert lines[0] == "time,a,b,impulse"
    times = [float(line.split(",")[0]) for line in lines[1:]]
    assert times == sorted(times) and len(times) > 50
    for line in lines[1:]:
        _, a, b, _ = line.split(",")
        assert b[0] in "xy" or int(a) < int(b)  # a wall named, or the lower index first


def test_fractions_sum_within_rounding_and_mass_defaults_to_volume() -> None:
    gas = ExactGas(n=30, dim=3, species=(Species("a", 0.3333333, 1.0), Species("b", 0.6666667, 2.0))).checked()
    assert sum(sp.fraction for sp in gas.species) == pytest.approx(1.0, abs=ROUNDING)
    _, radii, masses, counts = gas.mixture()
    assert counts == [10, 20] and set(masses.tolist()) == {1.0, 8.0} and set(radii.tolist()) == {1.0, 2.0}
    with pytest.raises(InvalidInputError, match="no ball"):
        ExactGas(n=3, species=(Species("a", 0.9, 1.0), Species("b", 0.1, 2.0))).checked()


def test_one_species_through_species_reports_itself() -> None:
    status, out, err = _cli(["--mode", "exact", "--n", "300", "--time", "2", "--format", "json", "--species", "a:1:1"])
    assert status == 0, err
    report = json.loads(out)
    assert [sp["count"] for sp in report["species"]] == [300]
    (pair,) = report["pair_collision_rates"]
    assert pair["species"] == ["a", "a"] and pair["collisions"] == report["collisions"]
