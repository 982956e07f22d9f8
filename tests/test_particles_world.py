"""ParticleWorld: the scalar core's law, conservation, order independence, walls, robustness."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from collisionlab.errors import InvalidInputError
from collisionlab.particles import ParticleWorld, StepReport, gas_scenario
from collisionlab.resolution import reflect_velocity, resolve_collision, separate
from collisionlab.tolerances import CONTACT_SLOP
from collisionlab.vector import Vector3D

BACKENDS = ["python", "numba"]  # the same kernels, uncompiled and compiled
FAST = BACKENDS[-1]  # numba when installed: long runs use it


# --- golden values, worked by hand ---------------------------------------------------------------
@pytest.mark.parametrize("backend", BACKENDS)
def test_unequal_masses_head_on(backend: str) -> None:
    # m_a = 1 at x = 0 moving +2, m_b = 3 at x = 2.1 at rest, radii 1, dt = 0.1, e = 1.
    # After x += v dt: a at 0.2, b at 2.1, distance 1.9, depth 0.1, n = (1, 0).
    # v_n = (0 - 2) = -2; j = -(1 + 1)(-2) / (1/1 + 1/3) = 4 / (4/3) = 3;
    # v_a = 2 - 3/1 = -1, v_b = 0 + 3/3 = 1 (momentum 2 = -1 + 3, energy 2 = 1/2 + 3/2).
    # Push-apart by 0.1 + slop: a moves 3/4 of it, b 1/4: a = 0.2 - 0.075, b = 2.1 + 0.025.
    world = ParticleWorld([[0, 0], [2.1, 0]], [[2, 0], [0, 0]], 1.0, [1.0, 3.0], backend=backend)
    report = world.step(0.1)
    assert report == StepReport(steps=1, body_collisions=1, wall_collisions=0)
    np.testing.assert_allclose(world.velocities, [[-1, 0], [1, 0]], rtol=0, atol=1e-15)
    shift = 0.1 + CONTACT_SLOP
    np.testing.assert_allclose(world.positions, [[0.2 - 0.75 * shift, 0], [2.1 + 0.25 * shift, 0]], atol=1e-14)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize(("e", "vx_after"), [(1.0, 1.0), (0.5, 0.5), (0.0, 0.0)])
def test_wall_bounce_lab_eq_24(backend: str, e: float, vx_after: float) -> None:
    # Radius 1 at x = 1.05 moving -1 towards the wall x = 0; dt = 0.1 puts it at 0.95 (depth
    # 0.05): v_x = -1 - (1 + e)(-1) = e; it is put back at x = 1 + slop; v_y = 3 is untouched.
    world = ParticleWorld([[1.05, 5.0]], [[-1.0, 3.0]], box=((0, 0), (10, 10)), restitution=e, backend=backend)
    assert world.step(0.1).wall_collisions == 1
    np.testing.assert_allclose(world.velocities, [[vx_after, 3.0]], atol=1e-15)
    np.testing.assert_allclose(world.positions, [[1.0 + CONTACT_SLOP, 5.3]], atol=1e-14)


@pytest.mark.parametrize("backend", BACKENDS)
def test_static_body_reflects_like_a_wall_and_ignores_gravity(backend: str) -> None:
    # A static ball (mass inf) at the origin; a unit ball falls on it straight down at speed 2.
    # It reflects (e = 1) and the static one neither moves nor falls.
    world = ParticleWorld(
        [[0, 0, 0], [0, 0, 2.1]], [[0, 0, 0], [0, 0, -2]], 1.0, [math.inf, 1.0], gravity=(0, 0, -10), backend=backend
    )
    world.step(0.1)  # z = 2.1 - 0.2 = 1.9: touching with depth 0.1, v_z = -2 - 1 = -3 -> +3
    np.testing.assert_allclose(world.velocities, [[0, 0, 0], [0, 0, 3]], atol=1e-14)
    assert world.positions[0].tolist() == [0.0, 0.0, 0.0]
    assert world.masses[0] == math.inf


@pytest.mark.parametrize("backend", BACKENDS)
def test_tilted_plane(backend: str) -> None:
    # Wall x + y >= 0 (normal (1, 1)/sqrt 2); a ball coming in along -x is reflected by eq. 24.
    world = ParticleWorld([[1.0, 0.5]], [[-3.0, 0.0]], 1.0, planes=[((1.0, 1.0), 0.0)], backend=backend)
    world.step(0.1)
    expected = reflect_velocity((-3.0, 0.0), (1.0, 1.0), 1.0)
    np.testing.assert_allclose(world.velocities[0], [expected.x, expected.y], atol=1e-14)
    normal = np.array([1.0, 1.0]) / math.sqrt(2)
    assert float(world.positions[0] @ normal) > 1.0


# --- the scalar core, pair by pair -----------------------------------------------------------------
def _vec(row: np.ndarray) -> Vector3D:
    return Vector3D(*(float(x) for x in row))


def reference_step(
    pos: np.ndarray,
    vel: np.ndarray,
    rad: np.ndarray,
    mass: np.ndarray,
    lo: float,
    hi: float,
    dt: float,
    e: float,
    g: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, int]:
    """One step with collisionlab.resolution, in plain Python: Euler, detect, resolve, push apart.
    Each body has at most one contact (asserted), so the order of contacts does not matter."""
    dim = pos.shape[1]
    p = [_vec(r) for r in pos]
    v = [_vec(r) for r in vel]
    p = [p[i] + v[i] * dt for i in range(len(p))]
    v = [v[i] + _vec(g) * dt if mass[i] < math.inf else v[i] for i in range(len(v))]  # static: no gravity
    pairs = [(i, j) for i in range(len(p)) for j in range(i + 1, len(p)) if (p[j] - p[i]).length() <= rad[i] + rad[j]]
    walls = []
    for i in range(len(p)):
        for k in range(dim):
            for normal, offset in ((1.0, lo), (-1.0, -hi)):
                n = _vec(np.eye(dim)[k] * normal)
                if p[i].dot(n) - offset <= rad[i]:
                    walls.append((i, n, offset))
    touched = [i for pair in pairs for i in pair] + [w[0] for w in walls]
    assert len(touched) == len(set(touched)), "the scene must give each body one contact at most"
    for i, j in pairs:
        normal = (p[j] - p[i]).normalized()
        v[i], v[j] = resolve_collision(v[i], v[j], mass[i], mass[j], normal, e)
    for i, n, _ in walls:
        if v[i].dot(n) < 0.0:
            v[i] = reflect_velocity(v[i], n, e)
    for i, j in pairs:
        delta = p[j] - p[i]
        depth = rad[i] + rad[j] - delta.length()
        p[i], p[j] = separate(p[i], p[j], mass[i], mass[j], delta.normalized(), depth + CONTACT_SLOP)
    for i, n, offset in walls:
        p[i] = p[i] + n * (rad[i] - (p[i].dot(n) - offset) + CONTACT_SLOP)
    as_array = lambda vs: np.array([list(x)[:dim] for x in vs])  # noqa: E731
    return as_array(p), as_array(v), len(pairs)


@st.composite
def pair_scenes(draw: st.DrawFn) -> dict[str, object]:
    """Disjoint groups far apart: pairs about to touch (or not) and single balls near a wall."""
    dim = draw(st.sampled_from([2, 3]))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    groups = draw(st.integers(1, 6))
    pos, vel, rad, mass = [], [], [], []
    for k in range(groups):
        centre = np.zeros(dim)
        centre[0] = -100.0 + 30.0 * k
        r = rng.uniform(0.2, 2.0, 2)
        direction = rng.normal(size=dim)
        direction /= np.linalg.norm(direction)
        gap = rng.uniform(0.8, 1.1) * r.sum()
        pos += [centre, centre + direction * gap]
        vel += list(rng.uniform(-3.0, 3.0, (2, dim)))
        rad += list(r)
        mass += list(rng.choice([1.0, 2.5, 0.1, math.inf], 2, p=[0.4, 0.3, 0.2, 0.1]))
        if mass[-1] == mass[-2] == math.inf:
            mass[-1] = 1.0
    for k in range(draw(st.integers(0, 3))):  # a ball near the wall x = -150 or y = +150
        r = rng.uniform(0.2, 2.0)
        spot = np.zeros(dim)
        spot[k % 2] = (-150.0 + rng.uniform(0.5, 1.5) * r) if k % 2 == 0 else (150.0 - rng.uniform(0.5, 1.5) * r)
        spot[1 - k % 2] = -60.0 + 40.0 * k
        pos.append(spot)
        vel.append(rng.uniform(-3.0, 3.0, dim))
        rad.append(r)
        mass.append(rng.choice([1.0, 0.3]))
    return {
        "pos": np.array(pos),
        "vel": np.array(vel),
        "rad": np.array(rad),
        "mass": np.array(mass),
        "dt": draw(st.sampled_from([0.01, 0.05, 0.1])),
        "e": draw(st.sampled_from([1.0, 0.7, 0.0])),
        "g": np.array([0.0, -draw(st.sampled_from([0.0, 9.81]))] + [0.0] * (dim - 2)),
    }


@settings(max_examples=60)
@given(pair_scenes())
def test_one_step_equals_the_scalar_core(scene: dict[str, object]) -> None:
    pos, vel, rad, mass = (np.asarray(scene[k]) for k in ("pos", "vel", "rad", "mass"))
    dt, e, g = float(scene["dt"]), float(scene["e"]), np.asarray(scene["g"])  # type: ignore[arg-type]
    if g.any() and e > 0.0:
        # Under gravity the engine gives e = 0 to a body landing on a support slower than
        # 2 |g.n| dt / e^2 (a bounce lower than one step's penetration: README, "The simulation");
        # the scalar core has no such rule, so such scenes are left to tests/test_engine_supports.py.
        moved = pos + vel * dt
        near_wall = np.abs(np.abs(moved) - 150.0) <= rad[:, None]
        assume(not np.any(near_wall) and np.all(np.isfinite(mass)))
    want_pos, want_vel, _ = reference_step(pos, vel, rad, mass, -150.0, 150.0, dt, e, g)
    if g.any():
        # Under gravity a push-apart that leaves a body higher than both its start and where
        # Euler moved it makes energy: the engine takes that out of the body's kinetic energy
        # (README, "The simulation"; issue 27), the scalar core does not. Such scenes are left to
        # tests/test_engine_euler_statics.py.
        up = -g / np.linalg.norm(g)
        end, start, moved = want_pos @ up, pos @ up, (pos + vel * dt) @ up
        assume(not np.any((end > start) & (end > moved)))
    for backend in BACKENDS:
        world = ParticleWorld(
            pos,
            vel,
            rad,
            mass,
            box=((-150.0,) * pos.shape[1], (150.0,) * pos.shape[1]),
            restitution=e,
            gravity=g,
            backend=backend,
        )
        world.step(dt)
        np.testing.assert_allclose(world.positions, want_pos, rtol=0, atol=1e-12)
        np.testing.assert_allclose(world.velocities, want_vel, rtol=0, atol=1e-12)


# --- order independence ------------------------------------------------------------------------------
def _permuted_run(world_args: dict[str, object], permutation: np.ndarray, steps: int, backend: str) -> tuple:
    args = dict(world_args)
    for key in ("positions", "velocities", "radii", "masses"):
        value = np.asarray(args[key])
        args[key] = value[permutation] if value.ndim else value
    world = ParticleWorld(**args, backend=backend)  # type: ignore[arg-type]
    report = world.step(0.05, steps)
    inverse = np.argsort(permutation)
    return world.positions[inverse], world.velocities[inverse], report


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_ball_hit_by_four_at_once_does_not_depend_on_body_order(backend: str) -> None:
    # Four balls at (+-1.9, 0) and (0, +-1.9) all overlap the centre one by exactly 0.1: equal
    # depths, so the order comes from the positions tie-break. Masses differ so that the order of
    # the four impulses changes the answer.
    world_args = {
        "positions": [[0, 0], [1.9, 0], [-1.9, 0], [0, 1.9], [0, -1.9], [30, 30]],
        "velocities": [[0, 0], [-1, 0], [1, 0], [0, -1], [0, 1], [0, 0]],
        "radii": 1.0,
        "masses": [1.0, 2.0, 3.0, 0.5, 1.5, 1.0],
        "box": ((-40, -40), (40, 40)),
    }
    baseline = _permuted_run(world_args, np.arange(6), 1, backend)
    assert baseline[2].body_collisions >= 3  # several impulses on the centre ball in one step
    rng = np.random.default_rng(5)
    for _ in range(10):
        other = _permuted_run(world_args, rng.permutation(6), 1, backend)
        np.testing.assert_allclose(other[0], baseline[0], rtol=0, atol=1e-12)
        np.testing.assert_allclose(other[1], baseline[1], rtol=0, atol=1e-12)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("dim", [2, 3])
def test_a_dense_gas_does_not_depend_on_body_order(backend: str, dim: int) -> None:
    gas = gas_scenario(150, dim, seed=3, fraction=0.45 if dim == 2 else 0.35)
    world_args = {
        "positions": gas.positions,
        "velocities": gas.velocities,
        "radii": np.linspace(0.8, 1.0, 150),
        "masses": np.linspace(1.0, 2.0, 150),
        "box": ((0.0,) * dim, (gas.side,) * dim),
        "restitution": 0.9,
        "gravity": (0.0, -1.0, 0.0)[:dim],
    }
    baseline = _permuted_run(world_args, np.arange(150), 40, backend)
    assert baseline[2].body_collisions > 100
    other = _permuted_run(world_args, np.random.default_rng(1).permutation(150), 40, backend)
    np.testing.assert_allclose(other[0], baseline[0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(other[1], baseline[1], rtol=0, atol=1e-12)


# --- the two backends, conservation, walls, robustness ---------------------------------------------
@pytest.mark.skipif(len(BACKENDS) < 2, reason="numba is not installed")
@pytest.mark.parametrize("dim", [2, 3])
def test_numba_and_numpy_agree_to_the_last_bit(dim: int) -> None:
    gas = gas_scenario(400, dim, seed=2, fraction=0.3)
    worlds = [gas.world(restitution=0.8, gravity=2.0, backend=b) for b in ("numba", "python")]
    reports = [w.step(gas.dt, 100) for w in worlds]
    assert reports[0] == reports[1]
    np.testing.assert_array_equal(worlds[0].positions, worlds[1].positions)
    np.testing.assert_array_equal(worlds[0].velocities, worlds[1].velocities)


@pytest.mark.parametrize("dim", [2, 3])
def test_elastic_gas_conserves_energy(dim: int) -> None:
    gas = gas_scenario(1000, dim, seed=4)
    world = gas.world(backend=FAST)
    start = world.kinetic_energy()
    report = world.step(gas.dt, 1000)
    assert report.body_collisions > 5000 and report.wall_collisions > 0
    assert abs(world.kinetic_energy() - start) <= 1e-12 * start


@pytest.mark.parametrize("backend", BACKENDS)
def test_momentum_is_conserved_without_walls_and_energy_falls_with_e_below_one(backend: str) -> None:
    gas = gas_scenario(300, 2, seed=8, fraction=0.4)
    world = ParticleWorld(
        gas.positions,
        gas.velocities + np.array([0.3, -0.2]),
        1.0,
        np.linspace(0.5, 3.0, 300),
        restitution=0.6,
        backend=backend,
    )
    momentum = world.momentum()
    energies = [world.kinetic_energy()]
    for _ in range(20):
        world.step(gas.dt, 5)
        energies.append(world.kinetic_energy())
    np.testing.assert_allclose(world.momentum(), momentum, rtol=0, atol=1e-11 * np.abs(momentum).max())
    assert all(b <= a * (1 + 1e-14) for a, b in itertools.pairwise(energies))
    assert energies[-1] < 0.99 * energies[0]


@pytest.mark.parametrize("dim", [2, 3])
def test_no_ball_leaves_the_box_and_no_nan_after_10000_steps_of_a_dense_gas(dim: int) -> None:
    n = 300
    gas = gas_scenario(n, dim, seed=11, fraction=0.45 if dim == 2 else 0.35)
    world = gas.world(restitution=0.9, gravity=1.0, backend=FAST)
    for _ in range(10):
        world.step(gas.dt, 1000)
        pos = world.positions
        assert np.all(np.isfinite(pos)) and np.all(np.isfinite(world.velocities))
        assert np.all(pos >= gas.radius) and np.all(pos <= gas.side - gas.radius)
    assert world.steps_taken == 10_000
    assert np.isclose(world.time, 10_000 * gas.dt)


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_column_of_balls_comes_to_rest_on_the_floor(backend: str) -> None:
    # Five unit balls dropped as a column (gaps 0.05) with e = 0 under gravity: the floor's impulse
    # reaches up the column through the contact margin, so it settles with centres near 1, 3, 5, 7, 9.
    world = ParticleWorld(
        [[5.0, 1.0 + 2.05 * i] for i in range(5)],
        np.zeros((5, 2)),
        1.0,
        box=((0, 0), (10, 50)),
        restitution=0.0,
        gravity=(0, -1),
        backend=backend,
    )
    world.step(0.05, 1000)
    heights = world.positions[:, 1]
    np.testing.assert_allclose(heights, [1, 3, 5, 7, 9], atol=0.05)
    assert np.all(np.diff(heights) > 2.0 - 0.02)  # overlaps below 1% of a diameter
    assert np.abs(world.velocities).max() < 0.1


def test_progress_is_reported_up_to_the_total() -> None:
    gas = gas_scenario(50, 2)
    world = gas.world()
    calls: list[tuple[int, int]] = []
    world.step(gas.dt, 250, progress=lambda done, total: calls.append((done, total)))
    assert calls[-1] == (250, 250)
    assert [d for d, _ in calls] == sorted({d for d, _ in calls})
    assert 50 <= len(calls) <= 100
    assert world.steps_taken == 250


def test_memory_stays_small_per_body() -> None:
    gas = gas_scenario(20_000, 3)
    world = gas.world()
    world.step(gas.dt, 2)
    assert world.nbytes / world.n < 300


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"positions": [[0, 0, 0, 0]]}, "positions"),
        ({"velocities": [[0, 0], [1, 1]]}, "velocities"),
        ({"velocities": [[0, 0, 0]]}, "velocities"),
        ({"radii": [1.0, 2.0]}, "radii"),
        ({"radii": -1.0}, "radii"),
        ({"masses": 0.0}, "masses"),
        ({"masses": float("nan")}, "masses"),
        ({"restitution": float("nan")}, "restitution"),
        ({"restitution": -0.1}, "restitution"),
        ({"gravity": (0, 0, 1)}, "gravity"),
        ({"box": ((0, 0), (1, 1))}, "box"),
        ({"box": ((0, 0, 0), (5, 5, 5))}, "box"),
        ({"planes": [((0, 0), 1.0)]}, "planes[0]"),
        ({"backend": "gpu"}, "backend"),
    ],
)
def test_bad_input_names_the_field(kwargs: dict[str, object], field: str) -> None:
    args: dict[str, object] = {"positions": [[0.0, 0.0]], "velocities": [[1.0, 0.0]]} | kwargs
    with pytest.raises(InvalidInputError) as caught:
        ParticleWorld(**args)  # type: ignore[arg-type]
    assert caught.value.field == field


@pytest.mark.parametrize(("dt", "steps", "field"), [(0.0, 1, "dt"), (float("inf"), 1, "dt"), (0.1, -1, "steps")])
def test_bad_step_names_the_field(dt: float, steps: int, field: str) -> None:
    world = ParticleWorld([[0.0, 0.0]], [[1.0, 0.0]])
    with pytest.raises(InvalidInputError) as caught:
        world.step(dt, steps)
    assert caught.value.field == field


@pytest.mark.parametrize("seed", range(30))
def test_one_step_equals_the_scalar_world(seed: int) -> None:
    # The same scene in the scalar World (euler mode: Euler, detect, resolve, push apart, with
    # Circle/Sphere bodies and Line/Plane walls) and in the ParticleWorld: one step agrees to 1e-12.
    from collisionlab import Circle, Line, Plane, Sphere
    from collisionlab.model import Body, Obstacle, Scenario, Settings
    from collisionlab.tolerances import REST_SPEED
    from collisionlab.world import World

    rng = np.random.default_rng(seed)
    dim = 2 + seed % 2
    pos, vel, rad, mass = [], [], [], []
    for k in range(3):  # three pairs far apart, each about to touch or just touching
        centre = np.zeros(dim)
        centre[0] = -20.0 + 20.0 * k
        r = rng.uniform(0.3, 1.5, 2)
        direction = rng.normal(size=dim)
        direction /= np.linalg.norm(direction)
        pos += [centre, centre + direction * rng.uniform(0.85, 1.05) * r.sum()]
        vel += list(rng.uniform(-3.0, 3.0, (2, dim)))
        rad += list(r)
        mass += list(rng.uniform(0.2, 5.0, 2))
    # and one ball at the floor y = -30
    r0 = rng.uniform(0.3, 1.5)
    spot = np.zeros(dim)
    spot[1] = -30.0 + 0.9 * r0
    pos.append(spot)
    vel.append(rng.uniform(-3.0, 3.0, dim))
    rad.append(r0)
    mass.append(1.0)
    pos_a, vel_a, rad_a, mass_a = np.array(pos), np.array(vel), np.array(rad), np.array(mass)
    dt, e, g = 0.01, float(rng.choice([1.0, 0.6, 0.0])), np.array([0.0, -9.81, 0.0][:dim])
    make = Circle if dim == 2 else Sphere
    bodies = [
        Body(f"b{i}", make(tuple(p), r), velocity=tuple(v), mass=m)
        for i, (p, v, r, m) in enumerate(zip(pos_a, vel_a, rad_a, mass_a, strict=True))
    ]
    if dim == 2:
        walls = [
            Obstacle("floor", Line((0, -30), (1, 0))),
            Obstacle("ceiling", Line((0, 30), (1, 0))),
            Obstacle("left", Line((-30, 0), (0, 1))),
            Obstacle("right", Line((30, 0), (0, 1))),
        ]
    else:
        walls = [
            Obstacle(f"w{k}{s}", Plane(tuple(np.eye(3)[k] * -30 * s), tuple(np.eye(3)[k] * s)))
            for k in range(3)
            for s in (1, -1)
        ]
    settings = Settings(dt=dt, steps=1, restitution=e, gravity=tuple(g))
    world = World(Scenario(settings, tuple(bodies), tuple(walls), allow_initial_overlap=True))
    world.step()
    approach = [abs(ev.approach_speed) for ev in world.record.events]
    assert world.record.events or world.record.skipped, "the scene should hold at least one contact"
    if any(a < 2 * REST_SPEED for a in approach):
        pytest.skip("a contact slower than the scalar world's rest threshold (the gas has none)")
    for backend in BACKENDS:
        gas = ParticleWorld(
            pos_a, vel_a, rad_a, mass_a, box=((-30.0,) * dim, (30.0,) * dim), restitution=e, gravity=g, backend=backend
        )
        gas.step(dt)
        want_pos = np.array([list(x)[:dim] for x in world.positions])
        want_vel = np.array([list(v)[:dim] for v in world.velocities])
        np.testing.assert_allclose(gas.positions, want_pos, rtol=0, atol=1e-12)
        np.testing.assert_allclose(gas.velocities, want_vel, rtol=0, atol=1e-12)


def test_repr_counts_and_settings_not_arrays() -> None:
    world = ParticleWorld(np.zeros((1, 3)), np.zeros((1, 3)), 0.5, box=((-1, -1, -1), (1, 1, 1)), gravity=(0, -1, 0))
    world.step(0.25, steps=2)
    assert repr(world) == (
        f"<ParticleWorld: 1 sphere in 3D, 6 walls, e = 1, gravity on, t = 0.5 s after 2 steps, backend {world.backend}>"
    )
    big = ParticleWorld(np.arange(40_000.0).reshape(-1, 2) * 3, np.zeros((20_000, 2)), 1.0)
    assert repr(big).startswith("<ParticleWorld: 20,000 discs in 2D, 0 walls") and len(repr(big)) < 150
