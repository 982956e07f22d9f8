"""RunRecord: short repr, pandas tables, the inline picture (issue 13)."""

from __future__ import annotations

import sys

import pandas as pd
import pytest

from collisionlab.demos import load_demo
from collisionlab.errors import InvalidInputError
from collisionlab.record import RunRecord
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
