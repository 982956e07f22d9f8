"""RunRecord: short repr, pandas tables, the inline picture (issue 13)."""

from __future__ import annotations

import json
import math
import re
import struct
import sys
from collections.abc import Sequence

import numpy as np
import pandas as pd
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from collisionlab import text_kernels
from collisionlab.collision_events import EventBlock, json_numbers
from collisionlab.demos import load_demo
from collisionlab.errors import InvalidInputError
from collisionlab.extras import MissingExtraError
from collisionlab.record import CollisionEvent, RunRecord
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
    with pytest.raises(MissingExtraError) as missing:
        spheres.to_dataframe()
    assert str(missing.value) == (
        "pandas tables (RunRecord.to_dataframe) need the 'pandas' extra: pip install 'collisionlab[pandas]'"
    )
    assert isinstance(missing.value, ImportError)  # what a caller catching ImportError still sees
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


#: A number in JSON text as the json module lays it out (after "[", ": " or ", ").
_JSON_NUMBER = re.compile(r"(?:(?<=\[)|(?<=[:,] ))-?[0-9][0-9.eE+-]*")


def _same_json_as_the_json_module(lines: list[str], events: Sequence[CollisionEvent]) -> None:
    """``lines`` hold what ``json.dumps(event.to_dict())`` writes of each of ``events`` (the
    json module is the oracle): the same values to the bit, keys in the same order, the same
    layout; only the text of a number may differ (orjson's shortest text is not repr's)."""
    assert len(lines) == len(events)
    for line, event in zip(lines, events, strict=True):
        oracle = json.dumps(event.to_dict())
        assert json.dumps(json.loads(line)) == oracle  # values (repr is bit for bit) and key order
        assert _JSON_NUMBER.sub("N", line) == _JSON_NUMBER.sub("N", oracle)  # layout, names


@pytest.mark.parametrize("seed", range(5))
def test_event_block_json_is_what_the_json_module_writes(seed: int) -> None:
    block = _block(200, seed)
    lines = block.json_lines()
    _same_json_as_the_json_module(lines, block)
    assert not re.search(r"-0\.0(?![0-9])", "".join(lines))  # signed zeros were written 0.0
    # In pieces, with a separator before each event: the same lines.
    assert b"".join(block.json_chunks(",\n  ", size=7)).decode() == "".join(",\n  " + line for line in lines)


def test_event_block_json_of_a_nan_or_an_infinity_is_the_json_modules() -> None:
    # A world never hands these over (its range guard stops a run first); a block built by
    # hand may hold them: orjson would write null, the json module writes NaN and Infinity.
    block = _block(20, 7)
    block.impulse[3] = math.nan
    block.time[6] = math.inf
    block.after_b[5, 1] = -math.inf  # (a CollisionEvent cannot hold it: Vector3D is finite)
    lines = block.json_lines()
    for k in (3, 6):
        assert lines[k] == json.dumps(block[k].to_dict())
    assert '"impulse": NaN, ' in lines[3] and '"time": Infinity, ' in lines[6]
    assert re.search(r'"velocities_after": \{.*: \[[^,]+, -Infinity, [^,]+\]\}', lines[5])
    _same_json_as_the_json_module(lines[:5] + lines[7:], block[:5] + block[7:])


def _bits(x: float) -> int:
    return int(struct.unpack("<Q", struct.pack("<d", x))[0])


#: Doubles of every kind: from random bits (every exponent, subnormals included), whole
#: numbers, and the edges: the smallest subnormal, the largest subnormal, the smallest normal,
#: the largest double, where repr and orjson change between plain and exponent notation.
_DOUBLES = st.one_of(
    st.floats(allow_nan=False, allow_infinity=False),
    st.integers(0, 2**64 - 1).map(lambda bits: float(struct.unpack("<d", struct.pack("<Q", bits))[0])),
    st.integers(-(2**64), 2**64).map(float),
    st.sampled_from([5e-324, -5e-324, 2.225073858507201e-308, 2.2250738585072014e-308, 1.7976931348623157e308]),
    st.sampled_from([1e-7, 1.5e-7, 1e-5, 1e-4, 0.1 + 0.2, 1e15, 1e16, 1.5e16, 1e21, 1e22, 1e23, 2.0**53 + 2, -0.0]),
).filter(math.isfinite)
_JSON_NUMBER_TEXT = re.compile(r"-?(?:0|[1-9][0-9]*)(?:\.[0-9]+)?(?:[eE][-+]?[0-9]+)?")


@given(st.lists(_DOUBLES, min_size=1, max_size=60))
@example([-0.0, 5e-324, -2.225073858507201e-308, 1e-7, 1e-5, 1e16, 2.0**53 + 2, -1.7976931348623157e308, 100.0])
def test_every_number_written_reads_back_as_the_same_double(values: list[float]) -> None:
    # Each number's text, alone (json_numbers) and where a block's lines put it (every number
    # column of an event): a JSON number that json.loads reads as a float, the same double to
    # the bit; -0.0 written 0.0.
    for value, text in zip(values, json_numbers(np.array(values)), strict=True):
        assert _JSON_NUMBER_TEXT.fullmatch(text), text
        read = json.loads(text)
        assert isinstance(read, float) and _bits(read) == _bits(value + 0.0), (value, text)
    rows = -(-len(values) // 22)
    drawn = np.resize(np.array(values), (rows, 22))
    block = EventBlock(
        step=np.arange(rows), time=drawn[:, 0], a=np.zeros(rows, np.int64), b=np.ones(rows, np.int64),
        normal=drawn[:, 1:4], point=drawn[:, 4:7], approach_speed=drawn[:, 7], impulse=drawn[:, 8],
        restitution=drawn[:, 9], below_rest=np.zeros(rows, np.int64), before_a=drawn[:, 10:13],
        before_b=drawn[:, 13:16], after_a=drawn[:, 16:19], after_b=drawn[:, 19:22],
        names=["a", "b"], static_names=[], masses=np.array([1.0, 2.0]),
    )  # fmt: skip
    for line, row in zip(block.json_lines(), drawn.tolist(), strict=True):
        event = json.loads(line)
        written = [event["time"], *event["normal"], *event["point"], event["approach_speed"], event["impulse"]]
        written += [event["restitution"], *event["velocities_before"]["a"], *event["velocities_before"]["b"]]
        written += [*event["velocities_after"]["a"], *event["velocities_after"]["b"]]
        assert [_bits(x) for x in written] == [_bits(x + 0.0) for x in row]
        for text in _JSON_NUMBER.findall(line):  # (an energy may overflow, 1e300^2: Infinity is no number here)
            assert _JSON_NUMBER_TEXT.fullmatch(text), text


def test_event_block_json_compiled_is_its_python_form(monkeypatch: pytest.MonkeyPatch) -> None:
    # The lines are laid out by text_kernels.lay_out compiled by numba; the same function run
    # as Python writes the same text.
    block = _block(60, 3)
    compiled = b"".join(block.json_chunks(",\n  ", size=16))
    monkeypatch.setattr(text_kernels, "compiled", lambda: text_kernels.lay_out)
    assert b"".join(block.json_chunks(",\n  ", size=16)) == compiled


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
