"""Resting and sliding on flat supports, in both steppers: no events, no hops, the closed form."""

from __future__ import annotations

import math

import pytest

from collisionlab import AABB, Circle, Line, Plane, Sphere
from collisionlab.model import Body, Obstacle, Scenario, Settings
from collisionlab.tolerances import CONTACT_MARGIN, CONTACT_SLOP
from collisionlab.world import simulate

G = 9.81
DT = 0.01
STEPS = 200


def _incline(dims: int, degrees: float, speed: float) -> tuple[Scenario, tuple[float, float]]:
    """A ball of radius 0.5 placed on a frictionless incline rising to the left at ``degrees``,
    moving down the slope at ``speed``; returns the scenario and the downhill unit vector."""
    a = math.radians(degrees)
    normal = (-math.sin(a), math.cos(a))
    down = (-math.cos(a), -math.sin(a))
    centre = (normal[0] * 0.5, normal[1] * 0.5)
    velocity = (down[0] * speed, down[1] * speed)
    if dims == 2:
        ball = Body("ball", Circle(centre, 0.5), velocity=velocity)
        support = Obstacle("incline", Line((0, 0), (math.cos(a), math.sin(a))))
    else:
        ball = Body("ball", Sphere((*centre, 0.0), 0.5), velocity=(*velocity, 0.0))
        support = Obstacle("incline", Plane((0, 0, 0), (*normal, 0.0)))
    settings = Settings(dt=DT, steps=STEPS, restitution=0.5, gravity=(0, -G, 0), mode="euler")
    return Scenario(settings, (ball,), (support,)), down


@pytest.mark.parametrize("mode", ["euler", "exact"])
@pytest.mark.parametrize("dims", [2, 3])
@pytest.mark.parametrize("degrees", [5.0, 30.0, 60.0])
@pytest.mark.parametrize("speed", [0.0, 2.0])
def test_a_ball_slides_down_an_incline_without_events_or_hops(mode: str, dims: int, degrees: float, speed: float):
    scenario, down = _incline(dims, degrees, speed)
    record = simulate(scenario.with_settings(mode=mode))
    assert record.events == []
    a = math.radians(degrees)
    normal = (-math.sin(a), math.cos(a))
    for frame in record.frames:
        x = frame.bodies[0].position
        gap = x.x * normal[0] + x.y * normal[1] - 0.5
        assert -1e-12 <= gap <= CONTACT_SLOP * 1.01  # on the surface: no hop, no sinking
    x = record.frames[-1].bodies[0].position
    start = scenario.bodies[0].position
    along = (x.x - start.x) * down[0] + (x.y - start.y) * down[1]
    t = STEPS * DT
    accel = G * math.sin(a)  # frictionless: g sin(a) down the slope
    if mode == "exact":
        expected = speed * t + 0.5 * accel * t * t  # 0.5 a t^2 + v0 t
    else:
        # Forward Euler (position first): x_n = v0 n dt + a dt^2 n (n - 1) / 2.
        expected = speed * t + accel * DT * DT * STEPS * (STEPS - 1) / 2.0
    assert along == pytest.approx(expected, rel=1e-9, abs=1e-9)


@pytest.mark.parametrize("mode", ["euler", "exact"])
def test_a_ball_rests_and_slides_on_a_box_face(mode: str) -> None:
    # A unit ball on top of a fixed box (face y = 1), sliding at 1.5 m/s along x: stays on the face.
    ball = Body("ball", Sphere((0, 1.5, 0), 0.5), velocity=(1.5, 0, 0))
    box = Obstacle("table", AABB((-10, 0, -1), (10, 1, 1)))
    settings = Settings(dt=DT, steps=STEPS, restitution=0.8, gravity=(0, -G, 0), mode=mode)
    record = simulate(Scenario(settings, (ball,), (box,)))
    assert record.events == []
    for frame in record.frames:
        assert 1.5 - 1e-12 <= frame.bodies[0].position.y <= 1.5 + CONTACT_SLOP * 1.01
    assert record.frames[-1].bodies[0].position.x == pytest.approx(1.5 * STEPS * DT, rel=1e-12)


@pytest.mark.parametrize("mode", ["euler", "exact"])
def test_a_dropped_ball_bounces_then_comes_to_rest_on_an_incline(mode: str) -> None:
    # Dropped from 1 m above a 20-degree incline with e = 0.5: a few bounces (events), then it
    # rests on the slope and slides; it never sinks below the surface.
    a = math.radians(20.0)
    normal = (-math.sin(a), math.cos(a), 0.0)
    ball = Body("ball", Sphere((normal[0] * 1.5, normal[1] * 1.5, 0), 0.5), velocity=(0, 0, 0))
    settings = Settings(dt=0.001, steps=3000, restitution=0.5, gravity=(0, -G, 0), mode=mode)
    record = simulate(Scenario(settings, (ball,), (Obstacle("incline", Plane((0, 0, 0), normal)),)), every=10)
    assert 1 <= len(record.events) <= 12
    last = max(e.time for e in record.events)
    late = [f for f in record.frames if f.time > last + 0.05]
    assert late, "the ball should come to rest well before the end"
    for frame in record.frames:
        x = frame.bodies[0].position
        assert x.x * normal[0] + x.y * normal[1] - 0.5 >= -2e-3  # euler may dip one step's fall
    gaps = [f.bodies[0].position.x * normal[0] + f.bodies[0].position.y * normal[1] - 0.5 for f in late]
    # At rest on the surface: within the contact margin (euler: the push-apart's slop), no hops.
    assert max(gaps) <= (CONTACT_SLOP * 1.01 if mode == "euler" else CONTACT_MARGIN)
    assert max(gaps) - min(gaps) <= 1e-12
