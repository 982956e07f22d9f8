"""The event-driven stepper on the engine's world: balls in a box, run event by event, with the
world's frames, events and ledger (values worked by hand or from closed forms)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from collisionlab.body_block import BodyBlock
from collisionlab.edmd.observables import ExactGas
from collisionlab.engine.event_stepper import EventDrivenStepper
from collisionlab.engine.world import InitialOverlapError, World
from collisionlab.model import Body, Box, Scenario, Settings
from collisionlab.shapes import Circle, Sphere
from collisionlab.vector import Vector3D


def _pair(**settings: object) -> Scenario:
    a = Body("a", Circle((3, 5), 1), (1, 0))
    b = Body("b", Circle((7, 5), 1), (-1, 0))
    return Scenario(Settings(**{"dt": 0.5, "steps": 4, "mode": "exact", **settings}), [a, b], box=Box((0, 0), (10, 10)))


def test_balls_in_a_box_run_event_by_event() -> None:
    world = World(_pair())
    assert world.event_driven and isinstance(world.stepper, EventDrivenStepper)
    record = world.run()
    # The gap 4 - 2 = 2 closes at relative speed 2: contact at t = 1 (the end of step 2), and
    # equal masses swap their velocities (e = 1).
    (event,) = record.events
    assert (event.step, event.bodies) == (2, ("a", "b")) and event.time == pytest.approx(1.0, rel=1e-15)
    assert event.normal.isclose(Vector3D(1, 0, 0), abs_tol=1e-15)
    assert event.point.isclose(Vector3D(5, 5, 0), abs_tol=1e-14)
    assert event.approach_speed == pytest.approx(-2.0, rel=1e-15)
    assert event.impulse == pytest.approx(2.0, rel=1e-15)  # j = -(1 + 1)(-2) / (1 + 1)
    after = event.velocities_after
    assert after["a"].isclose(Vector3D(-1, 0, 0), abs_tol=1e-15) and after["b"].isclose(
        Vector3D(1, 0, 0), abs_tol=1e-15
    )
    # Frames are exact at their times (to rounding: the balls fly in pieces between list updates):
    # at t = 2 each is back where it started.
    assert [f.time for f in record.frames] == [0.0, 0.5, 1.0, 1.5, 2.0]
    a, b = (body.position for body in record.frames[-1].bodies)
    assert a.isclose(Vector3D(3, 5, 0), abs_tol=1e-14) and b.isclose(Vector3D(7, 5, 0), abs_tol=1e-14)
    assert abs(record.ledger.collisions) < 1e-15 and abs(record.ledger.residual) < 1e-15


def test_a_ball_falls_on_the_floor_of_its_box() -> None:
    # A sphere of radius 1 with its centre at y = 3 falls 2 m under g = 2: t = sqrt(2 * 2 / 2) =
    # sqrt 2, v_y = -2 sqrt 2; with e = 0.5 it leaves at +sqrt 2; the collision loses
    # (1 - 0.25) / 2 * 1 kg * 8 = 3 J.
    ball = Body("ball", Sphere((3, 3, 5), 1), (2, 0, 0))
    settings = Settings(dt=0.25, steps=8, restitution=0.5, gravity=(0, -2, 0), mode="exact")
    record = World(Scenario(settings, [ball], box=Box((0, 0, 0), (10, 10, 10)))).run()
    (event,) = record.events
    assert event.bodies == ("wall y-", "ball") and event.static and event.step == 6
    assert event.time == pytest.approx(math.sqrt(2.0), rel=1e-15)
    assert event.normal == Vector3D(0, 1, 0)
    assert event.velocities_after["ball"].y == pytest.approx(math.sqrt(2.0), rel=1e-15)
    assert record.ledger.collisions == pytest.approx(-3.0, rel=1e-14)
    assert record.ledger.collisions_predicted == pytest.approx(-3.0, rel=1e-14)
    assert abs(record.ledger.residual) < 1e-12 and record.ledger.integrator == 0.0  # exact flight
    # At t = 2: the flight after the bounce, y = 1 + sqrt2 s - s^2, s = 2 - sqrt 2.
    s = 2.0 - math.sqrt(2.0)
    assert record.frames[-1].bodies[0].position.y == pytest.approx(1.0 + math.sqrt(2.0) * s - s * s, rel=1e-14)


def test_a_periodic_box_brings_a_ball_back_by_the_opposite_face() -> None:
    ball = Body("ball", Circle((9, 5), 1), (2, 0))
    settings = Settings(dt=1.0, steps=3, mode="exact")
    record = World(Scenario(settings, [ball], box=Box((0, 0), (10, 10), "periodic"))).run()
    xs = [f.bodies[0].position.x for f in record.frames]
    assert xs == pytest.approx([9.0, 1.0, 3.0, 5.0], abs=1e-13) and not record.events  # 11 is 1 in a box of 10


def test_an_elastic_gas_keeps_its_energy_and_momentum() -> None:
    gas = ExactGas(n=500, dim=3, fraction=0.3, boundary="periodic", time=5.0, seed=4)
    world = World(gas.scenario(frames=50))
    e0, p0 = world.energy(), world.momentum()
    world.run(every=50, keep=False)
    assert world.impulses()[0] > 5000  # about 10 collisions per ball
    assert abs(world.energy() / e0 - 1.0) < 1e-12
    assert (world.momentum() - p0).length() < 1e-11  # the start has none (Gaussian, mean removed)
    assert world.deepest_overlap() < 1e-12


def test_events_come_out_as_the_engine_orients_them() -> None:
    # Whatever body's event the loop handles, the pair's first body is the one given first and
    # a wall comes before the ball, its normal pointing at the ball.
    gas = ExactGas(n=60, dim=2, fraction=0.3, boundary="walls", time=5.0, seed=1)
    record = World(gas.scenario(frames=10)).run(every=10)
    names = record.scenario.bodies.names() if record.scenario is not None else []
    walls = 0
    for event in record.events:
        a, b = event.bodies
        if event.static:
            walls += 1
            assert a.startswith("wall ") and b in names
            inward = {"x-": (1, 0), "x+": (-1, 0), "y-": (0, 1), "y+": (0, -1)}[a[5:]]
            assert (event.normal.x, event.normal.y) == inward
        else:
            assert names.index(a) < names.index(b)
        assert event.approach_speed < 0.0
    assert walls > 0 and len(record.events) > walls


def test_overlapping_balls_are_refused_naming_them() -> None:
    a = Body("a", Circle((3, 5), 1), (0, 0))
    b = Body("b", Circle((4, 5), 1), (0, 0))
    scenario = Scenario(Settings(mode="exact"), [a, b], box=Box((0, 0), (10, 10)))
    with pytest.raises(InitialOverlapError, match="'a' and 'b' overlap by 1 m"):
        World(scenario)


def test_a_block_of_many_balls_runs_without_building_bodies() -> None:
    n = 20_000
    rng = np.random.default_rng(0)
    side = 400.0
    grid = np.stack(np.meshgrid(np.arange(141), np.arange(142)), -1).reshape(-1, 2)[:n]
    positions = (grid + 0.5) * (side / 142)
    block = BodyBlock("d", "circle", (0.5, 0.5, 0.5), positions, rng.normal(size=(n, 2)))
    world = World(Scenario(Settings(dt=0.1, steps=10, mode="exact"), [block], box=Box((0, 0), (side, side))))
    world.advance(10)
    assert world.step_index == 10 and world.impulses()[0] > 0
    assert world.nbytes() / n < 500


def test_a_run_is_the_same_to_the_last_bit_however_its_steps_are_split() -> None:
    # The world reads the balls at the end of each call without moving them, so the calls (which
    # the command line sizes by wall time) leave no trace: a sweep's row is the same on any worker.
    gas = ExactGas(n=300, dim=3, fraction=0.3, boundary="walls", time=4.0, seed=9, restitution=0.8)
    whole, split = World(gas.scenario(frames=100)), World(gas.scenario(frames=100))
    whole.step(100)
    for count in (1, 2, 3, 7, 11, 13, 63):
        split.step(count)
    assert split.step_index == whole.step_index == 100
    assert np.array_equal(whole.position_array, split.position_array)
    assert np.array_equal(whole.velocity_array, split.velocity_array)
    assert whole.impulses() == split.impulses() and whole.record.ledger.collisions == split.record.ledger.collisions


@pytest.mark.parametrize("cached", [True, False])
def test_the_event_driven_compile_is_said_only_when_it_happens(monkeypatch: pytest.MonkeyPatch, cached: bool) -> None:
    """The first event-driven run on a machine compiles its loop for about two minutes
    (bench/README.md): the world says so where it was told to, and says nothing once cached."""
    from collisionlab.edmd import compile as edmd_compile

    monkeypatch.setattr(edmd_compile, "is_cached", lambda: cached)
    said: list[str] = []
    World(_pair(), notify=said.append)
    assert said == ([] if cached else ["compiling the event-driven kernels (once per machine; about two minutes)..."])
