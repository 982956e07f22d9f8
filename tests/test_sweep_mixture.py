"""Sweeps of a gas mixture: ``[[sweep.gas.species]]`` in the exact gas's base, ``gas.species.NAME.KEY``
varied, and the shipped sweep-mixture.toml (Z against the size ratio beside BMCSL) run small."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from collisionlab.edmd.theory import bmcsl, carnahan_starling
from collisionlab.sweep.spec import SweepError, load_sweep, parse_sweep

from .cli_helpers import EXAMPLES, run_cli

MIXTURE = EXAMPLES / "sweep-mixture.toml"

#: |Z / Z_BMCSL - 1| at most, for one row of 200 balls over time 10 at fraction 0.3: over 12
#: seeds per point such a row's Z scattered by a standard deviation of 0.6% (ratio 0.5) and
#: 0.8% (ratio 1), its mean 0.8-0.9% above BMCSL (few balls, averaged from the lattice start);
#: 5% is that offset and five standard deviations.
TOLERANCE = 0.05


def small(text: str, **changes: object) -> str:
    """The shipped sweep's text with [sweep.gas] keys and the parameter's values changed."""
    data = tomllib.loads(text)
    gas = data["sweep"]["gas"]
    lines = text.splitlines()
    for key, value in changes.items():
        if key == "radii":
            lines = [f'"gas.species.small.radius" = {value}' if line.startswith('"gas.species.small.radius"') else line
                     for line in lines]  # fmt: skip
        elif key == "replicas":
            lines = [f"replicas = {value}" if line.startswith("replicas =") else line for line in lines]
        else:
            assert key in gas
            lines = [f"{key} = {value}" if line.startswith(f"{key} =") else line for line in lines]
    return "\n".join(lines) + "\n"


def test_the_shipped_mixture_sweep_reads() -> None:
    spec = load_sweep(MIXTURE)
    assert spec.kind == "gas" and spec.base["mode"] == "exact" and len(spec.tasks()) == 15
    assert [sp["name"] for sp in spec.base["species"]] == ["big", "small"]
    assert spec.plot_x == "gas.species.small.radius" and spec.plot_y == "compressibility"
    assert "compressibility_theory" in spec.metrics
    radii = [task.data["species"][1]["radius"] for task in spec.tasks()]
    assert sorted(set(radii)) == [0.5, 0.625, 0.75, 0.875, 1.0]
    assert all(task.data["species"][0]["radius"] == 1.0 for task in spec.tasks())  # the big ones stay


def test_the_mixture_sweep_measures_z_beside_bmcsl(tmp_path: Path) -> None:
    sweep = tmp_path / "mix.toml"
    sweep.write_text(small(MIXTURE.read_text(), n=200, time=10, replicas=1, radii="[0.5, 1.0]"))
    result = run_cli(["sweep", str(sweep), "--output", str(tmp_path / "out"), "--workers", "1", "--plot",
                      str(tmp_path / "out.png")])  # fmt: skip
    assert result.status == 0, result.err
    rows = pq.read_table(tmp_path / "out.parquet").to_pylist()
    assert len(rows) == 2 and all(row["error"] == "" for row in rows)
    for row in rows:
        ratio = row["gas.species.small.radius"]
        # 100 balls of each (half of 200): BMCSL at the total fraction, diameters 2 and 2 r
        assert row["compressibility_theory"] == pytest.approx(bmcsl([0.5, 0.5], [2.0, 2.0 * ratio], 0.3), rel=1e-12)
        assert abs(row["compressibility"] / row["compressibility_theory"] - 1.0) < TOLERANCE, row
        assert row["kt"] == pytest.approx(1.0, rel=1e-9) and abs(row["energy_drift"]) < 1e-9
    one_kind = next(row for row in rows if row["gas.species.small.radius"] == 1.0)
    assert one_kind["compressibility_theory"] == pytest.approx(carnahan_starling(0.3), rel=1e-12)
    assert (tmp_path / "out.png").stat().st_size > 0


#: A varied parameter's field in the messages.
P = "sweep.parameters.gas.species."

EXACT = """
[sweep]
metrics = ["compressibility"]
[sweep.gas]
mode = "exact"
n = 64
dim = 3
boundary = "periodic"
time = 1
[[sweep.gas.species]]
name = "big"
fraction = 0.5
radius = 1
[[sweep.gas.species]]
name = "small"
fraction = 0.5
radius = 0.5
[sweep.parameters]
"gas.species.small.radius" = [0.5]
"""


@pytest.mark.parametrize(
    ("text", "field", "words"),
    [
        (EXACT.replace("small.radius", "huge.radius"), P + "huge.radius", "no species named 'huge'"),
        (EXACT.replace("small.radius", "small.name"), P + "small.name", "KEY one of fraction, radius, mass"),
        (EXACT.replace("small.radius", "small"), P + "small", "gas.species.NAME.KEY"),
        (EXACT.replace('name = "small"', 'name = "small"\ncolour = 1'), "sweep.gas", "unknown key 'colour'"),
        (EXACT.replace("radius = 0.5", ""), "sweep.gas", "missing 'radius'"),
        (EXACT.replace("fraction = 0.5\nradius = 1", "fraction = 0.7\nradius = 1"), "sweep.gas", "sum to 1"),
        (EXACT.replace('mode = "exact"', 'mode = "stepped"').replace("boundary", "#").replace("time", "#"),
         "sweep.gas.species",
         "unknown key for the stepped gas"),
    ],
)  # fmt: skip
def test_bad_species_in_a_sweep_are_one_line_naming_the_field(text: str, field: str, words: str) -> None:
    with pytest.raises(SweepError) as caught:
        parse_sweep(tomllib.loads(text), "s.toml")
    message = str(caught.value)
    assert message.startswith(f"s.toml: {field}") and words in message and "\n" not in message, message


def test_the_fractions_vary_together_with_zip() -> None:
    varied = '"gas.species.big.fraction" = [0.25, 0.75]\n"gas.species.small.fraction" = [0.75, 0.25]'
    text = EXACT.replace('"gas.species.small.radius" = [0.5]', varied)
    tasks = parse_sweep(tomllib.loads(text.replace("[sweep]\n", '[sweep]\ncombine = "zip"\n')), "s.toml").tasks()
    assert [[sp["fraction"] for sp in task.data["species"]] for task in tasks] == [[0.25, 0.75], [0.75, 0.25]]
