"""The JSON Schemas shipped in collisionlab.schemas: valid schemas, met by every output, and
strict enough to fail on what is not collisionlab's (a test that cannot fail is a bug)."""

from __future__ import annotations

import copy
import json
import tomllib

import jsonschema
import pytest

from collisionlab.cli.render import render_json
from collisionlab.demos import demo_names, demo_text, load_demo
from collisionlab.errors import InvalidInputError
from collisionlab.model import Body, Obstacle, Scenario, Settings
from collisionlab.schemas import SCHEMAS, schema
from collisionlab.shapes import Plane, Sphere
from collisionlab.world import simulate
from tests.cli_helpers import HEAVY_EXAMPLES, run_cli
from tests.schema_check import check


@pytest.mark.parametrize("name", SCHEMAS)
def test_each_shipped_schema_is_a_valid_draft_2020_12_schema(name: str) -> None:
    document = schema(name)
    assert document["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    jsonschema.Draft202012Validator.check_schema(document)


def test_an_unknown_schema_is_refused_by_name() -> None:
    with pytest.raises(InvalidInputError, match="schema: must be one of run, gas, scenario"):
        schema("runs")


@pytest.mark.parametrize("name", demo_names())
def test_every_shipped_example_meets_the_scenario_schema(name: str) -> None:
    check("scenario", tomllib.loads(demo_text(name)))


@pytest.mark.parametrize("name", demo_names())
def test_every_examples_run_in_both_modes_meets_the_run_schema(name: str) -> None:
    steps = HEAVY_EXAMPLES.get(name)  # a heavy example: its first steps, first and last frames
    for mode in ("euler", "exact"):
        scenario = load_demo(name).with_settings(mode=mode)
        record = simulate(scenario) if steps is None else simulate(scenario.with_settings(steps=steps), every=steps)
        check("run", json.loads(render_json(record)))


def test_a_slow_touch_is_documented_as_below_the_rest_threshold() -> None:
    # Exact mode, weak gravity (0.01 m/s^2): a ball 2e-7 m above the floor (beyond CONTACT_MARGIN,
    # 1e-7 m, so not yet resting) falls at 0.5 mm/s and lands at sqrt(0.0005^2 + 2 * 0.01 * 2e-7)
    # = 0.504 mm/s, below REST_SPEED (1 mm/s): no bounce (e = 0), and the event says why. (Without
    # gravity nothing rests and a slow touch bounces; in euler mode a slow touch under gravity is a
    # resting contact and no event at all.)
    ball = Body("ball", Sphere((0, 1 + 2e-7, 0), 1), velocity=(0, -0.0005, 0))
    floor = Obstacle("floor", Plane((0, 0, 0), (0, 1, 0)))
    settings = Settings(dt=0.01, steps=5, restitution=0.5, gravity=(0, -0.01, 0), mode="exact")
    record = simulate(Scenario(settings, (ball,), (floor,)))
    (event,) = check("run", json.loads(render_json(record)))["events"]
    assert event["below_rest_threshold"] is True and event["restitution"] == 0.0


def test_run_name_and_gas_outputs_meet_their_schemas() -> None:
    assert run_cli(["run", "head-on", "--format", "json"]).status == 0  # run_cli checks the schema
    assert run_cli(["gas", "--n", "50", "--steps", "5", "--format", "json"]).status == 0


BAD_RUN_EDITS = [
    ("an undocumented event field", lambda d: d["events"][0].update(extra=1)),
    ("an event without below_rest_threshold", lambda d: d["events"][0].pop("below_rest_threshold")),
    ("a 2-component position", lambda d: d["frames"][0]["bodies"][0].update(position=[0.0, 1.0])),
    ("an unknown mode", lambda d: d["settings"].update(mode="verlet")),
    ("a negative kinetic energy", lambda d: d["summary"].update(kinetic_energy_end=-1.0)),
]


@pytest.mark.parametrize(("what", "edit"), BAD_RUN_EDITS, ids=[w for w, _ in BAD_RUN_EDITS])
def test_the_run_schema_refuses(what: str, edit: object) -> None:
    data = json.loads(render_json(simulate(load_demo("head-on"))))
    check("run", data)
    broken = copy.deepcopy(data)
    edit(broken)  # type: ignore[operator]
    with pytest.raises(jsonschema.ValidationError):
        check("run", broken)


BAD_SCENARIOS = [
    ("an unknown key", '[[body]]\nshape = "sphere"\nposition = [0, 0, 0]\nradius = 1\ncolour = "red"\n'),
    ("a sphere without radius", '[[body]]\nshape = "sphere"\nposition = [0, 0, 0]\n'),
    ("a box without size", '[[body]]\nshape = "aabb"\nposition = [0, 0]\n'),
    ("no body", '[simulation]\ndt = 0.1\n'),
    ("a zero dt", '[simulation]\ndt = 0\n[[body]]\nshape = "circle"\nposition = [0, 0]\nradius = 1\n'),
    ("a plane with neither form", '[[body]]\nshape = "sphere"\nposition = [0, 0, 0]\nradius = 1\n'
     '[[static]]\nshape = "plane"\npoint = [0, 0, 0]\n'),
    ("a 4-component vector", '[[body]]\nshape = "sphere"\nposition = [0, 0, 0, 0]\nradius = 1\n'),
]  # fmt: skip


@pytest.mark.parametrize(("what", "text"), BAD_SCENARIOS, ids=[w for w, _ in BAD_SCENARIOS])
def test_the_scenario_schema_refuses_what_the_loader_refuses(what: str, text: str) -> None:
    with pytest.raises(jsonschema.ValidationError):
        check("scenario", tomllib.loads(text))
    assert run_cli_file(text) == 65  # and collisionlab itself refuses it: invalid data


def run_cli_file(text: str) -> int:
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "bad.toml"
        path.write_text(text, encoding="utf-8")
        return run_cli(["run", str(path)]).status
