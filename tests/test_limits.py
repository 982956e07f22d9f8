"""The range of magnitudes that can be simulated (collisionlab.limits): refused before a run,
watched during it, and the measurement behind ``MAX_TRAVEL_PER_SIZE``."""

from __future__ import annotations

import json
import random
import subprocess
import sys
from pathlib import Path

import pytest

from collisionlab import InvalidInputError, Plane, Sphere
from collisionlab.edmd.guard import RunGuard
from collisionlab.edmd.observables import ExactGas
from collisionlab.errors import OutOfRangeError
from collisionlab.limits import MAX_BODY_STEPS, MAX_RESTITUTION, MAX_RUN_SPEED, MAX_STEPS, MAX_TRAVEL_PER_SIZE
from collisionlab.model import Body, Obstacle, Scenario, Settings
from collisionlab.particles.scenarios import gas_scenario
from collisionlab.world import simulate
from tests.cli_helpers import run_cli

BALL = '[[body]]\nname = "ball"\nshape = "sphere"\nposition = [0, 3, 0]\nradius = 0.5\nvelocity = [1, -2, 0]\n'


def _ball_between_walls(restitution: float) -> Scenario:
    # A ball between two walls 2 m apart: each bounce multiplies its speed by e.
    ball = Body("ball", Sphere((0, 0, 0), 0.1), velocity=(1, 0, 0))
    walls = (Obstacle("left", Plane((-1, 0, 0), (1, 0, 0))), Obstacle("right", Plane((1, 0, 0), (-1, 0, 0))))
    return Scenario(Settings(dt=1e-3, steps=MAX_STEPS, restitution=restitution, mode="exact"), (ball,), walls)


def test_a_speed_that_grows_out_of_range_stops_the_run_naming_the_step_and_the_body() -> None:
    # e = 10: after k bounces the speed is 10^k m/s; past 1e12 m/s the run stops (it would reach
    # inf, then NaN). Bounce k comes after about 2 / 10^(k-1) s: all 13 within 2.3 s.
    with pytest.raises(OutOfRangeError) as caught:
        simulate(_ball_between_walls(MAX_RESTITUTION))
    message = str(caught.value)
    # Either the guard saw 1e12 m/s pass at the end of a step, or within one step (thousands of
    # bounces) a number overflowed: both name the step and say why.
    assert message.startswith("step ") and "too large to simulate" in message
    assert "'ball' reached velocity" in message or "overflowed" in message


def test_the_guard_names_the_body_and_the_bound() -> None:
    from collisionlab.run_guard import RangeGuard
    from collisionlab.vector import Vector3D

    guard = RangeGuard(_ball_between_walls(1.0))
    assert guard.check(3, 0.003, [Vector3D(0, 0, 0)], [Vector3D(1, 0, 0)]) is None
    with pytest.raises(OutOfRangeError) as caught:
        guard.check(4, 0.004, [Vector3D(0, 0, 0)], [Vector3D(2e12, 0, 0)])
    assert str(caught.value).startswith("step 4 (t = 0.004 s): 'ball' reached velocity (2e+12, 0, 0)")
    assert f"{MAX_RUN_SPEED:g}" in str(caught.value)


def test_the_command_line_reports_a_run_out_of_range_as_invalid_data_naming_the_file(tmp_path: Path) -> None:
    path = tmp_path / "grow.toml"
    path.write_text(
        "[simulation]\ndt = 0.001\nsteps = 100000\nrestitution = 10\nmode = 'exact'\n"
        '[[body]]\nname = "ball"\nshape = "sphere"\nposition = [0, 0, 0]\nradius = 0.1\nvelocity = [1, 0, 0]\n'
        '[[static]]\nname = "l"\nshape = "plane"\npoint = [-1, 0, 0]\nnormal = [1, 0, 0]\n'
        '[[static]]\nname = "r"\nshape = "plane"\npoint = [1, 0, 0]\nnormal = [-1, 0, 0]\n'
    )
    result = run_cli(["run", str(path), "--format", "json"])
    assert result.status == 65
    assert result.out == ""
    (line,) = result.err.splitlines()
    assert line.startswith(f"collisionlab: invalid scenario: {path}: step ") and "too large to simulate" in line


@pytest.mark.parametrize(
    ("flag", "value", "words"),
    [
        ("--restitution", "1e308", "at most 10"),
        ("--dt", "1e308", "at most 1e+06"),
        ("--dt", "1e-300", "at least 1e-09"),
        ("--steps", "100000000000000000000000", "at most 2e+06"),
    ],
)
def test_a_flag_out_of_range_is_refused_before_the_run_naming_the_flag(flag: str, value: str, words: str) -> None:
    result = run_cli(["demo", "sphere-plane", flag, value])
    assert result.status == 2
    assert result.out == ""
    assert flag in result.err and words in result.err and "Traceback" not in result.err


def test_steps_times_bodies_beyond_memory_is_refused_naming_the_flag(tmp_path: Path) -> None:
    # newtons-cradle has 5 balls: 5 x 2e6 steps of frames kept in memory (~4 GB) for a picture
    # cannot fit. (Without pictures the frames stream out: tests/test_cli_run.py.)
    result = run_cli(["demo", "newtons-cradle", "--steps", str(MAX_STEPS), "--plot", str(tmp_path / "p.png")])
    assert result.status == 2
    assert result.err.startswith("collisionlab: --steps: ") and f"{MAX_BODY_STEPS:,}" in result.err


def test_a_sphere_at_1e200_m_per_s_is_refused_so_json_is_never_invalid() -> None:
    with pytest.raises(InvalidInputError) as caught:
        Scenario(Settings(), (Body("b", Sphere((0, 0, 0), 1), velocity=(1e200, 0, 0)),))
    assert caught.value.field == "body[0].velocity"


def test_exact_mode_refuses_bodies_too_fast_for_time_of_impact_to_resolve() -> None:
    # Two spheres at +-1e154 m/s, dt 1: beyond the speed range; at +-1e8 m/s with radius 1 they
    # close 2e8 m a step, 2e8 radii: beyond MAX_TRAVEL_PER_SIZE, where a miss was measured.
    for speed in (1e154, 1e8):
        a = Body("a", Sphere((-1e3, 0, 0), 1), velocity=(speed, 0, 0))
        b = Body("b", Sphere((1e3, 0, 0), 1), velocity=(-speed, 0, 0))
        with pytest.raises(InvalidInputError) as caught:
            Scenario(Settings(dt=1, steps=2, mode="exact"), (a, b))
        assert caught.value.field == "body[0].velocity"


def _misses(speed: float, radius: float, dt: float, tries: int = 20) -> int:
    """Head-on and grazing meetings within the first step; how many found no collision.
    Built as a euler scenario (not checked for travel), then run in exact mode by hand."""
    from collisionlab.world import World

    rng = random.Random(1)
    missed = 0
    for _ in range(tries):
        offset = rng.uniform(0, 1.9) * radius  # < 2 r: they must touch
        gap = rng.uniform(0.1, 0.9) * speed * dt
        a = Body("a", Sphere((-gap, 0, 0), radius), velocity=(speed, 0, 0))
        b = Body("b", Sphere((gap, offset, 0), radius), velocity=(-speed, 0, 0))
        scenario = Scenario(Settings(dt=dt, steps=1), (a, b))
        object.__setattr__(scenario.settings, "mode", "exact")  # bypass the check: measure
        world = World(scenario)
        world.step()
        missed += not world.record.events
    return missed


def test_the_travel_limit_is_where_time_of_impact_still_finds_every_touch() -> None:
    # The measurement behind MAX_TRAVEL_PER_SIZE: at 1e6 radii per step (closing) no touch is
    # missed; at 1e9 most are (the discriminant's rounding, sqrt(eps) ~ 1.5e-8 of the travel).
    assert _misses(speed=MAX_TRAVEL_PER_SIZE / 2, radius=1.0, dt=1.0) == 0
    assert _misses(speed=MAX_TRAVEL_PER_SIZE / 2 * 1e-6, radius=1e-6, dt=1.0) == 0
    assert _misses(speed=5e8, radius=1.0, dt=1.0) > 0


def test_exact_mode_warns_when_gravity_makes_bodies_too_fast_for_time_of_impact() -> None:
    # A 1 mm ball falling at 1e9 m/s^2 with dt 1 s: after k steps it moves ~1e9 k m a step,
    # far past 1e6 x 1 mm. The run warns (it is not refused: it starts at rest).
    ball = Body("ball", Sphere((0, 0, 0), 1e-3), velocity=(0, 0, 0))
    record = simulate(Scenario(Settings(dt=1e-3, steps=100, gravity=(0, -1e9, 0), mode="exact"), (ball,)))
    assert any("time of impact may miss" in w for w in record.warnings)


def test_json_output_is_valid_json_at_the_edge_of_the_range() -> None:
    # The largest speed, mass and coordinate allowed: every number in the JSON is finite.
    ball = Body("b", Sphere((1e9 - 10, 0, 0), 1e9), velocity=(-1e9, 1e9, -1e9), mass=1e30)
    record = simulate(Scenario(Settings(dt=1e-3, steps=5, gravity=(1e9, 1e9, 1e9)), (ball,)))
    from collisionlab.cli.render import render_json

    text = render_json(record)
    json.loads(text, parse_constant=lambda name: pytest.fail(f"{name} in the JSON"))


# --- the many-body gas (issue 11, the audit) ----------------------------------------------------
@pytest.mark.parametrize(
    ("changes", "field", "words"),
    [
        ({"n": 10**20}, "n", "at most"),  # ran for minutes before any message
        ({"time": 1e308}, "time", "at most"),  # ran for ever (and ignored Ctrl-C)
        ({"time": 5e-324}, "time", "at least"),  # Infinity in the JSON (momentum over the time)
        ({"fraction": 1e-20}, "fraction", "at least"),  # ValueError: negative dimensions
        ({"seed": -1}, "seed", ">= 0"),  # numpy's ValueError
    ],
)
def test_the_exact_gas_refuses_what_cannot_finish_or_fit(changes: dict[str, float], field: str, words: str) -> None:
    with pytest.raises(InvalidInputError) as caught:
        ExactGas(**{"n": 10, "time": 1.0, **changes}).checked()  # type: ignore[arg-type]
    assert caught.value.field == field and words in str(caught.value)


def test_the_gas_refuses_more_balls_than_fit() -> None:
    # collisionlab gas --n 99999999999999999999 ended in "unexpected error: ValueError: array is too big".
    with pytest.raises(InvalidInputError, match="at most 1e\\+07") as caught:
        gas_scenario(10**20)
    assert caught.value.field == "n"
    assert gas_scenario(10, 2).velocities.shape == (10, 2)


def test_an_exact_gas_whose_speeds_explode_stops_out_of_range_not_spinning_for_ever() -> None:
    # e = 10: speeds grow tenfold at each collision until a ball crosses its neighbour-list shell
    # within the resolution of the time; the compiled loop then spun at one instant for ever. The
    # guard (edmd.guard) stops the run with the library's error. max_events bounds this run should
    # the guard fail: it would then end quietly, and the test fail instead of hanging.
    world = ExactGas(n=10, dim=2, time=100.0, restitution=10.0).checked().world()
    guard = RunGuard(world)
    with pytest.raises(OutOfRangeError, match="too large to simulate"):
        world.run(100.0, max_events=50_000_000, between=guard, every=guard.every)


def test_the_exploding_exact_gas_through_the_command_line_exits_65() -> None:
    # The same gas as the command line runs it (on the engine's world, whose event-driven stepper
    # holds the guard); a subprocess with a timeout, so a run that spins fails the test.
    argv = ["gas", "--mode", "exact", "--n", "10", "--dim", "2", "--time", "100", "--restitution", "10"]
    done = subprocess.run(
        [sys.executable, "-m", "collisionlab", *argv], capture_output=True, text=True, timeout=600, check=False
    )
    assert done.returncode == 65, done.stderr
    assert "too large to simulate" in done.stderr and "Traceback" not in done.stderr
