"""The stateful world: the step order, events once per impact, exact mode never tunnels,
resting contact, and the conservation ledger (issues 3 and 4)."""

from __future__ import annotations

import itertools
import math
import os

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collisionlab import AABB, Circle, Line, Plane, Sphere, Vector3D
from collisionlab.model import Body, Obstacle, Scenario, Settings
from collisionlab.tolerances import CONTACT_MARGIN, CONTACT_SLOP, REST_SPEED
from collisionlab.world import InitialOverlapError, World, simulate

FLOOR = Obstacle("floor", Plane((0, 0, 0), (0, 1, 0)))


def _scenario(bodies, obstacles=(), **kw) -> Scenario:
    return Scenario(Settings(**kw), tuple(bodies), tuple(obstacles))


def test_bodies_that_start_overlapping_are_refused_naming_both_and_the_depth():
    # Centres 0.8 apart, radii 0.5 + 0.5: 0.2 m deep.
    a = Body("a", Sphere((0, 0, 0), 0.5), velocity=(0, 0, 0))
    b = Body("b", Sphere((0.8, 0, 0), 0.5), velocity=(0, 0, 0))
    with pytest.raises(InitialOverlapError, match=r"'a' and 'b' overlap by 0.2 m"):
        World(_scenario([a, b], dt=0.01, steps=5))
    # A ball 0.25 into a floor: the obstacle is named first.
    ball = Body("ball", Sphere((0, 0.25, 0), 0.5), velocity=(0, 0, 0))
    with pytest.raises(InitialOverlapError, match=r"'floor' and 'ball' overlap by 0.25 m"):
        World(_scenario([ball], [FLOOR], dt=0.01, steps=5))
    # Exactly touching is not overlapping.
    touching = Body("ball", Sphere((0, 0.5, 0), 0.5), velocity=(0, 0, 0))
    World(_scenario([touching], [FLOOR], dt=0.01, steps=5))


# --- euler mode (the lab's) -------------------------------------------------------------------
def test_euler_sphere_plane_golden():
    # y_k = 3.01 - 0.02 k <= 0.5 first at k = 126 (125.5 rounds up); lab eq. 24 with n = (0, 1, 0),
    # e = 0.8: v_y = -2 - 1.8 * (-2) = 1.6, tangential (1, _, 0.5) unchanged.
    ball = Body("ball", Sphere((0, 3.01, 0), 0.5), velocity=(1, -2, 0.5))
    record = simulate(_scenario([ball], [FLOOR], dt=0.01, steps=200, restitution=0.8))
    assert [e.step for e in record.events] == [126]
    after = record.events[0].velocities_after["ball"]
    assert after.as_tuple() == pytest.approx((1.0, 1.6, 0.5), abs=1e-12)
    # Pushed out: after the step, the sphere sits on the plane (gap CONTACT_SLOP), not inside it.
    frame = record.frames[126]
    assert frame.bodies[0].position.y - 0.5 == pytest.approx(CONTACT_SLOP, abs=1e-12)


def test_euler_reports_each_impact_once_even_when_e_is_zero():
    # e = 0: the pair moves on together, touching; that is one impact, not one per step.
    a = Body("a", Circle((0, 0), 0.5), velocity=(1, 0))
    b = Body("b", Circle((3, 0), 0.5), velocity=(-1, 0))
    record = simulate(_scenario([a, b], dt=0.01, steps=300, restitution=0.0))
    assert len(record.events) == 1
    va = record.frames[-1].bodies[0].velocity
    assert va.as_tuple() == pytest.approx((0.0, 0.0, 0.0), abs=1e-12)


def test_euler_integrator_energy_gain_matches_forward_euler_theory():
    # Forward Euler under gravity gains g^2 dt t / 2 per unit mass (x from the old velocity):
    # 9.81^2 * 0.01 * 1.0 / 2 = 0.4811805 J for m = 1 over 100 steps.
    ball = Body("ball", Sphere((0, 100, 0), 0.5), velocity=(0, 0, 0))
    record = simulate(_scenario([ball], dt=0.01, steps=100, gravity=(0, -9.81, 0)))
    assert record.ledger.integrator == pytest.approx(9.81**2 * 0.01 * 1.0 / 2, rel=1e-9)
    assert record.ledger.residual == pytest.approx(0.0, abs=1e-9)


def test_euler_warns_once_about_tunnelling_through_a_fixed_box():
    # 100 m/s * 0.01 s = 1 m per step against a ball 0.2 m across and a box 0.1 m thick: it
    # jumps over it, and the lab's discrete check misses it: the reason for exact mode.
    ball = Body("ball", Sphere((0, 0.55, 0), 0.1), velocity=(0, -100, 0))
    slab = Obstacle("slab", AABB((-1, -0.1, -1), (1, 0, 1)))
    record = simulate(_scenario([ball], [slab], dt=0.01, steps=5))
    tunnel = [w for w in record.warnings if "tunnelling" in w]
    assert len(tunnel) == 1 and "--mode exact" in tunnel[0]
    assert record.events == []
    assert record.frames[-1].bodies[0].position.y < -0.1


def test_euler_never_lets_a_ball_through_a_plane_and_does_not_warn():
    # The same ball at a plane: its centre crosses it within the step, and it is put back on its
    # side, where the step's contact bounces it (issue 27); nothing can tunnel, so no warning.
    ball = Body("ball", Sphere((0, 0.55, 0), 0.1), velocity=(0, -100, 0))
    record = simulate(_scenario([ball], [FLOOR], dt=0.01, steps=5))
    assert not [w for w in record.warnings if "tunnelling" in w]
    assert len(record.events) == 1 and record.events[0].step == 1
    assert all(frame.bodies[0].position.y >= 0.1 for frame in record.frames[1:])


# --- exact mode: nothing tunnels --------------------------------------------------------------
SPEEDS = [1.0, 1e2, 1e4, 1e6]  # radius lengths per step


@pytest.mark.parametrize("speed", SPEEDS)
@pytest.mark.parametrize("target", ["plane", "line", "box", "sphere"])
def test_exact_mode_never_tunnels(target, speed):
    # A body of radius 1 moving `speed` radii per step (dt = 1) toward a target 10 away.
    if target == "line":
        body = Body("b", Circle((0, 10), 1), velocity=(0, -speed))
        obstacles = [Obstacle("t", Line((0, 0), (1, 0)))]
    elif target == "plane":
        body = Body("b", Sphere((0, 10, 0), 1), velocity=(0, -speed, 0))
        obstacles = [Obstacle("t", Plane((0, 0, 0), (0, 1, 0)))]
    elif target == "box":
        body = Body("b", Sphere((0, 10, 0), 1), velocity=(0, -speed, 0))
        obstacles = [Obstacle("t", AABB((-1, -0.01, -1), (1, 0, 1)))]  # 1 cm thin
    else:
        body = Body("b", Sphere((0, 10, 0), 1), velocity=(0, -speed, 0))
        obstacles = []
    bodies = [body]
    if target == "sphere":
        bodies.append(Body("t", Sphere((0, 0, 0), 0.01), velocity=(0, 0, 0), mass=1e12))
    steps = max(3, math.ceil(12 / speed))
    record = simulate(_scenario(bodies, obstacles, dt=1.0, steps=steps, restitution=1.0, mode="exact"))
    assert len(record.events) == 1
    for frame in record.frames:
        assert frame.bodies[0].position.y >= 0.0, "the body was found beyond its target"


def test_exact_rebound_is_the_same_wherever_the_impact_falls_in_the_step():
    # 200 start heights put the impact at 200 places inside step 1; the velocity after is
    # always lab eq. 24's (0, +0.5 * 3) and the height after the step is exact too.
    results = set()
    for k in range(200):
        y0 = 0.5 + 3.0 * (k + 0.5) / 200  # impact time (y0 - 0.5)/3 inside (0, 1)
        ball = Body("ball", Sphere((0, y0, 0), 0.5), velocity=(0, -3, 0))
        record = simulate(_scenario([ball], [FLOOR], dt=1.0, steps=1, restitution=0.5, mode="exact"))
        (event,) = record.events
        assert event.time == pytest.approx((y0 - 0.5) / 3.0, abs=1e-12)
        results.add(record.frames[-1].bodies[0].velocity.as_tuple())
        # after impact at t_i it rises at 1.5 for 1 - t_i
        assert record.frames[-1].bodies[0].position.y == pytest.approx(0.5 + 1.5 * (1 - event.time), abs=1e-9)
    assert results == {(0.0, 1.5, 0.0)}


def test_exact_elastic_bounces_keep_energy_over_ten_thousand_collisions():
    # Ball between two planes 1 m apart at 1000 m/s, dt = 0.01: 10 m a step, ~13 collisions a step.
    ball = Body("ball", Sphere((0, 0.5, 0), 0.1), velocity=(0, 1000, 0))
    walls = [Obstacle("floor", Plane((0, 0, 0), (0, 1, 0))), Obstacle("ceiling", Plane((0, 1, 0), (0, -1, 0)))]
    scenario = _scenario([ball], walls, dt=0.01, steps=800, restitution=1.0, mode="exact")
    world = World(scenario)
    record = world.run(every=100)
    assert len(record.events) >= 10_000
    assert abs(record.ledger.kinetic_end / record.ledger.kinetic_start - 1.0) < 1e-9
    assert all(0.1 - 1e-9 <= f.bodies[0].position.y <= 0.9 + 1e-9 for f in record.frames)


def test_exact_balls_in_a_box_keep_energy():
    walls = [
        Obstacle("left", Line((-3, 0), (0, 1))),
        Obstacle("right", Line((3, 0), (0, 1))),
        Obstacle("bottom", Line((0, -3), (1, 0))),
        Obstacle("top", Line((0, 3), (1, 0))),
    ]
    balls = [
        Body("a", Circle((-1.5, 0.2), 0.5), velocity=(7, 3), mass=1.0),
        Body("b", Circle((1.0, -0.3), 0.4), velocity=(-5, 4), mass=2.0),
        Body("c", Circle((0.0, 1.8), 0.3), velocity=(2, -9), mass=0.5),
    ]
    record = simulate(_scenario(balls, walls, dt=0.01, steps=1000, restitution=1.0, mode="exact"))
    assert len(record.events) > 50
    assert abs(record.ledger.kinetic_end / record.ledger.kinetic_start - 1.0) < 1e-9
    for frame in record.frames:
        for state, body in zip(frame.bodies, balls, strict=True):
            r = body.shape.radius
            assert -3 + r - 1e-9 <= state.position.x <= 3 - r + 1e-9
            assert -3 + r - 1e-9 <= state.position.y <= 3 - r + 1e-9


@settings(max_examples=40, deadline=None)
@given(
    m_a=st.floats(0.1, 100),
    m_b=st.floats(0.1, 100),
    vx=st.floats(0.5, 50),
    offset=st.floats(-0.9, 0.9),
    e=st.floats(0, 1),
    mode=st.sampled_from(["euler", "exact"]),
)
def test_free_two_body_collisions_conserve_momentum(m_a, m_b, vx, offset, e, mode):
    a = Body("a", Sphere((0, 0, 0), 0.5), velocity=(vx, 0, 0), mass=m_a)
    b = Body("b", Sphere((3, offset, 0.1), 0.5), velocity=(-1, 0, 0), mass=m_b)
    dt = 0.001 if mode == "euler" else 0.01
    record = simulate(_scenario([a, b], dt=dt, steps=round(4 / dt / (vx + 1)) + 50, restitution=e, mode=mode))
    assert len(record.events) == 1
    p0, p1 = record.ledger.momentum_start, record.ledger.momentum_end
    # Rounding is relative to the momenta exchanged, not to their sum (which can cancel to
    # ~1e-4 of them, e.g. m_a = 0.99999 at 32 m/s against m_b = 32 at -1 m/s).
    scale = m_a * abs(vx) + m_b * 1.0
    assert (p1 - p0).length() <= 1e-12 * scale
    # the ledger attributes the energy change to the collision, as theory predicts
    scale = record.ledger.kinetic_start  # rounding of a difference of energies is relative to them
    assert record.ledger.collisions == pytest.approx(record.ledger.collisions_predicted, rel=1e-9, abs=1e-14 * scale)


def test_exact_grazing_impact_is_one_event():
    # Moving along x at y = 1 with radii summing to 1: the spheres touch at exactly one instant.
    a = Body("a", Sphere((0, 0, 0), 0.5), velocity=(1, 0, 0))
    b = Body("b", Sphere((3, 1, 0), 0.5), velocity=(0, 0, 0))
    record = simulate(_scenario([a, b], dt=0.01, steps=500, mode="exact"))
    assert len(record.events) <= 1
    # a graze has no approach along the normal, so at most one (zero-impulse) contact is seen
    for event in record.events:
        assert abs(event.approach_speed) < 1e-6


def test_exact_e_zero_is_one_event():
    a = Body("a", Sphere((0, 0, 0), 0.5), velocity=(1, 0, 0))
    b = Body("b", Sphere((3, 0, 0), 0.5), velocity=(-1, 0, 0))
    record = simulate(_scenario([a, b], dt=0.01, steps=300, restitution=0.0, mode="exact"))
    assert len(record.events) == 1
    assert record.events[0].time == pytest.approx(1.0, abs=1e-12)  # gap 2 closing at 2


# --- exact mode under gravity: bounces follow e^2, then rest -----------------------------------
def test_exact_bounce_heights_follow_e_squared_then_rest():
    g, e, r, h0 = 9.81, 0.8, 0.25, 2.0
    ball = Body("ball", Sphere((0, h0, 0), r), velocity=(0, 0, 0))
    scenario = _scenario([ball], [FLOOR], dt=0.01, steps=800, restitution=e, gravity=(0, -g, 0), mode="exact")
    record = World(scenario).run()
    ups = [ev.velocities_after["ball"].y for ev in record.events]
    # first impact: dropped from h0 - r = 1.75 m: v = sqrt(2 g 1.75) at t = sqrt(2 * 1.75 / g)
    assert record.events[0].time == pytest.approx(math.sqrt(2 * (h0 - r) / g), rel=1e-12)
    assert ups[0] == pytest.approx(e * math.sqrt(2 * g * (h0 - r)), rel=1e-12)
    heights = [u * u / (2 * g) for u in ups if u > REST_SPEED]
    for first, second in itertools.pairwise(heights):
        assert second / first == pytest.approx(e * e, rel=1e-9)
    # time between bounces is the flight time 2u/g of the parabola: exact, not stepped
    for ev1, ev2 in zip(record.events[:5], record.events[1:6], strict=False):
        assert ev2.time - ev1.time == pytest.approx(2 * ev1.velocities_after["ball"].y / g, rel=1e-9)
    # at rest on the floor at the end: no sinking, no jitter
    final = record.frames[-1].bodies[0]
    assert abs(final.velocity.y) <= REST_SPEED
    assert 0.0 <= final.position.y - r <= CONTACT_MARGIN
    resting_heights = [f.bodies[0].position.y for f in record.frames[-100:]]
    assert max(resting_heights) - min(resting_heights) <= CONTACT_SLOP
    # penetration never exceeds CONTACT_SLOP at any recorded frame
    assert min(f.bodies[0].position.y - r for f in record.frames) >= -CONTACT_SLOP


def test_exact_ledger_explains_the_energy():
    ball = Body("ball", Sphere((0, 2, 0), 0.25), velocity=(0.5, 0, 0))
    scenario = _scenario([ball], [FLOOR], dt=0.01, steps=300, restitution=0.8, gravity=(0, -9.81, 0), mode="exact")
    ledger = simulate(scenario).ledger
    assert ledger.collisions < 0
    assert ledger.collisions == pytest.approx(ledger.collisions_predicted, rel=1e-6)
    assert abs(ledger.integrator) < 1e-9  # exact parabola: no integrator energy
    assert abs(ledger.residual) < 1e-9


def test_world_rejects_a_pair_with_no_query():
    with pytest.raises(ValueError, match="cannot collide"):
        _scenario([Body("c", Circle((0, 0), 1), velocity=(0, 0))], [FLOOR])


def test_restitution_above_one_warns_and_adds_energy():
    ball = Body("ball", Sphere((0, 1.01, 0), 0.5), velocity=(0, -1, 0))
    record = simulate(_scenario([ball], [FLOOR], dt=0.01, steps=100, restitution=1.5))
    assert any("adds kinetic energy" in w for w in record.warnings)
    assert record.ledger.kinetic_end == pytest.approx(record.ledger.kinetic_start * 1.5**2)


def test_momentum_and_frames_shape():
    a = Body("a", Circle((0, 0), 0.5), velocity=(1, 0))
    record = World(_scenario([a], dt=0.1, steps=10)).run(every=3)
    assert [f.step for f in record.frames] == [0, 3, 6, 9, 10]
    assert record.frames[-1].bodies[0].position == Vector3D(1.0, 0.0, 0.0) or record.frames[-1].bodies[
        0
    ].position.x == pytest.approx(1.0)


def test_euler_grazing_impact_is_at_most_one_event():
    # Centres pass at y offset 1.0 = r_a + r_b: at the closest step they touch (distance 0 at
    # x-offset 0). A touch with no approach along the normal gets no impulse; never two events.
    a = Body("a", Sphere((0, 0, 0), 0.5), velocity=(1, 0, 0))
    b = Body("b", Sphere((3, 1, 0), 0.5), velocity=(0, 0, 0))
    record = simulate(_scenario([a, b], dt=0.01, steps=600))
    assert len(record.events) <= 1
    assert record.ledger.kinetic_end == pytest.approx(record.ledger.kinetic_start, rel=1e-12)


def test_a_separating_overlap_is_skipped_and_said_why():
    # Placed overlapping but moving apart: pushed apart, no impulse, and the skip is recorded
    # with its reason for --explain.
    a = Body("a", Sphere((0, 0, 0), 0.5), velocity=(-1, 0, 0))
    b = Body("b", Sphere((0.8, 0, 0), 0.5), velocity=(1, 0, 0))
    scenario = Scenario(Settings(dt=0.01, steps=5), (a, b), allow_initial_overlap=True)
    record = simulate(scenario)
    assert record.events == []
    # 0.5 + 0.5 - 0.8 = 0.2 m deep at the start: reported, not silently teleported.
    assert any("overlapped at the start" in w and "0.2 m" in w for w in record.warnings)
    assert [(s.step, s.bodies, s.reason) for s in record.skipped] == [(1, ("a", "b"), "separating")]
    from collisionlab.cli.render import render_table

    assert "contact a / b at step 1 (t = 0.010 s) skipped: separating" in render_table(record, explain=True)


def test_exact_stack_of_two_balls_settles_without_sinking():
    # The upper ball falls 0.5 m onto a ball resting on the floor, bounces with e = 0.5 and
    # comes to rest on it: the floor takes the push through the lower ball (it cannot be pushed
    # into its support), nothing sinks, and the energy lost is m g h = 1 * 9.81 * 0.5.
    lower = Body("lower", Sphere((0, 0.5, 0), 0.5), velocity=(0, 0, 0))
    upper = Body("upper", Sphere((0, 2.0, 0), 0.5), velocity=(0, 0, 0))
    scenario = _scenario(
        [lower, upper], [FLOOR], dt=0.01, steps=300, restitution=0.5, gravity=(0, -9.81, 0), mode="exact"
    )
    record = simulate(scenario)
    assert all(e.bodies == ("lower", "upper") for e in record.events)  # the lower ball never leaves the floor
    assert len(record.events) < 30
    final = {b.name: b for b in record.frames[-1].bodies}
    assert final["lower"].position.y == pytest.approx(0.5, abs=CONTACT_SLOP)
    assert final["upper"].position.y == pytest.approx(1.5, abs=CONTACT_MARGIN)
    assert final["upper"].velocity.length() <= REST_SPEED
    for frame in record.frames:
        lo, up = (b.position.y for b in frame.bodies)
        assert lo >= 0.5 - CONTACT_SLOP and up - lo >= 1.0 - CONTACT_SLOP
    assert record.ledger.energy_end - record.ledger.energy_start == pytest.approx(-9.81 * 0.5, rel=1e-9)
    assert abs(record.ledger.push_apart) < 1e-9


@settings(max_examples=int(os.environ.get("COLLISIONLAB_EXAMPLES", "25")), deadline=None)
@given(
    count=st.integers(2, 6),
    seed=st.integers(0, 10_000),
    e=st.sampled_from([0.0, 0.5, 1.0]),
)
def test_exact_discs_in_a_box_never_overlap_or_escape(count, seed, e):
    # Random discs (no two overlapping at the start) in a box of four lines: exact mode finds
    # every impact, so push-apart never has more than rounding to undo and nothing leaves.
    import random

    rng = random.Random(seed)
    walls = [
        Obstacle("left", Line((-5, 0), (0, 1))),
        Obstacle("right", Line((5, 0), (0, 1))),
        Obstacle("bottom", Line((0, -5), (1, 0))),
        Obstacle("top", Line((0, 5), (1, 0))),
    ]
    slots = rng.sample([(x, y) for x in (-3, -1, 1, 3) for y in (-3, -1, 1, 3)], count)
    bodies = [
        Body(
            f"d{i}",
            Circle(slot, rng.uniform(0.2, 0.9)),
            velocity=(rng.uniform(-20, 20), rng.uniform(-20, 20)),
            mass=rng.uniform(0.5, 3),
        )
        for i, slot in enumerate(slots)
    ]
    record = simulate(_scenario(bodies, walls, dt=0.02, steps=60, restitution=e, mode="exact"))
    assert record.ledger.max_penetration <= 1e-9
    for frame in record.frames:
        for state, body in zip(frame.bodies, bodies, strict=True):
            r = body.shape.radius
            assert abs(state.position.x) <= 5 - r + 1e-9 and abs(state.position.y) <= 5 - r + 1e-9
    if e == 1.0:
        assert record.ledger.kinetic_end == pytest.approx(record.ledger.kinetic_start, rel=1e-9)


def test_exact_ball_slides_off_a_moving_crate_smoothly():
    # A ball dropped onto a crate that slides (no friction) at 0.3 m/s: it bounces to rest on the
    # crate's top, rides it until the crate's edge passes under it, slides over the edge (a curved
    # support of radius 0.4) and falls to the floor. No friction and a floor that pushes only
    # along y: horizontal momentum is conserved, the contact forces do no work (integrator ~ 0), and
    # the slide over the edge is a few contacts, not a run of tiny hops.
    crate = Body("crate", AABB.from_center_size((0, 2, 0), (1, 1, 1)), velocity=(0.3, 0, 0))
    ball = Body("ball", Sphere((0.2, 4, 0), 0.4), velocity=(0, 0, 0))
    scenario = _scenario([crate, ball], [FLOOR], dt=0.01, steps=400, restitution=0.5, gravity=(0, -9.81, 0),
                         mode="exact")  # fmt: skip
    record = simulate(scenario)
    assert record.ledger.momentum_end.x == pytest.approx(0.3, abs=1e-12)
    assert abs(record.ledger.integrator) < 1e-9
    assert record.ledger.max_penetration <= CONTACT_SLOP
    slide = [e for e in record.events if e.bodies == ("crate", "ball") and e.time > 2.0]
    assert len(slide) < 10
    final = {b.name: b for b in record.frames[-1].bodies}
    assert final["ball"].position.y == pytest.approx(0.4, abs=CONTACT_MARGIN)
    assert abs(final["ball"].velocity.y) <= REST_SPEED
    assert final["ball"].velocity.x < 0 < final["crate"].velocity.x  # pushed apart by the slide
