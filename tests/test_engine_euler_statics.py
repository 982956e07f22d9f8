"""Forward Euler and the static lines and planes (issue 27): a body never ends on the far side of a
line or plane it started on, a pour stays in its box without making energy, and a column rests
on its floor. The oracles are geometry and the energy of the start, not the engine's numbers."""

from __future__ import annotations

import numpy as np
import pytest

from collisionlab import Circle, Line, Plane, Sphere
from collisionlab.engine.params import WorldParams
from collisionlab.engine.world import World
from collisionlab.model import Body, Obstacle, Scenario, Settings

G = 9.81


def _energy(world: World) -> float:
    return world.kinetic_energy() + world.potential_energy()


@pytest.mark.parametrize("speed", [30.0, 100.0, 1e4])
@pytest.mark.parametrize("target", ["plane", "line"])
def test_a_ball_thrown_fast_at_a_plane_or_line_never_ends_past_it(target: str, speed: float) -> None:
    # r 0.1 at up to 100 m per step: the old stepper let it pass (its centre past the plane, the
    # two-sided plane then saw it from below and let it go on).
    if target == "plane":
        ball = Body("ball", Sphere((0, 0.55, 0), 0.1), velocity=(0.3, -speed, 0))
        wall = Obstacle("floor", Plane((0, 0, 0), (0, 1, 0)))
    else:
        ball = Body("ball", Circle((0, 0.55), 0.1), velocity=(0.3, -speed))
        wall = Obstacle("floor", Line((0, 0), (1, 0)))
    world = World(Scenario(Settings(dt=0.01, steps=20, restitution=0.5), (ball,), (wall,)))
    for _ in range(20):
        world.step(1)
        assert world.position_array[0, 1] > 0.0  # the centre on the side it started on
    assert world.position_array[0, 1] >= 0.1  # and not into the plane either
    assert world.velocity_array[0, 1] > 0.0  # it bounced
    assert len(world.record.events) == 1


def test_a_ball_below_a_line_stays_below_it() -> None:
    # The side is the body's own: a line is two-sided.
    ball = Body("ball", Circle((0, -0.55), 0.1), velocity=(0, 100.0))
    world = World(Scenario(Settings(dt=0.01, steps=10), (ball,), (Obstacle("l", Line((0, 0), (1, 0))),)))
    world.step(10)
    assert world.position_array[0, 1] <= -0.1


def _pour(n: int, width: float, steps: int) -> Scenario:
    """``n`` circles (r 0.5, m 1) on a grid 1.2 diameters apart from y = 2 m, over a box of three
    lines ``width`` wide, e 0.5 (bench/bench_piles.py's scene)."""
    spacing = 1.2
    per_row = int((width - 1.0) // spacing)
    k = np.arange(n)
    x = -width / 2 + 0.5 + spacing * (k % per_row) + 0.5 * (width - 1.0 - spacing * (per_row - 1))
    x += 0.025 * np.sin(1.7 * k)
    y = 2.0 + spacing * (k // per_row)
    bodies = tuple(Body(f"c{i}", Circle((float(x[i]), float(y[i])), 0.5), velocity=(0, 0)) for i in range(n))
    lines = (
        Obstacle("floor", Line((0, 0), (1, 0))),
        Obstacle("left", Line((-width / 2, 0), (0, 1))),
        Obstacle("right", Line((width / 2, 0), (0, 1))),
    )
    settings = Settings(dt=0.01, steps=steps, restitution=0.5, gravity=(0, -G, 0), mode="euler")
    return Scenario(settings, bodies, lines)


def test_a_pour_in_euler_mode_stays_in_its_box_and_makes_no_energy() -> None:
    # 200 circles in a 10 m box, 29 rows: the top row lands at about 2.7 s. The old stepper let
    # the pile through the floor from step ~180 (and out through the sides).
    width, steps = 10.0, 320
    world = World(_pour(200, width, steps), params=WorldParams(compiled=True))
    start = _energy(world)
    world.step(steps)
    pos = world.position_array
    assert pos[:, 1].min() > 0.0
    assert np.abs(pos[:, 0]).max() < width / 2
    assert _energy(world) <= start + 0.01 * abs(start)


def test_a_column_of_spheres_rests_on_its_floor_plane() -> None:
    # 10 spheres touching, the lowest on the floor: it sank 0.1 m on average (potential 490.5 ->
    # 480.6 J) and its middle bounced (3,000 events, 3.2 J of kinetic energy after 10 s).
    bodies = tuple(Body(f"b{i}", Sphere((0, 0.5 + i, 0), 0.5), velocity=(0, 0, 0)) for i in range(10))
    floor = Obstacle("floor", Plane((0, 0, 0), (0, 1, 0)))
    settings = Settings(dt=0.01, steps=1000, restitution=0.5, gravity=(0, -G, 0), mode="euler")
    world = World(Scenario(settings, bodies, (floor,)), params=WorldParams(compiled=True))
    start = world.potential_energy()
    world.step(1000)
    assert world.position_array[:, 1].min() >= 0.5 - 1e-6  # nothing into the floor
    assert world.potential_energy() >= start - 1e-3 * start  # 0.49 J: the balls 1 mm deep at most on average
    assert world.kinetic_energy() < 0.1
    assert {e.step for e in world.record.events} == {1}  # the first touches only, no bouncing
