"""The event-driven stepper on the engine's world: balls in a box, run event by event, with the
world's frames, events and ledger (values worked by hand or from closed forms)."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from collisionlab.body_block import BodyBlock
from collisionlab.edmd.observables import ExactGas
from collisionlab.engine.event_stepper import EventDrivenStepper
from collisionlab.engine.world import InitialOverlapError, World
from collisionlab.model import Body, Box, Scenario, Settings
from collisionlab.scenario_file import parse_scenario
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
    """The first event-driven run on a machine compiles its loop for up to a minute
    (bench/README.md): the world says so where it was told to, and says nothing once cached."""
    from collisionlab.edmd import compile as edmd_compile

    monkeypatch.setattr(edmd_compile, "is_cached", lambda: cached)
    said: list[str] = []
    World(_pair(), notify=said.append)
    notice = "compiling the event-driven kernels (once per machine; up to a minute)..."
    assert said == ([] if cached else [notice])


# --- mixtures: several [[gas]] tables in a box ----------------------------------------------------
#: Two tables of discs, big (radius 1, mass 1) in the lower half and small (radius 0.5, mass 0.25)
#: in the upper half of a 20 m box: each table placed on its own lattice, in its own region.
MIXTURE = """
[simulation]
dt = 0.1
steps = 40
mode = "exact"
restitution = {e}
[box]
region = [[0, 0], [20, 20]]
boundary = "{boundary}"
[[gas]]
name = "big"
shape = "circle"
radius = 1.0
region = [[0, 0], [20, 10]]
count = 20
kT = 1.0
seed = 1
[[gas]]
name = "small"
shape = "circle"
radius = {small}
mass = {mass}
region = [[0, 10], [20, 20]]
count = {count}
kT = 1.0
seed = 2
"""
#: Each table's mass, by the prefix of its bodies' names.
_MASSES = {"big": 1.0, "small": 0.25}


def _mixture(
    boundary: str = "periodic", e: float = 1.0, small: float = 0.5, mass: float = 0.25, count: int = 40
) -> Scenario:
    text = MIXTURE.format(boundary=boundary, e=e, small=small, mass=mass, count=count)
    return parse_scenario(tomllib.loads(text))


def _mass_of(name: str) -> float:
    return _MASSES[name.rstrip("0123456789")]


def _energy_and_momentum(frame: object) -> tuple[float, np.ndarray]:
    """The kinetic energy and momentum of a frame's bodies, each with its table's mass."""
    energy, momentum = 0.0, np.zeros(3)
    for body in frame.bodies:  # type: ignore[attr-defined]
        m, v = _mass_of(body.name), np.array(body.velocity.as_tuple())
        energy += 0.5 * m * float(v @ v)
        momentum += m * v
    return energy, momentum


@pytest.mark.parametrize("boundary", ["periodic", "walls"])
def test_two_gas_tables_of_two_radii_and_masses_run_event_by_event(boundary: str) -> None:
    scenario = _mixture(boundary)
    assert scenario.event_driven
    world = World(scenario)
    assert isinstance(world.stepper, EventDrivenStepper)
    balls = world.stepper.world
    names = scenario.bodies.names()
    # Each ball its table's radius and mass, in the order given.
    assert balls.mixed and balls.radii.tolist() == [1.0 if n.startswith("big") else 0.5 for n in names]
    assert balls.masses.tolist() == [_mass_of(n) for n in names]
    record = world.run(every=10)
    kinds = {tuple(sorted(name.rstrip("0123456789") for name in event.bodies)) for event in record.events}
    assert ("big", "small") in kinds and ("small", "small") in kinds
    for event in (e for e in record.events if not e.static):
        # Each collision: the pair's momentum kept with the tables' masses, its kinetic energy
        # too (e = 1), and the impulse along the normal: j / m_a and j / m_b.
        a, b = event.bodies
        ma, mb = _mass_of(a), _mass_of(b)
        assert event.masses == (ma, mb)
        before = {k: np.array(v.as_tuple()) for k, v in event.velocities_before.items()}
        after = {k: np.array(v.as_tuple()) for k, v in event.velocities_after.items()}
        assert np.allclose(ma * before[a] + mb * before[b], ma * after[a] + mb * after[b], rtol=0, atol=1e-12)
        energy = 0.5 * ma * before[a] @ before[a] + 0.5 * mb * before[b] @ before[b]
        assert 0.5 * ma * after[a] @ after[a] + 0.5 * mb * after[b] @ after[b] == pytest.approx(energy, rel=1e-12)
        n = np.array(event.normal.as_tuple())
        j = -2.0 * float((before[b] - before[a]) @ n) / (1.0 / ma + 1.0 / mb)
        assert np.allclose(after[a], before[a] - j / ma * n, atol=1e-12)


def test_an_elastic_mixture_keeps_its_energy_and_in_a_periodic_box_its_momentum() -> None:
    record = World(_mixture("periodic").with_settings(steps=100)).run(every=100)
    assert record.collision_total > 200
    e0, p0 = _energy_and_momentum(record.frames[0])
    e1, p1 = _energy_and_momentum(record.frames[-1])
    assert abs(e1 / e0 - 1.0) < 1e-9
    assert np.linalg.norm(p1 - p0) < 1e-9 * float(np.linalg.norm(p0))
    assert record.summary()["kinetic_energy_end"] == pytest.approx(e1, rel=1e-12)
    # Each kind's kT is its kinetic energy averaged over the run: with e = 1 the kinds' sum,
    # sum of N d kT / 2, is the kinetic energy itself, whatever passed between them.
    species = record.species or []
    assert [(s["name"], s["count"], s["radius"], s["mass"]) for s in species] == [
        ("big", 20, 1.0, 1.0),
        ("small", 40, 0.5, 0.25),
    ]
    assert sum(s["count"] * s["kT"] for s in species) == pytest.approx(e0, rel=1e-9)  # d / 2 = 1 in 2D


def test_an_inelastic_mixture_under_gravity_loses_what_theory_says() -> None:
    # e = 0.8 with g = 9.81 in a box of walls: every collision loses (1 - e^2) / 2 mu v_n^2, mu the
    # pair's reduced mass (a wall's: the ball's mass), worked here from each event's own numbers.
    scenario = _mixture("walls", e=0.8).with_settings(gravity=(0, -9.81, 0), steps=20, tc=1e-4)
    record = World(scenario).run(every=20)
    assert record.collision_total > 50
    theory = 0.0
    for event in record.events:
        a, b = event.bodies
        mu = _mass_of(b) if event.static else 1.0 / (1.0 / _mass_of(a) + 1.0 / _mass_of(b))
        theory -= (1.0 - event.restitution**2) / 2.0 * mu * event.approach_speed**2
    ledger = record.ledger
    assert ledger.collisions == pytest.approx(theory, rel=1e-9)
    assert abs(ledger.residual) < 1e-9 * abs(ledger.energy_start)


def test_two_tables_of_equal_balls_run_as_one_table_to_the_last_bit() -> None:
    # Counted by table, the balls fly and collide exactly as when they are one table: the
    # kinds only count.
    two = _mixture("periodic", small=1.0, mass=1.0, count=30)
    first, second = two.bodies.blocks
    one = BodyBlock(
        "g", "circle", (1.0, 1.0, 1.0), np.concatenate([first.positions, second.positions]),
        np.concatenate([first.velocities, second.velocities]),
    )  # fmt: skip
    together = Scenario(two.settings, [one], box=two.box)
    apart_world, together_world = World(two), World(together)
    assert apart_world.stepper.species and not together_world.stepper.species  # type: ignore[union-attr]
    apart, joined = apart_world.run(every=40), together_world.run(every=40)
    assert np.array_equal(apart_world.position_array, together_world.position_array)
    assert np.array_equal(apart_world.velocity_array, together_world.velocity_array)
    assert apart.collision_total == joined.collision_total > 0 and joined.species is None
    assert [s["count"] for s in apart.species or []] == [20, 30]
