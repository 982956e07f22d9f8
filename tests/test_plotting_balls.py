"""``collisionlab gas --mode exact --plot FILE``: the last frame, each species its colour, beside
each species' speeds (issue 29: "A GIF or PNG of the last frame (--plot) colours the species")."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from matplotlib.colors import to_rgba

from collisionlab.plotting.balls import MOST_DRAWN, draw_balls
from tests.cli_helpers import run_cli

MIXTURE = ["--species", "big:0.5:1", "--species", "small:0.5:0.5"]


def gas(argv: list[str]) -> tuple[int, str, str]:
    """``collisionlab gas --mode exact`` on 200 balls for a time of 2 (a JSON report checked
    against the shipped schema)."""
    result = run_cli(["gas", "--mode", "exact", "--n", "200", "--time", "2", *argv])
    return result.status, result.out, result.err


@pytest.mark.parametrize(
    ("dim", "boundary", "suffix"), [(2, "periodic", "png"), (3, "walls", "gif"), (2, "walls", "svg")]
)
def test_a_mixture_is_drawn_to_the_file_asked_and_the_report_names_it(
    tmp_path: Path, dim: int, boundary: str, suffix: str
) -> None:
    path = tmp_path / f"last.{suffix}"
    status, out, err = gas(
        ["--dim", str(dim), "--boundary", boundary, *MIXTURE, "--plot", str(path), "--format", "json"]
    )
    assert status == 0, err
    assert json.loads(out)["plot"] == str(path)
    head = path.read_bytes()[:8]
    assert head.startswith({"png": b"\x89PNG", "gif": b"GIF8", "svg": b"<?xml"}[suffix])
    assert [p.name for p in tmp_path.iterdir()] == [path.name]  # nothing half-written beside it


def test_one_kind_of_ball_is_drawn_too(tmp_path: Path) -> None:
    path = tmp_path / "last.png"
    status, out, err = gas(["--dim", "2", "--plot", str(path)])
    assert status == 0, err
    assert f"plot             {path}" in out
    assert path.stat().st_size > 10_000


@pytest.mark.parametrize(
    ("name", "words"),
    [("last.txt", "expected FILE.png (or .svg, .pdf, .gif)"), ("no/such/folder/last.png", "does not exist")],
)
def test_a_bad_plot_path_is_one_line_before_the_run(tmp_path: Path, name: str, words: str) -> None:
    status, out, err = gas([*MIXTURE, "--plot", str(tmp_path / name)])
    assert status == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and "--plot" in err and words in err


def test_each_ball_has_its_species_colour_and_is_drawn_to_scale() -> None:
    # Three balls of two species in a 2D box: ball i of species kinds[i] is a disc of diameter
    # 2 r_i at its centre, coloured C0 for the first species and C1 for the second.
    positions = np.array([[2.0, 2.0], [5.0, 5.0], [8.0, 3.0]])
    radii = np.array([1.0, 0.5, 1.0])
    kinds = np.array([0, 1, 0])
    velocities = np.array([[1.0, 0.0], [0.0, -2.0], [-1.0, 1.0]])
    figure = draw_balls(positions, velocities, radii, kinds, ("big", "small"), (10.0, 10.0), "three balls")
    box = figure.axes[0]
    (discs,) = box.collections
    assert np.array_equal(discs.get_offsets(), positions)
    assert np.allclose(discs._widths * 2.0, 2.0 * radii)  # EllipseCollection keeps half-widths
    blue, orange = to_rgba("C0", 0.85), to_rgba("C1", 0.85)
    assert [tuple(c) for c in discs.get_facecolors()] == [blue, orange, blue]
    labels = [t.get_text() for t in box.get_legend().get_texts()]
    assert labels == ["big: 2 balls, r = 1", "small: 1 balls, r = 0.5"]
    assert box.get_xlim() == pytest.approx((-0.2, 10.2)) and box.get_aspect() == 1.0


def test_each_species_is_held_against_maxwell_boltzmann_at_its_own_temperature() -> None:
    # kT/m of a species: <|v|^2> / dim over its balls. Big: (1 + 1) / 2 / 2 = 0.5 from two balls
    # of speed 1; small: 4 / 2 = 2 from one ball of speed 2.
    velocities = np.array([[1.0, 0.0], [0.0, -2.0], [0.0, 1.0]])
    figure = draw_balls(
        np.array([[2.0, 2.0], [5.0, 5.0], [8.0, 3.0]]), velocities, np.array([1.0, 0.5, 1.0]),
        np.array([0, 1, 0]), ("big", "small"), (10.0, 10.0), "three balls",
    )  # fmt: skip
    labels = [t.get_text() for t in figure.axes[1].get_legend().get_texts()]
    assert "big: Maxwell-Boltzmann, kT/m = 0.5" in labels and "small: Maxwell-Boltzmann, kT/m = 2" in labels


def test_a_million_balls_are_drawn_as_a_fixed_choice_of_the_most_drawn() -> None:
    n = MOST_DRAWN + 5
    rng = np.random.default_rng(1)
    figure = draw_balls(
        rng.random((n, 2)) * 100.0, rng.normal(size=(n, 2)), np.full(n, 0.1), np.zeros(n, dtype=np.int64),
        ("A",), (100.0, 100.0), "many",
    )  # fmt: skip
    (discs,) = figure.axes[0].collections
    assert len(discs.get_offsets()) == MOST_DRAWN
    assert f"({MOST_DRAWN:,} of {n:,} drawn)" in figure.axes[0].get_title()
