"""The contact solver (``contacts = "solve"``, :mod:`collisionlab.engine.contact_kernels`): stacks
stay put, impacts stay exact and in order, supports carry the weight and balance momentum,
piles settle and sleep, and a sleeping pile wakes when hit. Every oracle is a closed form or a
conservation law, never the solver's own numbers.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from collisionlab import AABB, Circle, Line, Plane, Sphere
from collisionlab.body_block import BodyBlock
from collisionlab.engine.contact_stepper import ContactStepper
from collisionlab.engine.params import WorldParams
from collisionlab.engine.world import World
from collisionlab.errors import InvalidInputError
from collisionlab.model import Body, Box, Obstacle, Scenario, Settings
from collisionlab.scenario_file import load_scenario, parse_scenario
from collisionlab.tolerances import SLEEP_TIME
from tests.cli_helpers import EXAMPLES

G = 9.81
DOWN = (0.0, -G, 0.0)


def settings(steps: int, e: float = 0.5, dt: float = 0.01, gravity: tuple[float, float, float] = DOWN) -> Settings:
    return Settings(dt=dt, steps=steps, restitution=e, gravity=gravity, mode="exact", contacts="solve")


def floor_3d() -> Obstacle:
    return Obstacle("floor", Plane((0, 0, 0), (0, 1, 0)))


def column(count: int) -> tuple[Body, ...]:
    return tuple(Body(f"b{i}", Sphere((0, 0.5 + i, 0), 0.5), velocity=(0, 0, 0)) for i in range(count))


def pyramid() -> tuple[tuple[Body, ...], tuple[Obstacle, ...]]:
    """15 touching circles (rows of 5, 4, 3, 2, 1) on a line, between two walls touching the base."""
    bodies = []
    for row in range(5):
        for i in range(5 - row):
            x, y = -2.0 + 0.5 * row + i, 0.5 + row * math.sqrt(3.0) / 2.0
            bodies.append(Body(f"c{len(bodies)}", Circle((x, y), 0.5), velocity=(0, 0)))
    walls = (
        Obstacle("floor", Line((0, 0), (1, 0))),
        Obstacle("left", Line((-2.5, 0), (0, 1))),
        Obstacle("right", Line((2.5, 0), (0, 1))),
    )
    return tuple(bodies), walls


def pour(n: int, width: float, steps: int) -> Scenario:
    """``n`` circles on rows 1.2 diameters apart from y = 2 m, over a box of three lines."""
    per_row = int(width / 1.2) - 1
    k = np.arange(n)
    x = -width / 2 + 1.1 + 1.2 * (k % per_row) + 0.05 * np.sin(1.7 * k)
    y = 2.0 + 1.2 * (k // per_row)
    block = BodyBlock("ball", "circle", (0.5, 0.5, 0.5), np.c_[x, y], np.zeros((n, 2)))
    walls = (
        Obstacle("floor", Line((0, 0), (1, 0))),
        Obstacle("left", Line((-width / 2, 0), (0, 1))),
        Obstacle("right", Line((width / 2, 0), (0, 1))),
    )
    return Scenario(settings(steps), (block,), walls)


def assert_asleep_in_box(world: World, n: int, half: float, seconds: float, overlap: float) -> None:
    """Every one of the ``n`` balls (r 0.5 m, 1 kg) asleep and still, its centre inside the box of
    half-width ``half`` (across x, and z in 3D) above the floor, no overlap deeper than
    ``overlap``; the statics' impulses balance momentum: their sum = P_end - P_start - M g T, an
    account kept apart from the velocities, so a misbooked impulse shows."""
    stepper = world.stepper
    assert isinstance(stepper, ContactStepper)
    assert stepper.asleep == n
    assert world.kinetic_energy() == 0.0
    p = world.position_array
    assert np.all(p[:, 1] >= 0.5 - 1e-6)
    assert np.all(np.abs(p[:, [0, 2]]) <= half - 0.5 + 1e-6)  # (z is 0 in 2D)
    assert world.deepest_overlap() <= overlap
    total = np.sum(list(world.record.static_impulses.values()), axis=0)  # type: ignore[union-attr]
    momentum = np.array(world.momentum().as_tuple())
    assert total == pytest.approx(momentum - n * np.array(DOWN) * seconds, abs=1e-9 * n * G * seconds)


# --- stacks stay put ------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "bodies, statics",
    [
        (column(20), (floor_3d(),)),
        (  # a tower of 20 unit boxes
            tuple(Body(f"box{i}", AABB((-0.5, i, -0.5), (0.5, i + 1, 0.5)), velocity=(0, 0, 0)) for i in range(20)),
            (floor_3d(),),
        ),
        pyramid(),
    ],
    ids=["column of 20 spheres", "tower of 20 boxes", "pyramid of 15 circles between walls"],
)
def test_a_stack_at_rest_stays_put_for_ten_seconds_with_no_event(
    bodies: tuple[Body, ...], statics: tuple[Obstacle, ...]
) -> None:
    world = World(Scenario(settings(1000), bodies, statics))
    start = world.position_array
    record = world.run(every=1000)
    assert record.collision_total == 0
    assert np.abs(world.position_array - start).max() <= 1e-9  # no drift over 10 s
    assert record.ledger.integrator == 0.0


def test_each_support_of_a_column_carries_the_weight_above_it() -> None:
    # A column of 20 balls of 1 kg: the floor carries 20 m g, every step, asleep or awake; its
    # impulse over T is 20 m g T = 20 x 9.81 x 10 = 1962 N s (and nothing sideways).
    world = World(Scenario(settings(1000), column(20), (floor_3d(),)))
    record = world.run(every=1000)
    assert record.static_impulses is not None
    assert record.static_impulses["floor"] == pytest.approx([0.0, 20 * G * 10.0, 0.0], abs=1e-6)


# --- impacts stay exact -----------------------------------------------------------------------------
def test_newtons_cradle_leaves_only_the_last_ball_moving() -> None:
    # e = 1, equal masses: momentum 2 kg m/s and energy 2 J go whole to the last ball (the
    # impacts run one after another; a simultaneous solve would share them out).
    scenario = load_scenario(EXAMPLES / "newtons-cradle.toml").with_settings(contacts="solve")
    world = World(scenario)
    world.run(every=150)
    assert world.velocity_array[:, 0].tolist() == pytest.approx([0, 0, 0, 0, 2.0], abs=1e-12)


def test_a_dropped_ball_lands_at_its_time_of_impact_and_bounces_with_e() -> None:
    # From 2 m above the floor: lands at t = sqrt(2 h / g) = sqrt(4 / 9.81) = 0.63855 s, at
    # v = sqrt(2 g h) = 6.2642 m/s, and leaves at e v = 3.1321 m/s.
    ball = Body("ball", Sphere((0, 2.5, 0), 0.5), velocity=(0, 0, 0))
    record = World(Scenario(settings(100), (ball,), (floor_3d(),))).run()
    first = record.events[0]
    assert first.time == pytest.approx(math.sqrt(4.0 / G), rel=1e-12)
    assert first.velocities_after["ball"].y == pytest.approx(0.5 * math.sqrt(2.0 * G * 2.0), rel=1e-12)
    # The ledger: flight is exact (no integrator term) and the losses are theory's.
    ledger = record.ledger
    assert ledger.integrator == 0.0
    assert ledger.collisions == pytest.approx(ledger.collisions_predicted, rel=1e-9)
    assert abs(ledger.residual) < 1e-9


def test_a_ball_slides_down_a_frictionless_incline_as_g_sin_a_t2_over_2() -> None:
    a = math.radians(20.0)
    normal = (-math.sin(a), math.cos(a), 0.0)
    start = (0.5 * normal[0], 0.5 * normal[1], 0.0)
    ball = Body("ball", Sphere(start, 0.5), velocity=(0, 0, 0))
    world = World(Scenario(settings(100), (ball,), (Obstacle("ramp", Plane((0, 0, 0), normal)),)))
    record = world.run(every=100)
    along = 0.5 * G * math.sin(a) * 1.0**2  # after 1 s, down the slope (-cos a, -sin a)
    expected = np.array(start) + along * np.array([-math.cos(a), -math.sin(a), 0.0])
    assert world.position_array[0] == pytest.approx(expected, abs=1e-9)
    assert record.collision_total == 0


# --- piles ----------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def settled_pour() -> World:
    """60 circles poured into a 10 m box, run for 8 s: they sleep by about 6 s (compiled: the session's fixture
    has compiled the kernels; the Python form is the same to the last bit, tested below)."""
    world = World(pour(60, 10.0, 800), WorldParams(compiled=True))
    world.step(800)
    return world


def test_a_pour_settles_sleeps_and_stays_in_its_box(settled_pour: World) -> None:
    assert_asleep_in_box(settled_pour, 60, 5.0, 8.0, overlap=1e-6 * 0.5)


def test_a_pours_collision_losses_are_theorys(settled_pour: World) -> None:
    # The ledger's collision column is the bodies' kinetic energy measured before and after each
    # impact and solve; theory's is summed contact by contact (impacts: (1 - e^2) mu v_n^2 / 2;
    # a solve: the impulses' work P (v_n + v_n') / 2), and the kinetic energy sleep stops. They
    # agree to rounding (the solve's work went uncounted in theory's column before). Flight is
    # exact: no integrator term.
    ledger = settled_pour.record.ledger
    assert ledger.collisions == pytest.approx(ledger.collisions_predicted, rel=1e-12)
    assert ledger.collisions < -1000.0
    assert ledger.integrator == 0.0


def test_a_deep_pour_settles_and_sleeps_within_ten_seconds() -> None:
    # 400 circles in a 20 m box: a pile 20 layers deep, whose bottom contacts carry 20 balls'
    # weight. Solved by sweeps alone it went on jittering (kinetic energy 3e-5 to 8e-5 J a ball
    # at 10 s, never asleep); the solve must reach the bottom for the pile to come to rest.
    world = World(pour(400, 20.0, 1000), WorldParams(compiled=True))
    world.step(1000)
    # No overlap deeper than 1e-6 r: the island is pushed apart in full as it falls asleep (one
    # step's push-apart left 1e-5 m wedged in the pile, 2e-5 r).
    assert_asleep_in_box(world, 400, 10.0, 10.0, overlap=1e-6 * 0.5)
    # Frictionless supports push only along their normals, asleep or awake: the walls never
    # up, the floor never sideways (the floor carries the weight, 400 m g T = 39,240 N s).
    impulses = world.record.static_impulses
    assert impulses is not None
    weight = 400 * G * 10.0
    assert abs(impulses["left"][1]) <= 1e-9 * weight and abs(impulses["right"][1]) <= 1e-9 * weight
    assert abs(impulses["floor"][0]) <= 1e-9 * weight


def test_spheres_poured_into_a_box_of_walls_settle_and_sleep() -> None:
    # 200 spheres (r 0.5 m, 1 kg) on a lattice 1.2 diameters apart, poured into a 5 m square box
    # of four static AABB walls on a floor plane: at rest and asleep by 12 s, every centre inside,
    # no overlap left, and the statics' impulses balance momentum.
    n, half = 200, 2.5
    k = np.arange(n)
    x = -half + 1.1 + 1.2 * (k % 3) + 0.05 * np.sin(1.7 * k)
    z = -half + 1.1 + 1.2 * ((k // 3) % 3) + 0.05 * np.cos(1.3 * k)
    y = 2.0 + 1.2 * (k // 9)
    block = BodyBlock("ball", "sphere", (0.5, 0.5, 0.5), np.c_[x, y, z], np.zeros((n, 3)))
    t, top = 1.0, 40.0
    walls = (
        floor_3d(),
        Obstacle("west", AABB((-half - t, 0, -half - t), (-half, top, half + t))),
        Obstacle("east", AABB((half, 0, -half - t), (half + t, top, half + t))),
        Obstacle("south", AABB((-half, 0, -half - t), (half, top, -half))),
        Obstacle("north", AABB((-half, 0, half), (half, top, half + t))),
    )
    world = World(Scenario(settings(1200), (block,), walls), WorldParams(compiled=True))
    world.step(1200)
    assert_asleep_in_box(world, n, half, 12.0, overlap=1e-6 * 0.5)


def test_a_sleeping_pile_wakes_when_a_ball_lands_on_it() -> None:
    bodies = column(3)
    dropped = Body("dropped", Sphere((0, 9.0, 0), 0.5), velocity=(0, 0, 0))
    world = World(Scenario(settings(200), (*bodies, dropped), (floor_3d(),)))
    world.step(int(SLEEP_TIME / 0.01) + 2)  # the column sleeps; the ball is still falling
    stepper = world.stepper
    assert isinstance(stepper, ContactStepper)
    assert stepper.asleep == 3
    world.step(60)  # it lands (t = sqrt(2 x 5.5 / g) = 1.06 s) and wakes the column
    assert world.record.collision_total >= 1
    assert world.record.events[0].bodies == ("b2", "dropped")


def test_a_world_all_asleep_stays_put_while_its_floor_carries_its_weight() -> None:
    # A column of 3 spheres (1 kg each) sleeps after SLEEP_TIME; from then on a step only books
    # its weight on the floor: 200 steps more leave every position to the last bit, make no event,
    # and add 3 m g dt = 3 x 9.81 x 0.01 = 0.2943 N s a step to the floor's impulse, 58.86 N s.
    world = World(Scenario(settings(400), column(3), (floor_3d(),)))
    world.step(int(SLEEP_TIME / 0.01) + 10)
    stepper = world.stepper
    assert isinstance(stepper, ContactStepper)
    assert stepper.asleep == 3
    before = world.position_array.copy()
    impulses = world.record.static_impulses
    assert impulses is not None
    floor = impulses["floor"][1]
    world.step(200)
    assert np.array_equal(world.position_array, before)
    assert world.record.collision_total == 0
    after = world.record.static_impulses
    assert after is not None
    assert after["floor"][1] - floor == pytest.approx(58.86, rel=1e-12)
    assert after["floor"][0] == 0.0 and after["floor"][2] == 0.0


def test_the_compiled_form_steps_as_the_python_form_to_the_last_bit() -> None:
    # 30 circles through their landing (impacts, clusters, solves): the same source both ways.
    worlds = [World(pour(30, 10.0, 120), WorldParams(compiled=compiled)) for compiled in (False, True)]
    for world in worlds:
        world.step(120)
    python, compiled = worlds
    assert np.array_equal(python.position_array, compiled.position_array)
    assert np.array_equal(python.velocity_array, compiled.velocity_array)
    assert python.record.collision_count == compiled.record.collision_count > 0
    assert python.record.ledger == compiled.record.ledger
    assert python.record.static_impulses == compiled.record.static_impulses


def test_contacts_must_be_events_or_solve() -> None:
    with pytest.raises(InvalidInputError, match="contacts"):
        Settings(contacts="stack")  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match=r"simulation\.contacts"):
        parse_scenario({"simulation": {"mode": "exact", "contacts": "solved"}})


def test_balls_in_a_box_with_their_contacts_solved_rest_on_its_floor() -> None:
    # Balls of one kind in a [box] with no obstacles ran on the event-driven stepper whatever
    # contacts said: "solve" was silently ignored there (a pour into a box never rested).
    block = BodyBlock("ball", "circle", (0.5, 0.5, 0.5), [[-1.0, 2.0], [1.0, 3.0]], np.zeros((2, 2)))
    scenario = Scenario(settings(400), (block,), box=Box((-3, 0), (3, 6)))
    world = World(scenario)
    assert isinstance(world.stepper, ContactStepper)
    world.step(400)
    # On the floor wall (y = 0), each at its radius: the higher one lands at sqrt(2 x 2.5 / g) =
    # 0.71 s at 7.0 m/s, and its bounces (e = 0.5) take 0.71 (1 + 1/2 + 1/4 + ...) = 1.43 s more.
    assert world.position_array[:, 1] == pytest.approx([0.5, 0.5], abs=1e-9)
    assert world.record.static_impulses is not None and "wall y-" in world.record.static_impulses


def test_a_periodic_box_cannot_have_its_contacts_solved() -> None:
    block = BodyBlock("ball", "circle", (0.5, 0.5, 0.5), [[1.0, 1.0]], np.zeros((1, 2)))
    with pytest.raises(InvalidInputError, match='contacts = "events"'):
        Scenario(settings(10, gravity=(0, 0, 0)), (block,), box=Box((0, 0), (4, 4), "periodic"))
