"""Sweep files: the [sweep] table, ranges, paths, points, seeds, and every bad input's one line."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from collisionlab.sweep.spec import SweepError, derived_seed, expand_range, load_sweep, parse_sweep

from .cli_helpers import EXAMPLES, run_cli


def spec_of(text: str, folder: Path = EXAMPLES) -> object:
    return parse_sweep(tomllib.loads(text), "s.toml", folder)


DT = """
[sweep]
demo = "sphere-plane"
metrics = ["first_collision_step"]
[sweep.parameters]
"simulation.dt" = [0.01, 0.02]
"""


def test_a_list_and_a_range_make_a_grid_in_order() -> None:
    spec = parse_sweep(
        tomllib.loads(
            """
[sweep]
demo = "sphere-plane"
replicas = 2
metrics = ["collisions", "momentum_end"]
[sweep.parameters]
"simulation.restitution" = {start = 0.5, stop = 1.0, step = 0.25}
"body.ball.velocity.y" = [-2, -4]
"""
        ),
        "s.toml",
    )
    values = [dict(p.values) for p in spec.points()]
    # 3 restitutions x 2 speeds, the last parameter varying fastest
    assert values == [
        {"simulation.restitution": e, "body.ball.velocity.y": v} for e in (0.5, 0.75, 1.0) for v in (-2, -4)
    ]
    tasks = spec.tasks()
    assert len(tasks) == 12 and [t.key for t in tasks[:3]] == [(0, 0), (0, 1), (1, 0)]
    # the point's values are in the scenario data the task carries; the rest of the vector is kept
    ball = tasks[3].data["body"][0]
    assert ball["velocity"] == [1, -4, 0.5] and tasks[3].data["simulation"]["restitution"] == 0.5
    assert spec.base["body"][0]["velocity"] == [1, -2, 0.5]  # the base itself is untouched


@pytest.mark.parametrize(
    ("table", "expected"),
    [
        (
            {"start": 0.1, "stop": 0.5, "step": 0.1},
            (0.1, 0.2, 0.3, 0.4, 0.5),
        ),  # 0.1 * 3 is 0.3, not 0.30000000000000004
        ({"start": 0.1, "stop": 0.45, "step": 0.1}, (0.1, 0.2, 0.3, 0.4)),  # stop not reached: not included
        ({"start": 1, "stop": 0, "step": -0.5}, (1.0, 0.5, 0.0)),  # downwards
        ({"start": 0, "stop": 1, "num": 5}, (0.0, 0.25, 0.5, 0.75, 1.0)),
        ({"start": 10, "stop": 40, "num": 4}, (10, 20, 30, 40)),  # whole numbers stay whole
        ({"start": 2.5, "stop": 9, "num": 1}, (2.5,)),
    ],
)
def test_ranges(table: dict[str, float], expected: tuple[float, ...]) -> None:
    values = expand_range("s.toml", table, "p")
    assert values == expected
    assert [type(v) for v in values] == [type(v) for v in expected]


def test_zip_pairs_values_and_a_scenario_file_is_found_beside_the_sweep(tmp_path: Path) -> None:
    (tmp_path / "drop.toml").write_text((EXAMPLES / "bouncing-ball.toml").read_text())
    spec = parse_sweep(
        tomllib.loads(
            """
[sweep]
scenario = "drop.toml"
combine = "zip"
metrics = ["energy_end"]
[sweep.parameters]
"simulation.restitution" = [0.5, 0.9]
"static.floor.restitution" = [0.1, 0.2]
"""
        ),
        "s.toml",
        tmp_path,
    )
    assert [dict(p.values) for p in spec.points()] == [
        {"simulation.restitution": 0.5, "static.floor.restitution": 0.1},
        {"simulation.restitution": 0.9, "static.floor.restitution": 0.2},
    ]
    assert spec.tasks()[1].data["static"][0]["restitution"] == 0.2


def test_the_gas_takes_its_defaults_from_collisionlab_gas() -> None:
    spec = parse_sweep(
        tomllib.loads(
            '[sweep]\nmetrics = ["collisions"]\n[sweep.gas]\nn = 50\n[sweep.parameters]\n"gas.fraction" = [0.1]'
        )
    )
    assert spec.kind == "gas" and spec.base["n"] == 50 and spec.base["dim"] == 2 and spec.base["steps"] == 1000
    assert spec.base["mode"] == "stepped"


def test_the_exact_gas_takes_its_defaults_from_collisionlab_gas_mode_exact() -> None:
    spec = parse_sweep(tomllib.loads(EXACT.replace("time = 1\n", "")))
    assert spec.kind == "gas" and dict(spec.base) == {
        "mode": "exact", "n": 64, "dim": 3, "fraction": 0.2, "boundary": "periodic", "time": 10.0,
        "restitution": 1.0, "gravity": 0.0,
    }  # fmt: skip
    assert spec.tasks()[0].data["fraction"] == 0.1


def test_seeds_depend_on_the_point_not_on_its_place() -> None:
    a = derived_seed(0, {"gas.fraction": 0.1}, 0)
    assert a == derived_seed(0, {"gas.fraction": 0.1}, 0)
    others = {derived_seed(0, {"gas.fraction": 0.2}, 0), derived_seed(0, {"gas.fraction": 0.1}, 1)}
    others.add(derived_seed(1, {"gas.fraction": 0.1}, 0))
    assert a not in others and len(others) == 3
    assert all(0 <= s < 2**31 for s in others)


def test_the_shipped_sweeps_read() -> None:
    for name, kind, rows in (
        ("sweep-dt", "scenario", 40),
        ("sweep-restitution", "scenario", 7),
        ("sweep-eos", "gas", 27),
        ("sweep-mixture", "gas", 15),
    ):
        spec = load_sweep(EXAMPLES / f"{name}.toml")
        assert spec.kind == kind and len(spec.tasks()) == rows
    eos = load_sweep(EXAMPLES / "sweep-eos.toml").base
    assert (eos["mode"], eos["boundary"], eos["dim"]) == ("exact", "periodic", 3)


BASE = '[sweep]\ndemo = "sphere-plane"\nmetrics = ["collisions"]\n[sweep.parameters]\n"simulation.dt" = [0.01]\n'
ZIPPED = BASE.replace("[0.01]", '[0, 1]\n"simulation.mode" = ["euler"]').replace(
    "[sweep]\n", '[sweep]\ncombine = "zip"\n'
)


EXACT = """
[sweep]
metrics = ["compressibility"]
[sweep.gas]
mode = "exact"
n = 64
dim = 3
boundary = "periodic"
time = 1
[sweep.parameters]
"gas.fraction" = [0.1]
"""


@pytest.mark.parametrize(
    ("text", "field", "words"),
    [
        ("[other]\n", "other", "unknown table"),
        ('[sweep]\nmetrics = ["collisions"]\n', "sweep", "exactly one base"),
        (BASE.replace('demo = "sphere-plane"', 'demo = "sphere-plane"\nscenario = "x.toml"'), "sweep", "exactly one"),
        (BASE.replace('"sphere-plane"', '"nope"'), "sweep.demo", "unknown demo"),
        (BASE.replace('demo = "sphere-plane"', 'scenario = "missing.toml"'), "sweep.scenario", "cannot read"),
        (BASE.replace("[sweep]\n", "[sweep]\nreplicas = 0\n"), "sweep.replicas", "whole number >= 1"),
        (BASE.replace("[sweep]\n", "[sweep]\nreplicas = 1.5\n"), "sweep.replicas", "whole number"),
        (BASE.replace("[sweep]\n", "[sweep]\nseed = -1\n"), "sweep.seed", ">= 0"),
        (BASE.replace("[sweep]\n", "[sweep]\ncolour = 1\n"), "sweep.colour", "unknown key"),
        (BASE.replace('["collisions"]', '["speed"]'), "sweep.metrics[0]", "unknown for a scenario"),
        (BASE.replace('["collisions"]', '["compressibility"]'), "sweep.metrics[0]", "expected one of"),
        (BASE.replace('metrics = ["collisions"]\n', ""), "sweep.metrics", "is missing"),
        (BASE.replace('["collisions"]', "[]"), "sweep.metrics", "non-empty list"),
        (BASE.replace('"simulation.dt" = [0.01]', '"simulation.speed" = [1]'), "simulation.speed", "unknown field"),
        (BASE.replace('"simulation.dt" = [0.01]', '"body.rock.mass" = [1]'), "body.rock.mass", "no body named 'rock'"),
        (BASE.replace('"simulation.dt" = [0.01]', '"gas.n" = [1]'), "gas.n", "expected simulation.KEY"),
        (BASE.replace('"simulation.dt" = [0.01]', '"body.ball.mass.x" = [1]'), "body.ball.mass.x", "as a vector"),
        (BASE.replace("[0.01]", "[]"), "sweep.parameters.simulation.dt", "non-empty list"),
        (BASE.replace("[0.01]", "0.01"), "sweep.parameters.simulation.dt", "non-empty list"),
        (BASE.replace("[0.01]", "{start = 0, stop = 1}"), "sweep.parameters.simulation.dt", "one of step or num"),
        (BASE.replace("[0.01]", "{start = 0, stop = 1, step = -1}"), "simulation.dt.step", "towards stop"),
        (BASE.replace("[0.01]", "{start = 0, stop = 1, num = 0}"), "simulation.dt.num", "whole number >= 1"),
        (BASE.replace("[0.01]", "{start = 0, stop = 1, num = 3, by = 2}"), "simulation.dt.by", "unknown key"),
        (BASE.replace("[0.01]", "{start = 0, stop = inf, num = 3}"), "simulation.dt.stop", "finite number"),
        (BASE.replace("[0.01]", "[nan]"), "simulation.dt[0]", "finite"),
        (ZIPPED, "sweep.combine", "as many"),
        (BASE.replace("[sweep]\n", '[sweep]\ncombine = "cross"\n'), "sweep.combine", "'grid' or 'zip'"),
        (BASE + "[sweep.plot]\nx = \"simulation.steps\"\n", "sweep.plot.x", "varied parameter"),
        (BASE + "[sweep.plot]\ny = \"energy_end\"\n", "sweep.plot.y", "one of the metrics"),
        ("[sweep]\nmetrics = [\"collisions\"]\n[sweep.gas]\nseed = 3\n", "sweep.gas.seed", "derived from sweep.seed"),
        ("[sweep]\nmetrics = [\"collisions\"]\n[sweep.gas]\nn = -5\n[sweep.parameters]\n\"gas.n\" = [1]\n",
         "sweep.gas", "the base is invalid: n: must be a whole number >= 1"),
        ("[sweep]\nmetrics = [\"collisions\"]\n[sweep.gas]\n[sweep.parameters]\n\"simulation.dt\" = [1]\n",
         "simulation.dt", "expected gas.KEY"),
        (EXACT.replace('mode = "exact"', 'mode = "events"'), "sweep.gas.mode", "must be one of 'stepped', 'exact'"),
        (EXACT.replace("n = 64", "steps = 100"), "sweep.gas.steps", "unknown key for the exact gas"),
        (EXACT.replace("n = 64", 'speeds = "equal"'), "sweep.gas.speeds", "unknown key for the exact gas"),
        (EXACT.replace("n = 64", "seed = 4"), "sweep.gas.seed", "derived from sweep.seed"),
        (EXACT.replace('"periodic"', '"torus"'), "sweep.gas", "the base is invalid: boundary: must be one of"),
        (EXACT.replace("time = 1", "time = -1"), "sweep.gas", "the base is invalid: time: must be > 0"),
        (EXACT.replace("time = 1", 'time = "long"'), "sweep.gas", "the base is invalid: time:"),
        (EXACT.replace("n = 64", "n = 64\ntc = -0.5"), "sweep.gas", "the base is invalid: tc: must be >= 0"),
        (EXACT.replace("n = 64", "n = 4"), "sweep.gas", "the base is invalid: fraction: too dense"),
        (EXACT.replace('"gas.fraction"', '"gas.steps"'), "gas.steps", "expected gas.KEY"),
        (EXACT.replace('"gas.fraction" = [0.1]', '"gas.mode" = ["stepped"]'), "gas.mode", "set in [sweep.gas]"),
        (EXACT.replace('["compressibility"]', '["ledger"]'), "sweep.metrics[0]", "unknown for the exact gas"),
        (EXACT.replace("\n[sweep.gas]\nmode", "\n[sweep.gas]\nkt = 1\nmode"), "sweep.gas.kt", "unknown key"),
    ],
)  # fmt: skip
def test_bad_sweep_files_fail_in_one_line_naming_the_field(tmp_path: Path, text: str, field: str, words: str) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(SweepError) as caught:
        load_sweep(path)
    assert field in str(caught.value) and words in str(caught.value)
    result = run_cli(["sweep", str(path), "--output", str(tmp_path / "out")])
    assert result.status == 65 and result.out == ""
    lines = result.err.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"collisionlab sweep: {path}: ") and field in lines[0]
    assert not list(tmp_path.glob("out*"))  # nothing written


def test_a_missing_file_and_bad_flags(tmp_path: Path) -> None:
    missing = run_cli(["sweep", str(tmp_path / "none.toml")])
    assert missing.status == 1 and "cannot be read" in missing.err and len(missing.err.splitlines()) == 1
    good = tmp_path / "good.toml"
    good.write_text(DT)
    both = run_cli(["sweep", str(good), "--workers", "2", "--scheduler", "tcp://127.0.0.1:1"])
    assert both.status == 2 and "--workers" in both.err
    zero = run_cli(["sweep", str(good), "--workers", "0"])
    assert zero.status == 2 and "--workers" in zero.err
    plot = run_cli(["sweep", str(good), "--plot", str(tmp_path / "no-such-folder" / "p.png")])
    assert plot.status == 2 and "--plot" in plot.err


# --- issue 11 (the audit): a sweep file is read as a scenario file is -----------------------------
@pytest.mark.parametrize(
    ("content", "field", "words"),
    [
        (b"\xff", "file", "is not UTF-8 text (byte 0xff at offset 0)"),  # was UnicodeDecodeError, exit 1
        (b"[sweep]\nx = " + b"[" * 500 + b"]" * 500 + b"\n", "file", "nested too deeply"),  # was RecursionError
        (b"# " + b"x" * 1_000_000 + b"\n", "file", "larger than 1,000,000 bytes"),
        (
            BASE.replace('demo = "sphere-plane"', 'scenario = "bad.toml"').encode(),
            "sweep.scenario",
            "bad.toml is not UTF-8",
        ),
    ],
    ids=["not-utf8", "nested", "too-large", "base-not-utf8"],
)
def test_a_sweep_file_is_read_as_a_scenario_file_is(tmp_path: Path, content: bytes, field: str, words: str) -> None:
    (tmp_path / "bad.toml").write_bytes(b"\xfe")
    path = tmp_path / "sweep.toml"
    path.write_bytes(content)
    with pytest.raises(SweepError) as caught:
        load_sweep(path)
    assert caught.value.field == field and words in str(caught.value)
    result = run_cli(["sweep", str(path)])
    assert result.status == 65 and result.err.strip().startswith(f"collisionlab sweep: {path}: {field}: ")


@pytest.mark.parametrize("where", ["the sweep file", "its base scenario"])
def test_an_endless_file_is_refused_without_reading_it_all(tmp_path: Path, where: str) -> None:
    # collisionlab sweep /dev/zero read on until memory ran out.
    path = Path("/dev/zero")
    if where == "its base scenario":
        path = tmp_path / "sweep.toml"
        path.write_text(BASE.replace('demo = "sphere-plane"', 'scenario = "/dev/zero"'))
    with pytest.raises(SweepError, match="larger than 1,000,000 bytes"):
        load_sweep(path)
