"""RunRecord: short repr, pandas tables, the inline picture (issue 13)."""

from __future__ import annotations

import json
import math
import re
import sys

import numpy as np
import pandas as pd
import pytest

from collisionlab.demos import load_demo
from collisionlab.errors import InvalidInputError
from collisionlab.record import EventBlock, RunRecord
from collisionlab.vector import Vector3D
from collisionlab.world import simulate


@pytest.fixture(scope="module")
def spheres() -> RunRecord:
    return simulate(load_demo("spheres"))  # the lab's case 2: 200 steps, one collision at step 103


def test_repr_counts_instead_of_listing(spheres: RunRecord) -> None:
    text = repr(spheres)
    assert text == (
        "<RunRecord 'Lab case 2: sphere and sphere': 3D, mode euler, 200 steps of 0.01 s, 2 bodies, "
        "201 frames, 1 collision, 0 skipped contacts, 0 warnings>"
    )
    long_run = simulate(load_demo("bouncing-ball").with_settings(steps=5000))
    assert len(repr(long_run)) < 200  # the issue saw 67,065 characters for a short run


def test_frames_table_has_a_row_per_step_and_body(spheres: RunRecord) -> None:
    frames = spheres.to_dataframe()
    assert list(frames.columns) == ["step", "time", "body", "x", "y", "z", "vx", "vy", "vz"]
    assert len(frames) == 201 * 2
    first = frames.iloc[0]
    state = spheres.frames[0].bodies[0]
    assert (first["step"], first["body"]) == (0, state.name)
    assert Vector3D(first["x"], first["y"], first["z"]) == state.position
    last = frames[frames["step"] == 200].set_index("body")
    for body in spheres.frames[-1].bodies:
        assert Vector3D(*last.loc[body.name, ["vx", "vy", "vz"]]) == body.velocity


def test_events_table_holds_the_working(spheres: RunRecord) -> None:
    events = spheres.to_dataframe("events")
    (event,) = spheres.events
    assert len(events) == 1
    row = events.iloc[0]
    assert (row["step"], row["body_a"], row["body_b"]) == (103, *event.bodies)
    assert (row["approach_speed"], row["impulse"]) == (event.approach_speed, event.impulse)
    assert Vector3D(row["normal_x"], row["normal_y"], row["normal_z"]) == event.normal
    assert bool(row["below_rest_threshold"]) is False
    # Elastic (e = 1): the kinetic energy before equals the energy after, 1 J (README's postlab 3).
    assert row["kinetic_energy_before"] == pytest.approx(1.0) == row["kinetic_energy_after"]


def test_skipped_table_and_empty_tables_keep_their_columns() -> None:
    record = simulate(load_demo("head-on"))
    skipped = record.to_dataframe("skipped")
    assert list(skipped.columns) == ["step", "time", "body_a", "body_b", "reason"]
    assert len(skipped) == len(record.skipped)
    quiet = simulate(load_demo("head-on").with_settings(steps=1))
    assert quiet.to_dataframe("events").empty and "impulse" in quiet.to_dataframe("events").columns


def test_an_unknown_table_is_refused(spheres: RunRecord) -> None:
    with pytest.raises(InvalidInputError, match="table: must be one of frames, events, skipped"):
        spheres.to_dataframe("bodies")  # type: ignore[arg-type]


def test_without_pandas_the_error_says_how_to_get_it(spheres: RunRecord, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "pandas", None)  # import pandas now raises ImportError
    with pytest.raises(ImportError, match="needs pandas, which is not installed: pip install pandas"):
        spheres.to_dataframe()
    assert isinstance(pd.DataFrame(), pd.DataFrame)  # the real module is untouched


def test_jupyter_shows_the_plot_as_png(spheres: RunRecord) -> None:
    png = spheres._repr_png_()
    assert png is not None and png[:8] == b"\x89PNG\r\n\x1a\n"
    bare = RunRecord("t", "euler", 0.1, 1, 1.0, Vector3D(0, 0, 0))
    assert bare._repr_png_() is None  # no scenario, no picture: Jupyter falls back to the repr
    with pytest.raises(InvalidInputError, match="scenario"):
        bare.plot()
    figure = spheres.plot(size=(400, 300))
    assert tuple(figure.get_size_inches() * figure.dpi) == (400, 300)


# --- EventBlock: a world's events as columns --------------------------------------------------
def _block(rows: int, seed: int) -> EventBlock:
    """A block of random events, some against an obstacle, with signed zeros and odd names."""
    rng = np.random.default_rng(seed)
    names = ['ball "a"', "bällchen", "c\\d"]
    a = rng.integers(-2, 3, rows)
    b = rng.integers(0, 3, rows)
    a = np.where(a == b, -1, a)

    def vectors() -> np.ndarray:
        v = rng.normal(size=(rows, 3))
        v[rng.random((rows, 3)) < 0.2] = -0.0
        return v

    return EventBlock(
        step=rng.integers(1, 10_000, rows),
        time=rng.random(rows) * 100,
        a=a,
        b=b,
        normal=vectors(),
        point=vectors(),
        approach_speed=-rng.random(rows),
        impulse=rng.random(rows),
        restitution=rng.choice([0.0, 0.5, 1.0], rows),
        below_rest=rng.integers(0, 2, rows),
        before_a=vectors(),
        before_b=vectors(),
        after_a=vectors(),
        after_b=vectors(),
        names=names,
        static_names=["floor", "wall ☃"],
        masses=np.array([1.0, 2.5, math.inf]),
    )


@pytest.mark.parametrize("seed", range(5))
def test_event_block_json_is_what_the_json_module_writes(seed: int) -> None:
    block = _block(200, seed)
    lines = block.json_lines()
    assert lines == [json.dumps(event.to_dict()) for event in block]  # the json module is the oracle
    assert not re.search(r"-0\.0(?![0-9])", "".join(lines))  # signed zeros were written 0.0


def test_event_block_builds_events_on_demand() -> None:
    # One ball (1 kg) bouncing off the floor and two balls (1 and 2.5 kg) meeting: kinetic
    # energies worked by hand: 1/2 * 1 * 2^2 = 2 J before, 1/2 * 1 * 1^2 = 0.5 J after; the pair
    # 1/2 * 1 * 1 + 1/2 * 2.5 * 0 = 0.5 J before, 1/2 * 1 * 0.25 + 1/2 * 2.5 * 0.04 = 0.175 J after.
    z = np.zeros(3)
    block = EventBlock(
        step=np.array([3, 7]),
        time=np.array([0.03, 0.07]),
        a=np.array([-1, 0]),
        b=np.array([0, 1]),
        normal=np.array([[0.0, 1, 0], [1.0, 0, 0]]),
        point=np.zeros((2, 3)),
        approach_speed=np.array([-2.0, -1.0]),
        impulse=np.array([3.0, 0.5]),
        restitution=np.array([0.5, 0.5]),
        below_rest=np.array([0, 1]),
        before_a=np.array([z, [1.0, 0, 0]]),
        before_b=np.array([[0.0, -2, 0], z]),
        after_a=np.array([z, [0.5, 0, 0]]),
        after_b=np.array([[0.0, 1, 0], [0.2, 0, 0]]),
        names=["a", "b"],
        static_names=["floor"],
        masses=np.array([1.0, 2.5]),
    )
    assert len(block) == 2
    wall, pair = block
    assert wall.bodies == ("floor", "a") and wall.static and wall.masses == (math.inf, 1.0)
    assert wall.velocities_after == {"a": Vector3D(0, 1, 0)}
    assert (wall.kinetic_energy_before, wall.kinetic_energy_after) == (2.0, 0.5)
    assert pair.bodies == ("a", "b") and not pair.static and pair.below_rest_threshold
    assert list(pair.velocities_before) == ["a", "b"]
    assert pair.kinetic_energy_before == 0.5 and math.isclose(pair.kinetic_energy_after, 0.175)
    assert block[-1] == pair and block[0:1] == [wall]
    with pytest.raises(IndexError):
        block[2]
