"""The shipped examples from any install: ``run NAME``, ``examples``, ``examples --copy DIR``;
and the flag combinations issue 13 found surprising (--explain with JSON, demo picture names)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from collisionlab.demos import SWEEP_PREFIX, builtin_scenario_path, demo_names, demo_text
from tests.cli_helpers import files_in, run_cli


@pytest.mark.parametrize("spelling", ["head-on", "head-on.toml", "examples/head-on.toml"])
def test_run_finds_a_builtin_scenario_by_name_from_any_folder(
    spelling: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)  # no examples/ folder here, as after pip install
    result = run_cli(["run", spelling, "--quiet"])
    assert result.status == 0, result.err
    # head-on: 1 kg at +1 m/s meets 3 kg at -1 m/s, e = 1: v_light = -2.5, v_heavy = 0.5 (momentum -2).
    assert "light = (-2.500, 0.000), heavy = (0.500, 0.000) m/s" in result.out


def test_a_real_file_wins_over_a_builtin_name(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    Path("head-on").write_text(demo_text("spheres"), encoding="utf-8")  # a file that happens to be named so
    assert run_cli(["run", "head-on", "--quiet"]).out.startswith("Lab case 2: sphere and sphere")


def test_an_unknown_name_is_a_missing_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    result = run_cli(["run", "no-such-scenario"])
    assert result.status == 1 and "no-such-scenario: cannot be read" in result.err
    assert builtin_scenario_path("elsewhere/head-on.toml") is None  # only bare names and examples/NAME


def test_examples_lists_every_builtin_with_its_title_and_where_it_is() -> None:
    result = run_cli(["examples"])
    assert result.status == 0
    for name in demo_names():
        assert any(line.startswith(name + " ") for line in result.lines)
    assert "head-on         Head-on collision, 1 kg and 3 kg" in result.lines
    shipped = Path(result.out.split("shipped in ")[1].splitlines()[0])
    scenarios = [p.stem for p in shipped.glob("*.toml") if not p.stem.startswith(SWEEP_PREFIX)]  # sweeps aside
    assert sorted(scenarios) == sorted(demo_names())


def test_examples_copy_writes_every_file_unchanged_and_never_overwrites(tmp_path: Path) -> None:
    target = tmp_path / "mine"
    result = run_cli(["examples", "--copy", str(target)])
    assert result.status == 0 and f"wrote {len(demo_names())} scenario files to {target}" in result.err
    assert files_in(target) == sorted(f"{name}.toml" for name in demo_names())  # no temporary files
    for name in demo_names():
        assert (target / f"{name}.toml").read_text(encoding="utf-8") == demo_text(name)
    (target / "stack.toml").write_text("# my edits\n", encoding="utf-8")
    again = run_cli(["examples", "--copy", str(target)])
    assert again.status == 2 and "--copy: would overwrite" in again.err and "choose an empty or new folder" in again.err
    assert (target / "stack.toml").read_text(encoding="utf-8") == "# my edits\n"
    copied = run_cli(["run", str(target / "head-on.toml"), "--quiet"])
    assert copied.status == 0 and "heavy = (0.500, 0.000)" in copied.out


def test_examples_copy_into_a_file_is_refused(tmp_path: Path) -> None:
    (tmp_path / "f").write_text("", encoding="utf-8")
    result = run_cli(["examples", "--copy", str(tmp_path / "f")])
    assert result.status == 2 and "--copy: must be a folder" in result.err


@pytest.mark.parametrize("fmt", ["json", "csv"])
def test_explain_is_refused_outside_the_table_instead_of_dropped(fmt: str) -> None:
    result = run_cli(["demo", "spheres", "--explain", "--format", fmt])
    assert result.status == 2 and result.out == ""
    assert result.err.strip().splitlines() == [
        f"collisionlab: --explain: works with --format table only, not {fmt}; --format json already carries "
        "each collision's working (normal, approach_speed, impulse, velocities)"
    ]


def test_demo_pictures_are_named_by_the_demo(tmp_path: Path) -> None:
    result = run_cli(["demo", "--quiet", "--steps", "2", "--plot", str(tmp_path / "lab.png")])
    assert result.status == 0, result.err
    expected = sorted(f"lab-{name}.png" for name in ("aabb3d", "spheres", "circle-line", "sphere-plane"))
    assert files_in(tmp_path) == expected  # not lab-lab-case-1--aabb-in-3d.png


def test_the_numba_cache_goes_to_the_users_cache_folder(tmp_path: Path) -> None:
    code = (
        "import os, collisionlab.particles, numba\n"
        "print(os.environ['NUMBA_CACHE_DIR']); print(numba.config.CACHE_DIR)\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["XDG_CACHE_HOME"] = str(tmp_path)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True).stdout
    expected = str(tmp_path / "collisionlab" / "numba")
    assert out.splitlines() == [expected, expected]
    # A cache folder the user chose is kept.
    env["NUMBA_CACHE_DIR"] = str(tmp_path / "mine")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True).stdout
    assert out.splitlines() == [str(tmp_path / "mine")] * 2
