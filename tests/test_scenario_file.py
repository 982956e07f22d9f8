"""Scenario files (TOML): what they may say, every way they can be wrong (status 65 and a message
naming the file, the field and the expected form), and the round trip through scenario_to_toml."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import pytest

from collisionlab.demos import demo_names, demo_text, load_demo
from collisionlab.limits import MAX_SCENARIO_BYTES
from collisionlab.model import Scenario
from collisionlab.scenario_file import ScenarioError, load_scenario, parse_scenario, scenario_to_toml
from collisionlab.shapes import AABB, Plane, Sphere
from collisionlab.world import simulate
from tests.cli_helpers import EXAMPLE_NAMES, HEAVY_EXAMPLES, example, run_cli
from tests.schema_check import check_scenario_text

BALL = '[[body]]\nname = "ball"\nshape = "sphere"\nposition = [0, 3, 0]\nradius = 0.5\nvelocity = [0, -1, 0]\n'
FLOOR = '[[static]]\nname = "floor"\nshape = "plane"\npoint = [0, 0, 0]\nnormal = [0, 1, 0]\n'

#: Two [[gas]] tables of discs (radii 1 and 0.5) in a box: each placed on its own lattice, blind
#: to the other, so in the same region ({big} and {small}) their discs land on each other.
TWO_TABLES = """
[simulation]
mode = "exact"
[box]
region = [[0, 0], [20, 20]]
[[gas]]
name = "big"
shape = "circle"
radius = 1.0
region = {big}
count = 20
[[gas]]
name = "small"
shape = "circle"
radius = 0.5
region = {small}
count = 40
"""

# (name, file text, the field the message must name, words of the expected form)
BAD_FILES = [
    (
        "two gas tables in one region",
        TWO_TABLES.format(big="[[0, 0], [20, 20]]", small="[[0, 0], [20, 20]]"),
        "gas[1].region",
        "each [[gas]] table is placed on its own, blind to the others; give gas[0] and gas[1] regions that do not meet",
    ),
    ("missing radius", '[[body]]\nshape = "sphere"\nposition = [0, 0, 0]\n', "body[0].radius", "missing"),
    ("missing position", '[[body]]\nshape = "sphere"\nradius = 1\n', "body[0].position", "missing"),
    ("missing shape", "[[body]]\nposition = [0, 0, 0]\nradius = 1\n", "body[0].shape", "missing"),
    ("missing plane normal", BALL + '[[static]]\nshape = "plane"\npoint = [0, 0, 0]\n', "static[0].normal", "missing"),
    ("no body at all", "[simulation]\ndt = 0.1\n", "body", "at least one"),
    ("unknown simulation key", "[simulation]\ncolour = 1\n" + BALL, "simulation.colour", "unknown key"),
    ("unknown body key", BALL + "colour = 1\n", "body[0].colour", "unknown key"),
    ("unknown static key", BALL + FLOOR + "colour = 1\n", "static[0].colour", "unknown key"),
    ("unknown top-level key", "speed = 1\n" + BALL, "scenario.speed", "unknown key"),
    ("misspelt key", BALL.replace("radius", "radious"), "body[0].radious", "unknown key"),
    ("radius as text", BALL.replace("0.5", '"big"'), "body[0].radius", "must be a number"),
    ("radius as boolean", BALL.replace("0.5", "true"), "body[0].radius", "must be a number"),
    ("dt as text", '[simulation]\ndt = "fast"\n' + BALL, "simulation.dt", "must be a number"),
    ("steps fractional", "[simulation]\nsteps = 1.5\n" + BALL, "simulation.steps", "whole number"),
    ("position as a number", BALL.replace("[0, 3, 0]", "3"), "body[0].position", "[x, y, z]"),
    ("position of 4 numbers", BALL.replace("[0, 3, 0]", "[0, 3, 0, 1]"), "body[0].position", "2 or 3"),
    ("vector with text", BALL.replace("[0, -1, 0]", '[0, "a", 0]'), "body[0].velocity", "must be a number"),
    ("shape unknown", BALL.replace('"sphere"', '"cube"'), "body[0].shape", "circle | sphere | aabb"),
    ("body as a table", BALL.replace("[[body]]", "[body]"), "body", "[[body]]"),
    ("nan position", BALL.replace("[0, 3, 0]", "[0, nan, 0]"), "body[0].position", "finite"),
    ("inf velocity", BALL.replace("[0, -1, 0]", "[0, -inf, 0]"), "body[0].velocity", "finite"),
    ("nan radius", BALL.replace("0.5", "nan"), "body[0].radius", "finite"),
    ("nan dt", "[simulation]\ndt = nan\n" + BALL, "simulation.dt", "finite"),
    ("radius zero", BALL.replace("0.5", "0"), "body[0].radius", "> 0"),
    ("mass negative", BALL + "mass = -1\n", "body[0].mass", "> 0"),
    ("restitution negative", "[simulation]\nrestitution = -0.5\n" + BALL, "simulation.restitution", ">= 0"),
    ("dt zero", "[simulation]\ndt = 0\n" + BALL, "simulation.dt", "> 0"),
    ("mode unknown", '[simulation]\nmode = "fast"\n' + BALL, "simulation.mode", "'euler' or 'exact'"),
    ("title a number", "[simulation]\ntitle = 3\n" + BALL, "simulation.title", "string"),
    ("box size zero", '[[body]]\nshape = "aabb"\nposition = [0, 0, 0]\nsize = [1, 0, 1]\n', "body[0].size.y", "> 0"),
    ("zero plane normal", BALL + FLOOR.replace("[0, 1, 0]", "[0, 0, 0]"), "static[0].normal", "zero vector"),
    (
        "collinear plane points",
        BALL + '[[static]]\nshape = "plane"\npoints = [[0, 0, 0], [1, 1, 1], [2, 2, 2]]\n',
        "static[0].points",
        "collinear",
    ),
    (
        "coincident plane points",
        BALL + '[[static]]\nshape = "plane"\npoints = [[1, 0, 0], [1, 0, 0], [0, 0, 1]]\n',
        "static[0].points",
        "collinear",
    ),
    (
        "two plane points",
        BALL + '[[static]]\nshape = "plane"\npoints = [[0, 0, 0], [1, 0, 0]]\n',
        "static[0].points",
        "three points",
    ),
    (
        "nan in a plane point",
        BALL + '[[static]]\nshape = "plane"\npoints = [[0, 0, 0], [1, 0, nan], [0, 0, 1]]\n',
        "static[0].points",
        "finite",
    ),
    (
        "zero line direction",
        '[[body]]\nshape = "circle"\nposition = [0, 3]\nradius = 1\n'
        '[[static]]\nshape = "line"\npoint = [0, 0]\ndirection = [0, 0]\n',
        "static[0].direction",
        "zero vector",
    ),
    (
        "circle off the plane",
        '[[body]]\nshape = "circle"\nposition = [0, 3, 1]\nradius = 1\n',
        "body[0].position",
        "z = 0",
    ),
    ("duplicate names", BALL + BALL.replace("[0, 3, 0]", "[5, 3, 0]"), "body[1].name", "unique"),
    ("empty name", BALL.replace('"ball"', '""'), "body[0].name", "non-empty"),
    (
        "a pair with no query",
        BALL + '[[static]]\nshape = "line"\npoint = [0, 0]\ndirection = [1, 0]\n',
        "body[0].shape",
        "cannot collide",
    ),
    ("not TOML", "[[body]\n", "file", "not valid TOML"),
    # --- issue 11: what got through ---------------------------------------------------------------
    ("nested 500 arrays deep", "[simulation]\nsteps = " + "[" * 500 + "]" * 500 + "\n" + BALL, "file", "nested"),
    ("an integer of 400 digits", "[simulation]\nsteps = " + "9" * 400 + "\n" + BALL, "simulation.steps", "at most"),
    ("a radius of 400 digits", BALL.replace("0.5", "9" * 400), "body[0].radius", "too large"),
    ("2 velocity components for a sphere", BALL.replace("[0, -1, 0]", "[0, -1]"), "body[0].velocity", "3 numbers"),
    ("2 position components for a sphere", BALL.replace("[0, 3, 0]", "[0, 3]"), "body[0].position", "3 numbers"),
    ("an escape in a name", BALL.replace('"ball"', '"ba\\u001b[2Jll"'), "body[0].name", "control character"),
    ("a newline in a name", BALL.replace('"ball"', '"ball\\ncollision at step 1"'), "body[0].name", "control"),
    ("a NUL in a title", '[simulation]\ntitle = "a\\u0000b"\n' + BALL, "simulation.title", "control character"),
    ("a speed beyond the range", BALL.replace("[0, -1, 0]", "[1e200, 0, 0]"), "body[0].velocity", "at most"),
    ("a position beyond the range", BALL.replace("[0, 3, 0]", "[0, 3e300, 0]"), "body[0].position", "at most"),
    ("dt beyond the range", "[simulation]\ndt = 1e308\n" + BALL, "simulation.dt", "at most"),
    ("restitution beyond the range", "[simulation]\nrestitution = 1e308\n" + BALL, "simulation.restitution", "at most"),
    ("gravity beyond the range", "[simulation]\ngravity = [0, -1e300, 0]\n" + BALL, "simulation.gravity", "at most"),
    (
        "steps beyond the range",
        "[simulation]\nsteps = 100000000000000000000000\n" + BALL,
        "simulation.steps",
        "at most",
    ),
    ("a radius below the range", BALL.replace("0.5", "5e-324"), "body[0].radius", "at least"),
    ("a mass beyond the range", BALL + "mass = 1e300\n", "body[0].mass", "at most"),
    (
        "a plane point beyond the range",
        BALL + FLOOR.replace("[0, 0, 0]", "[0, -1e100, 0]"),
        "static[0].point",
        "at most",
    ),
]


@pytest.mark.parametrize(("text", "field", "form"), [b[1:] for b in BAD_FILES], ids=[b[0] for b in BAD_FILES])
def test_a_bad_scenario_file_exits_65_naming_the_file_and_the_field(
    text: str, field: str, form: str, tmp_path: Path
) -> None:
    path = tmp_path / "scenario.toml"
    path.write_text(text)
    with pytest.raises(ScenarioError) as caught:
        load_scenario(path)
    assert caught.value.field == field
    assert caught.value.source == str(path)
    message = str(caught.value)
    assert message.startswith(f"{path}: {field}: ") and form in message, message
    result = run_cli(["run", str(path)])
    assert result.status == 65
    assert result.out == ""
    assert len(result.err.strip().splitlines()) == 1
    assert f"{path}: {field}: " in result.err and "Traceback" not in result.err


def test_a_file_that_is_not_utf8_exits_65_naming_the_file(tmp_path: Path) -> None:
    path = tmp_path / "f.toml"
    path.write_bytes(b"\xff")
    result = run_cli(["run", str(path)])
    assert result.status == 65
    assert (
        result.err.strip() == f"collisionlab: invalid scenario: {path}: file: is not UTF-8 text (byte 0xff at offset 0)"
    )


def test_a_file_too_large_is_refused_before_it_is_read_whole(tmp_path: Path) -> None:
    path = tmp_path / "big.toml"
    path.write_text(BALL + "# " + "x" * MAX_SCENARIO_BYTES + "\n")
    result = run_cli(["run", str(path)])
    assert result.status == 65
    assert f"{path}: file: is larger than {MAX_SCENARIO_BYTES:,} bytes" in result.err


def test_an_endless_file_is_refused_without_reading_it_all() -> None:
    # /dev/zero never ends: reading it whole grew to 3.8 GB. Only the limit (plus one byte) is read.
    result = run_cli(["run", "/dev/zero"])
    assert result.status == 65
    assert "/dev/zero: file: is larger than" in result.err


def test_a_huge_bad_value_is_shortened_in_the_message(tmp_path: Path) -> None:
    path = tmp_path / "long.toml"
    path.write_text(BALL.replace('"sphere"', '"' + "cube" * 100_000 + '"'))
    result = run_cli(["run", str(path)])
    assert result.status == 65
    assert "body[0].shape" in result.err and "..." in result.err
    assert len(result.err) < 300


def test_a_missing_file_is_reported_without_a_traceback(tmp_path: Path) -> None:
    result = run_cli(["run", str(tmp_path / "nowhere.toml")])
    assert result.status == 1  # not bad data but a failure to read: "other failure", naming the file
    assert "nowhere.toml" in result.err and "cannot be read" in result.err


# --- what a valid file may say ------------------------------------------------------------------
def test_defaults_for_what_a_file_leaves_out() -> None:
    scenario = parse_scenario(tomllib.loads('[[body]]\nshape = "sphere"\nposition = [0, 3, 0]\nradius = 1\n'), "x.toml")
    (body,) = scenario.bodies
    assert body.name == "body1" and body.mass == 1.0 and body.velocity.as_tuple() == (0, 0, 0)
    assert body.restitution is None
    s = scenario.settings
    assert (s.dt, s.steps, s.restitution, s.mode) == (0.01, 100, 1.0, "euler")
    assert scenario.title == "x"


def test_a_plane_from_three_points_equals_the_plane_from_point_and_normal() -> None:
    by_points = load_demo("sphere-plane").obstacles[0].shape
    assert isinstance(by_points, Plane)
    # (b - a) x (c - a) = (0, 0, 1) x (1, 0, 0) = (0, 1, 0)
    assert by_points.unit_normal.as_tuple() == (0.0, 1.0, 0.0)
    text = BALL + FLOOR
    by_normal = parse_scenario(tomllib.loads(text)).obstacles[0].shape
    assert isinstance(by_normal, Plane)
    assert by_normal.unit_normal == by_points.unit_normal


def test_boxes_are_given_by_centre_and_full_size() -> None:
    box = load_demo("aabb3d").bodies[1].shape
    assert isinstance(box, AABB)
    assert box.min_corner.as_tuple() == (2.55, -0.3, -0.4) and box.max_corner.as_tuple() == (3.55, 0.7, 0.6)


def test_per_object_restitution_is_read() -> None:
    scenario = parse_scenario(tomllib.loads(BALL + "restitution = 0.25\n" + FLOOR + "restitution = 0.5\n"))
    assert scenario.bodies[0].restitution == 0.25 and scenario.obstacles[0].restitution == 0.5


def test_the_demos_are_the_example_files() -> None:
    for name in EXAMPLE_NAMES:
        assert demo_text(name) == Path(example(name)).read_text()
        assert load_demo(name) == load_scenario(example(name))


# --- writing: scenario_to_toml round-trips ---------------------------------------------------------
def _reload(scenario: Scenario) -> Scenario:
    return parse_scenario(tomllib.loads(check_scenario_text(scenario_to_toml(scenario))), "round-trip.toml")


@pytest.mark.parametrize("name", demo_names())
def test_scenario_to_toml_round_trips_every_example(name: str) -> None:
    original = load_demo(name)
    again = _reload(original)
    assert again == original  # every setting, shape, velocity, mass and name, bit for bit
    assert scenario_to_toml(again) == scenario_to_toml(original)
    if name in HEAVY_EXAMPLES:  # its first steps only (tests/cli_helpers.py)
        original, again = (s.with_settings(steps=HEAVY_EXAMPLES[name]) for s in (original, again))
    first, second = simulate(original), simulate(again)
    assert [e.to_dict() for e in first.events] == [e.to_dict() for e in second.events]
    assert first.frames[-1] == second.frames[-1]


def test_round_trip_keeps_overrides_gravity_and_odd_names() -> None:
    text = (
        '[simulation]\ntitle = "a \\"quoted\\" title"\ndt = 0.003\nsteps = 7\nrestitution = 0.3\n'
        'gravity = [0, -9.81, 0]\nmode = "exact"\n'
        + BALL.replace('"ball"', '"ball \\\\ one"')
        + "mass = 2.5\nrestitution = 0.9\n"
        + '[[body]]\nname = "box"\nshape = "aabb"\nposition = [0.1, 5.3, -0.7]\nsize = [0.3, 0.2, 0.1]\n'
        + FLOOR
        + "restitution = 0.1\n"
    )
    original = parse_scenario(tomllib.loads(text), "odd.toml")
    assert _reload(original) == original
    assert original.title == 'a "quoted" title' and original.bodies[0].name == "ball \\ one"


def test_round_trip_of_2d_scenarios_keeps_them_2d() -> None:
    for name in ("circle-line", "circle-box", "head-on", "ball-in-box"):
        again = _reload(load_demo(name))
        assert again.dims == 2
        assert all(b.position.z == 0.0 for b in again.bodies)


def test_every_number_written_is_finite() -> None:
    for name in demo_names():
        text = scenario_to_toml(load_demo(name))
        assert "nan" not in text
        data = tomllib.loads(text)
        assert all(isinstance(v, float) and math.isfinite(v) for v in data["simulation"]["gravity"])


def test_a_sphere_is_written_with_its_radius() -> None:
    scenario = load_demo("sphere-plane")
    assert isinstance(scenario.bodies[0].shape, Sphere)
    assert "radius = 0.5" in scenario_to_toml(scenario)


# --- fuzz: whatever a file holds, the answer is a scenario or one ScenarioError ------------------
# Moved to tests/test_fuzz_scenario_data.py (the same tables of any keys and values, plus plausible
# scenarios over the whole float range, run and rendered), driven by tests/fuzz_harness.py.


@pytest.mark.parametrize(
    ("extra", "field"),
    [("velocity = [1, 0, 0.5]\n", "body[0].velocity"), ("", "simulation.gravity")],
)
def test_a_2d_box_cannot_be_given_motion_along_z(tmp_path: Path, extra: str, field: str) -> None:
    # Found by the fuzzer: a 2D box moving along z became a flat 3D box after one step, and its
    # pair with a 2D box or a line ended the run in UnsupportedPairError (exit 1, "unexpected").
    gravity = "" if extra else "[simulation]\ngravity = [0, -9.81, 1]\n"
    text = (
        gravity + '[[body]]\nname = "b"\nshape = "aabb"\nposition = [0, 0]\nsize = [1, 1]\n' + extra
        + '[[static]]\nname = "l"\nshape = "line"\npoint = [0, -2]\ndirection = [1, 0]\n'
    )  # fmt: skip
    path = tmp_path / "flat.toml"
    path.write_text(text)
    result = run_cli(["run", str(path)])
    assert result.status == 65, result.err
    assert f"{path}: {field}: " in result.err and "x-y plane" in result.err


def test_a_plane_tilted_out_of_the_x_y_plane_cannot_meet_a_2d_box(tmp_path: Path) -> None:
    # Found by the fuzzer: a plane whose normal has z != 0 pushed a 2D box along z; the box became
    # a flat 3D box and its other pairs ended the run in UnsupportedPairError.
    text = (
        '[[body]]\nname = "b"\nshape = "aabb"\nposition = [0, 0]\nsize = [1, 1]\nvelocity = [0, -1]\n'
        '[[static]]\nname = "p"\nshape = "plane"\npoint = [0, -1, 0]\nnormal = [0, 1, 0.5]\n'
    )
    path = tmp_path / "tilted.toml"
    path.write_text(text)
    result = run_cli(["run", str(path)])
    assert result.status == 65, result.err
    assert f"{path}: static[0].normal: " in result.err and "x-y plane" in result.err


def test_a_moving_2d_box_cannot_meet_a_sphere(tmp_path: Path) -> None:
    # Found by the fuzzer: a sphere moving along z hit a moving 2D box and pushed it along z.
    text = (
        '[[body]]\nname = "b"\nshape = "aabb"\nposition = [0, 0]\nsize = [1, 1]\n'
        '[[body]]\nname = "s"\nshape = "sphere"\nposition = [0, 0, 3]\nradius = 1\nvelocity = [0, 0, -1]\n'
    )
    path = tmp_path / "mixed.toml"
    path.write_text(text)
    result = run_cli(["run", str(path)])
    assert result.status == 65, result.err
    assert f"{path}: body[0].shape: " in result.err and "x-y plane" in result.err


def test_two_gas_tables_in_regions_of_their_own_are_a_mixture() -> None:
    text = TWO_TABLES.format(big="[[0, 0], [20, 10]]", small="[[0, 10], [20, 20]]")
    scenario = parse_scenario(tomllib.loads(check_scenario_text(text)))
    assert scenario.event_driven and len(scenario.bodies) == 60
    kinds, labels = scenario.ball_species()
    assert [(k.name, k.radius, k.mass, k.count) for k in kinds] == [("big", 1.0, 1.0, 20), ("small", 0.5, 1.0, 40)]
    assert labels.tolist() == [0] * 20 + [1] * 40
    assert parse_scenario(tomllib.loads(scenario_to_toml(scenario))) == scenario
