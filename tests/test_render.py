"""The text forms of a run (cli/render.py, cli/event_text.py): the lab's aligned table with collision lines and the
summary, CSV and JSON. Records come from small scenarios whose numbers are easy by hand."""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import math
import re

import numpy as np
import pytest

from collisionlab.cli.render import COMPILE_NOTICE, render, render_csv, render_json, render_table
from collisionlab.demos import load_demo
from collisionlab.model import Body, Obstacle, Scenario, Settings
from collisionlab.record import Frame, FrameBodies, RunRecord
from collisionlab.shapes import Circle, Line, Plane, Sphere
from collisionlab.world import simulate
from tests.schema_check import check


def drop() -> RunRecord:
    """A ball r = 0.5 at y = 0.96 falling at 1 m/s onto the floor, dt = 0.1, e = 0.5:
    y = 0.96 - 0.1 k first <= 0.5 at k = 5 (4.6 rounded up; away from a boundary, so rounding
    cannot move it); lab eq. 24: v' = (0, -1, 0) - 1.5 (-1) (0, 1, 0) = (0, 0.5, 0)."""
    ball = Body("ball", Sphere((0, 0.96, 0), 0.5), velocity=(0, -1, 0))
    floor = Obstacle("floor", Plane((0, 0, 0), (0, 1, 0)))
    return simulate(Scenario(Settings(dt=0.1, steps=10, restitution=0.5), (ball,), (floor,), "drop"))


def head_on() -> RunRecord:
    """Circles r = 0.5 at x = 0 and 1.5, closing at 2 m/s, dt = 0.1: gap 0.5 - 0.2 k <= 0 at k = 3
    (2.5 is not a step). Equal masses, e = 1: they swap velocities, (1, 0) <-> (-1, 0)."""
    a = Body("left", Circle((0, 0), 0.5), velocity=(1, 0))
    b = Body("right", Circle((1.5, 0), 0.5), velocity=(-1, 0))
    return simulate(Scenario(Settings(dt=0.1, steps=6), (a, b), (), "pair"))


def rows(text: str) -> list[str]:
    return [line for line in text.splitlines() if line[:6].strip().isdigit()]


def test_the_drop_is_what_the_hand_says() -> None:
    (event,) = drop().events
    assert event.step == 5 and event.velocities_after["ball"].as_tuple() == (0.0, 0.5, 0.0)


def test_table_has_a_title_a_header_a_row_per_step_and_the_collision_after_its_step() -> None:
    text = render_table(drop())
    lines = text.splitlines()
    assert lines[0] == "drop  (dt = 0.1 s, 10 steps, mode euler)"
    assert lines[1].split() == ["step", "t", "(s)", "ball.x", "ball.y", "ball.z"]
    assert [int(r.split()[0]) for r in rows(text)] == list(range(11))
    row5 = next(r for r in rows(text) if r.split()[0] == "5")
    where = lines.index(row5)
    assert lines[where + 1] == "collision at step 5 (t = 0.500 s): ball hits floor"
    assert lines[where + 2] == "  velocity after: ball = (0.000, 0.500, 0.000) m/s"
    assert lines[where + 3].split()[0] == "6"


def test_table_columns_are_aligned() -> None:
    text = render_table(drop())
    header = text.splitlines()[1]
    table = [header, *rows(text)]
    assert {len(line) for line in table} == {len(header)}
    # right-aligned columns: every cell of every row ends where its heading ends ("t (s)" is one heading)
    ends = [m.end() for m in re.finditer(r"\S+", header) if m.group() != "t"]
    assert len(ends) == 5
    for line in table[1:]:
        assert [m.end() for m in re.finditer(r"\S+", line)] == ends, line


def test_table_values_are_the_positions_of_every_step() -> None:
    text = render_table(drop())
    row = rows(text)[3].split()  # after 3 steps: t = 0.3 s, y = 0.96 - 0.3 = 0.66
    assert row == ["3", "0.3000", "0.0000", "0.6600", "0.0000"]


def test_two_body_events_show_both_velocities() -> None:
    text = render_table(head_on())
    assert "collision at step 3 (t = 0.300 s): left and right collide" in text
    assert "  velocities after: left = (-1.000, 0.000), right = (1.000, 0.000) m/s" in text
    assert text.splitlines()[1].split() == ["step", "t", "(s)", "left.x", "left.y", "right.x", "right.y"]


def test_summary_gives_collisions_momentum_and_kinetic_energy_at_start_and_end() -> None:
    text = render_table(drop())
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("summary: "))
    assert lines[start] == "summary: 1 collision in 10 steps (1.000 s, mode euler)"
    # p = m v: (0, -1, 0) before, (0, 0.5, 0) after; KE 0.5 * 1 = 0.5 J before, 0.5 * 0.25 = 0.125 J after
    assert lines[start + 1].split() == [
        "momentum",
        "start",
        "(0.000,",
        "-1.000,",
        "0.000)",
        "kg",
        "m/s",
        "end",
        "(0.000,",
        "0.500,",
        "0.000)",
        "kg",
        "m/s",
    ]
    assert lines[start + 2].split() == ["kinetic", "energy", "start", "0.5", "J", "end", "0.125", "J"]


def test_summary_counts_in_plural() -> None:
    assert "summary: 1 collision in 6 steps" in render_table(head_on())
    none = simulate(
        Scenario(
            Settings(dt=0.1, steps=2),
            (Body("b", Circle((0, 5), 1), velocity=(1, 0)),),
            (Obstacle("l", Line((0, 0), (1, 0))),),
        )
    )
    assert "summary: 0 collisions in 2 steps" in render_table(none)


def test_every_and_quiet() -> None:
    record = drop()
    assert [r.split()[0] for r in rows(render_table(record, every=4))] == ["0", "4", "8", "10"]
    quiet = render_table(record, quiet=True)
    assert rows(quiet) == []
    assert "collision at step 5 (t = 0.500 s): ball hits floor" in quiet
    assert "summary: 1 collision" in quiet


def test_every_never_hides_a_collision() -> None:
    text = render_table(drop(), every=3)  # step 5 is not printed, its collision is
    assert "collision at step 5" in text
    lines = text.splitlines()
    assert lines.index("collision at step 5 (t = 0.500 s): ball hits floor") > lines.index(rows(text)[1])


def test_restitution_above_one_warns_in_the_table() -> None:
    ball = Body("ball", Sphere((0, 1, 0), 0.5), velocity=(0, -1, 0))
    floor = Obstacle("floor", Plane((0, 0, 0), (0, 1, 0)))
    record = simulate(Scenario(Settings(dt=0.1, steps=10, restitution=1.5), (ball,), (floor,)))
    assert any(line.startswith("warning: restitution 1.5 > 1") for line in render_table(record).splitlines())


def test_csv() -> None:
    parsed = list(csv.reader(io.StringIO(render_csv(drop(), every=5))))
    assert parsed[0] == ["step", "time", "ball.x", "ball.y", "ball.z", "ball.vx", "ball.vy", "ball.vz"]
    assert [r[0] for r in parsed[1:]] == ["0", "5", "10"]
    last = [float(x) for x in parsed[-1]]
    assert last[0] == 10 and math.isclose(last[1], 1.0) and last[6] == 0.5  # moving up at 0.5 m/s


def test_csv_numbers_are_exact() -> None:
    record = drop()
    parsed = list(csv.reader(io.StringIO(render_csv(record))))
    assert float(parsed[4][3]) == record.frames[3].bodies[0].position.y  # repr: nothing rounded


def test_json_has_the_documented_shape() -> None:
    data = check("run", json.loads(render_json(head_on())))
    assert {"frames", "events", "summary"} <= set(data)
    for frame in data["frames"]:
        assert set(frame) == {"step", "time", "bodies"}
        for body in frame["bodies"]:
            assert set(body) == {"name", "position", "velocity"}
            assert len(body["position"]) == 3 and len(body["velocity"]) == 3  # 3 elements even in 2D
    (event,) = data["events"]
    assert event["step"] == 3 and event["bodies"] == ["left", "right"]
    assert len(event["normal"]) == 3 and math.isclose(event["normal"][0], 1.0)
    assert event["velocities_after"] == {"left": [-1.0, 0.0, 0.0], "right": [1.0, 0.0, 0.0]}
    summary = data["summary"]
    assert summary["collisions"] == 1
    assert summary["momentum_start"] == [0.0, 0.0, 0.0] and summary["momentum_end"] == [0.0, 0.0, 0.0]
    assert summary["kinetic_energy_start"] == 1.0 and summary["kinetic_energy_end"] == 1.0


def test_json_static_events_list_only_the_moving_body() -> None:
    (event,) = check("run", json.loads(render_json(drop())))["events"]
    assert event["bodies"] == ["floor", "ball"]
    assert list(event["velocities_after"]) == ["ball"]


def test_json_every_keeps_every_kth_frame_and_the_last() -> None:
    data = check("run", json.loads(render_json(drop(), every=4)))
    assert [f["step"] for f in data["frames"]] == [0, 4, 8, 10]
    assert len(data["events"]) == 1


@pytest.mark.parametrize(("fmt", "function"), [("table", render_table), ("csv", render_csv), ("json", render_json)])
def test_render_dispatches_on_the_format(fmt: str, function: object) -> None:
    record = drop()
    assert render(record, fmt) == function(record)  # type: ignore[operator]


def test_explain_shows_the_working() -> None:
    text = render_table(drop(), explain=True)
    # v_n = (v_ball - 0) . n = -1; j = -(1 + 0.5)(-1) / (0 + 1/1) = 1.5
    assert "v_n = (v_ball - v_floor) . n = -1.0000 m/s" in text
    assert "= 1.5000 N s" in text


def test_no_signed_zero_in_any_output() -> None:
    # The lab's case 1 has no gravity: its potential energy is -m g.x = -0.0, and tiny negative
    # numbers round to -0.0000 in a table; neither may be printed with a minus sign.
    record = simulate(load_demo("aabb3d"))
    assert record.ledger.potential_start == 0.0  # -0.0 == 0.0; the sign is what the outputs must hide
    text = render_table(record, explain=True) + render_csv(record) + render_json(record)
    assert not re.search(r"-0(\.0*)?(?![0-9.e])", text)


def test_frames_from_a_worlds_arrays_print_no_signed_zero() -> None:
    # A world's frames hold its arrays (FrameBodies), where a kernel's -0.0 survives (a Vector3D
    # would have dropped its sign); each writer reads those arrays directly.
    record = simulate(load_demo("aabb3d"))
    first = record.frames[0]
    signed = np.full((len(first.bodies), 3), -0.0)
    names = [b.name for b in first.bodies]
    frame = Frame(first.step, first.time, FrameBodies(names, signed, signed.copy()))
    replaced = dataclasses.replace(record, frames=[frame, *record.frames[1:]])
    text = render_table(replaced) + render_csv(replaced) + render_json(replaced)
    assert not re.search(r"-0(\.0*)?(?![0-9.e])", text)


@pytest.mark.parametrize("compiled_from", [1, 10**9])  # every block laid out by the kernel; none
@pytest.mark.parametrize("dim", [2, 3])
def test_a_worlds_event_blocks_print_as_its_events_do(
    monkeypatch: pytest.MonkeyPatch, dim: int, compiled_from: int
) -> None:
    # The table writer prints a world's events from their columns (EventBlock); replaying the
    # record prints them from CollisionEvent objects, one by one. The two texts must agree,
    # line for line: bodies against walls and against each other, signed zeros included.
    import numba  # noqa: F401  (the kernel is used only once numba is loaded)

    from collisionlab.cli import event_text
    from collisionlab.cli.render import TableWriter
    from collisionlab.edmd.observables import ExactGas
    from collisionlab.engine.world import World

    monkeypatch.setattr(event_text, "_COMPILED_EVENTS", compiled_from)

    world = World(ExactGas(n=80, dim=dim, fraction=0.3, time=4.0, seed=2).scenario(frames=8))
    streamed = io.StringIO()
    record = world.run(every=4, observer=TableWriter(streamed, every=4, quiet=True))
    assert len(record.events) > 50 and any(event.static for event in record.events)
    assert streamed.getvalue() == render_table(record, every=4, quiet=True)


@pytest.mark.parametrize("compiled_from", [1, 10**9])
@pytest.mark.parametrize("seed", range(4))
def test_random_event_blocks_print_as_their_events_do(
    monkeypatch: pytest.MonkeyPatch, seed: int, compiled_from: int
) -> None:
    # Random blocks (odd and non-ASCII names, signed zeros, obstacles on either side, steps out
    # of order): the block's text, by the kernel or by %, is the events' own lines one by one.
    import numba  # noqa: F401

    from collisionlab.cli import event_text
    from tests.test_record import _block

    monkeypatch.setattr(event_text, "_COMPILED_EVENTS", compiled_from)
    block = _block(700, seed)
    for dims in (2, 3):
        texts = event_text.block_texts(block, dims)
        events = sorted(block, key=lambda event: event.step)  # stable: a step's events in order
        lines = [line + "\n" for event in events for line in event_text.event_lines(event, dims, False)]
        assert "".join(text for _, text in texts) == "".join(lines)
        assert [step for step, _ in texts] == sorted({event.step for event in events})


def test_the_kernel_lays_out_a_block_in_pieces_as_whole() -> None:
    # A long block is laid out a piece of `size` events at a time; steps that straddle two
    # pieces come out whole, as the % form writes them (the oracle: Python's own formatting).
    from collisionlab.cli import event_text

    rng = np.random.default_rng(3)
    n = 1000
    steps = np.sort(rng.integers(0, 40, n))  # ~25 events a step: most pieces cut a step
    index = rng.integers(0, 5, 2 * n)
    names = ["a", "bällchen", "c d", "e", "floor"]
    static = rng.random(n) < 0.3
    values = np.column_stack((steps * 0.01, rng.normal(size=(n, 6))))
    whole = event_text._formatted_texts(steps, index, names, static, values, 3)
    assert event_text._laid_out_texts(steps, index, names, static, values, 3, size=37) == whole
    assert event_text._laid_out_texts(steps, index, names, static, values, 3) == whole


@pytest.mark.parametrize(("cached", "heard"), [(False, [COMPILE_NOTICE]), (True, [])])
@pytest.mark.parametrize("fmt", ["json", "table"])
def test_the_writers_say_once_that_their_kernel_compiles(
    monkeypatch: pytest.MonkeyPatch, cached: bool, heard: list[str], fmt: str
) -> None:
    # A bouncing ball's run hands over several blocks of events (one a chunk of steps): the
    # notice comes once, before the first, and only when the kernel is not in the cache. (The
    # table lays out only large blocks by the kernel: here every block.)
    import numba  # noqa: F401  (the table uses the kernel only once numba is loaded)

    from collisionlab import text_kernels
    from collisionlab.cli import event_text, render
    from collisionlab.engine.world import World

    monkeypatch.setattr(text_kernels, "is_cached", lambda: cached)
    monkeypatch.setattr(event_text, "_COMPILED_EVENTS", 1)
    told: list[str] = []
    out = io.StringIO()
    writer = render.writer_for(fmt, out, notify=told.append)
    record = World(load_demo("bouncing-ball")).run(observer=writer, keep=False)
    assert record.collision_count >= 2  # e = 0.8 from 1 m: many bounces in the demo's 3 s
    assert told == heard
    if fmt == "json":
        assert len(json.loads(out.getvalue())["events"]) == record.collision_count
    else:
        assert out.getvalue().count("collision at step") == record.collision_count


@pytest.mark.parametrize("fmt", ["json", "table"])
def test_the_writers_say_when_their_kernel_has_compiled(monkeypatch: pytest.MonkeyPatch, fmt: str) -> None:
    # Issue 28: a command that has to compile says when it is done. The cache holds the kernel
    # once the first block has been laid out by it (a stand-in: not cached at the notice, cached
    # after): the notice, then one line with the seconds it took, then nothing more.
    import numba  # noqa: F401  (the table uses the kernel only once numba is loaded)

    from collisionlab import text_kernels
    from collisionlab.cli import event_text, render
    from collisionlab.engine.world import World

    asked: list[bool] = []

    def is_cached() -> bool:
        asked.append(True)
        return len(asked) > 1  # the notice's question: no; every later one: yes

    monkeypatch.setattr(text_kernels, "is_cached", is_cached)
    monkeypatch.setattr(event_text, "_COMPILED_EVENTS", 1)
    told: list[str] = []
    writer = render.writer_for(fmt, io.StringIO(), notify=told.append)
    World(load_demo("bouncing-ball")).run(observer=writer, keep=False)
    assert told[0] == COMPILE_NOTICE
    assert re.fullmatch(r"compiled the output writers' text kernel in \d+ s", told[1]) and len(told) == 2
