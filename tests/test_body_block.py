"""BodyBlock and Bodies: many bodies as arrays, one sequence of a scenario's bodies."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from collisionlab.body_block import Bodies, BodyBlock
from collisionlab.errors import InvalidInputError
from collisionlab.model import Body, Box, Scenario, Settings
from collisionlab.scenario_file import parse_scenario, scenario_to_toml
from collisionlab.shapes import AABB, Circle, Sphere
from collisionlab.vector import Vector3D


def _block(name: str = "g", n: int = 3, shape: str = "circle", **kwargs: object) -> BodyBlock:
    positions = [[3.0 * i, 0.0] for i in range(n)] if shape == "circle" else [[3.0 * i, 0.0, 0.0] for i in range(n)]
    velocities = [[0.0, 0.0]] * n if shape == "circle" else [[0.0, 0.0, 0.0]] * n
    return BodyBlock(name, shape, (1.0, 1.0, 1.0), positions, velocities, **kwargs)  # type: ignore[arg-type]


def test_a_block_builds_its_bodies_only_when_read() -> None:
    block = BodyBlock("g", "sphere", (0.5, 0.5, 0.5), [[0, 0, 0], [2, 0, 0]], [[1, 0, 0], [-1, 0, 0]], mass=2.0)
    assert len(block) == 2
    first, second = block
    assert first == Body("g0", Sphere((0, 0, 0), 0.5), (1, 0, 0), 2.0)
    assert second.name == "g1" and second.shape == Sphere((2, 0, 0), 0.5) and block[-1] == second
    assert block[0:1] == [first]
    with pytest.raises(IndexError):
        block[2]


def test_a_block_of_boxes_has_its_half_extents() -> None:
    block = BodyBlock("c", "aabb", (0.5, 1.0, 0.0), [[0, 0]], [[0, 0]])
    assert block.dims == 2 and block[0].shape == AABB((-0.5, -1.0), (0.5, 1.0))


def test_block_arrays_are_read_only_copies() -> None:
    positions = np.array([[0.0, 0.0], [3.0, 0.0]])
    block = BodyBlock("g", "circle", (1, 1, 1), positions, np.zeros((2, 2)))
    positions[0, 0] = 99.0
    assert block.positions[0].tolist() == [0.0, 0.0, 0.0]  # copied, with z = 0 added
    with pytest.raises(ValueError, match="read-only"):
        block.positions[0, 0] = 1.0


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"shape": "cube"}, "shape"),
        ({"half": (-1.0, 1.0, 1.0)}, "radius"),
        ({"positions": [[0.0, math.nan]]}, "positions"),
        ({"positions": [[0.0, 0.0, 1.0]]}, "velocities"),  # a circle off the x-y plane
        ({"velocities": [[0.0, 0.0], [1.0, 1.0]]}, "velocities"),  # two rows for one body
        ({"positions": "ab"}, "positions"),
        ({"mass": 0.0}, "mass"),
        ({"restitution": -1.0}, "restitution"),
        ({"name": "a\nb"}, "name"),
    ],
)
def test_bad_blocks_are_refused_naming_the_field(kwargs: dict[str, object], field: str) -> None:
    args: dict[str, object] = {
        "name": "g",
        "shape": "circle",
        "half": (1.0, 1.0, 1.0),
        "positions": [[0.0, 0.0]],
        "velocities": [[0.0, 0.0]],
    }
    args.update(kwargs)
    with pytest.raises(InvalidInputError) as caught:
        BodyBlock(**args)  # type: ignore[arg-type]
    assert caught.value.field == field


def test_bodies_chain_singles_and_blocks_in_order() -> None:
    a = Body("a", Circle((0, 10), 1), (0, 0))
    b = Body("b", Circle((5, 10), 1), (0, 0))
    bodies = Bodies([a, _block(), b])
    assert [x.name for x in bodies] == ["a", "g0", "g1", "g2", "b"] == bodies.names()
    assert bodies[4] == b and bodies[2].name == "g1" and bodies[-1] == b
    assert bodies.singles == (a, b) and len(bodies.blocks) == 1
    assert bodies == (a, *_block(), b)  # equal to the tuple of the same bodies
    columns = bodies.columns()
    assert columns.pos[:, 0].tolist() == [0.0, 0.0, 3.0, 6.0, 5.0]
    assert columns.kind.tolist() == [0, 0, 0, 0, 0] and columns.ima.tolist() == [1.0] * 5


def test_columns_hold_kinematic_bodies_as_zero_inverse_mass() -> None:
    bodies = Bodies([Body("k", Sphere((0, 0, 0), 1), (1, 0, 0), math.inf), _block(shape="sphere", mass=4.0)])
    columns = bodies.columns()
    assert columns.ima.tolist() == [0.0, 0.25, 0.25, 0.25] and columns.kind.tolist() == [1, 1, 1, 1]


@pytest.mark.parametrize(
    ("names", "clash"),
    [
        (("g", "g"), True),  # the same name
        (("g", "g1"), True),  # g1's bodies g10, g11, g12 are also bodies of g (g0 .. g19)
        (("g", "h"), False),
        (("g", "g01"), False),  # g01 is no body of g (numbers have no leading zero)
    ],
)
def test_blocks_whose_names_collide_are_refused(names: tuple[str, str], clash: bool) -> None:
    first = _block(names[0], n=20)
    second = _block(names[1], n=3)
    settings = Settings()
    shifted = second.positions + np.array([0.0, 50.0, 0.0])  # apart from the first block
    second = BodyBlock(second.name, "circle", (1, 1, 1), shifted, second.velocities)
    if clash:
        with pytest.raises(InvalidInputError, match="unique"):
            Scenario(settings, [first, second])
    else:
        assert len(Scenario(settings, [first, second]).bodies) == 23


def test_a_single_body_named_as_a_blocks_body_is_refused() -> None:
    with pytest.raises(InvalidInputError, match="'g0' to 'g2'"):
        Scenario(Settings(), [_block(), Body("g2", Circle((0, 50), 1), (0, 0))])


def test_a_scenario_of_a_block_in_a_box_has_walls_named() -> None:
    scenario = Scenario(Settings(), [_block()], box=Box((-2, -2), (10, 2)))
    assert scenario.dims == 2 and [w[0] for w in scenario.box.walls()] == ["wall x-", "wall x+", "wall y-", "wall y+"]  # type: ignore[union-attr]
    with pytest.raises(InvalidInputError, match="inside its walls"):
        Scenario(Settings(), [_block()], box=Box((0, -2), (10, 2)))  # g0 sticks out of x = 0
    with pytest.raises(InvalidInputError, match="unique"):
        Scenario(Settings(), [Body("wall x-", Circle((0, 0), 1), (0, 0))], box=Box((-2, -2), (10, 2)))


def test_a_periodic_box_needs_the_event_driven_stepper() -> None:
    block = _block()
    periodic = Box((-2, -2), (10, 2), "periodic")
    with pytest.raises(InvalidInputError, match="periodic box needs") as caught:
        Scenario(Settings(mode="euler"), [block], box=periodic)
    assert caught.value.field == "box.boundary"
    exact = Scenario(Settings(mode="exact"), [block], box=periodic)
    assert exact.event_driven
    walls = Box((-2, -2), (10, 2))
    # Another radius or mass: a mixture, event by event too; a box, an infinite mass or a body's
    # own restitution: the general exact stepper.
    for other, driven in [
        (Body("big", Circle((0, 1.5), 0.4), (0, 0)), True),
        (Body("heavy", Circle((0, 1.5), 0.4), (0, 0), mass=5.0), True),
        (Body("crate", AABB((-0.4, 1.1), (0.4, 1.9)), (0, 0)), False),
        (Body("fixed", Circle((0, 1.5), 0.4), (0, 0), mass=math.inf), False),
        (Body("bouncy", Circle((0, 1.5), 0.4), (0, 0), restitution=0.5), False),
    ]:
        assert Scenario(Settings(mode="exact"), [block, other], box=walls).event_driven is driven, other.name


def test_a_block_of_gas_reads_back_from_its_file() -> None:
    text = """
[simulation]
mode = "exact"
tc = 0.001
[[gas]]
name = "d"
shape = "circle"
radius = 0.5
region = [[0, 0], [20, 20]]
count = 50
seed = 3
[box]
region = [[0, 0], [20, 20]]
boundary = "periodic"
"""
    scenario = parse_scenario(tomllib.loads(text))
    assert isinstance(scenario.bodies.parts[0], BodyBlock) and len(scenario.bodies) == 50
    again = parse_scenario(tomllib.loads(scenario_to_toml(scenario)))
    assert again == scenario and again.settings.tc == 0.001 and again.box == Box((0, 0), (20, 20), "periodic")
    assert again.bodies[7].velocity == scenario.bodies[7].velocity != Vector3D(0, 0, 0)
