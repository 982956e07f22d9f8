"""The engine's world against oracles that do not share its code: closed forms worked by hand,
energies recomputed from the frames, a brute-force overlap search."""

from __future__ import annotations

import itertools
import math
import re
import tomllib
from collections.abc import Iterator

import jsonschema
import numpy as np
import pytest

from collisionlab import AABB, Circle, Line, Sphere
from collisionlab.body_block import BodyBlock
from collisionlab.engine.params import WorldParams
from collisionlab.model import Body, Obstacle, Scenario, Settings
from collisionlab.record import RunRecord
from collisionlab.scenario_file import ScenarioError, load_scenario, parse_scenario
from collisionlab.world import World, simulate
from tests.cli_helpers import EXAMPLES
from tests.schema_check import check_scenario_text


def _kinetic_from_frame(record: RunRecord, masses: dict[str, float], index: int) -> float:
    frame = record.frames[index]
    return sum(0.5 * masses[b.name] * b.velocity.length_squared() for b in frame.bodies if masses[b.name] < math.inf)


@pytest.mark.parametrize("mode", ["euler", "exact"])
def test_inelastic_head_on_with_masses_closed_form(mode: str) -> None:
    # m1 = 1 at +2 m/s, m2 = 3 at -1 m/s, e = 0.5 (1D, along x).
    # v_cm = (1*2 + 3*(-1)) / 4 = -0.25; v' = v_cm - e (v - v_cm):
    #   v1' = -0.25 - 0.5 * 2.25 = -1.375, v2' = -0.25 - 0.5 * (-0.75) = 0.125.
    # KE: before 0.5*4 + 0.5*3*1 = 3.5; after 0.5*1.890625 + 0.5*3*0.015625 = 0.96875; loss 2.53125
    #   = (1 - e^2)/2 * mu * (v1 - v2)^2 with mu = 3/4: 0.375 * 0.75 * 9 = 2.53125.
    light = Body("light", Circle((0, 0), 0.5), velocity=(2, 0), mass=1.0)
    heavy = Body("heavy", Circle((4, 0), 0.5), velocity=(-1, 0), mass=3.0)
    record = simulate(Scenario(Settings(dt=0.01, steps=150, restitution=0.5, mode=mode), (light, heavy)))
    (event,) = record.events
    assert event.velocities_after["light"].x == pytest.approx(-1.375, abs=1e-12)
    assert event.velocities_after["heavy"].x == pytest.approx(0.125, abs=1e-12)
    masses = {"light": 1.0, "heavy": 3.0}
    assert _kinetic_from_frame(record, masses, 0) == pytest.approx(3.5, abs=1e-12)
    assert _kinetic_from_frame(record, masses, -1) == pytest.approx(0.96875, abs=1e-12)
    assert record.ledger.collisions == pytest.approx(-2.53125, abs=1e-12)
    assert record.ledger.kinetic_end == pytest.approx(0.96875, abs=1e-12)


def test_forward_euler_gains_g_squared_dt_t_over_two_per_unit_mass() -> None:
    # Explicit Euler, position first: each step changes m|v|^2/2 - m g.x by m g^2 dt^2 / 2, so
    # after t = n dt the energy is up m g^2 dt t / 2 (three bodies of mass 1, 2, 5: 8 kg).
    # g = 9.81, dt = 0.01, t = 1: 8 * 96.2361 * 0.01 / 2 = 3.849444.
    bodies = [
        Body(f"b{k}", Sphere((3.0 * k, 0, 0), 0.5), velocity=(0.3 * k, 1.0, -0.2), mass=m)
        for k, m in enumerate((1.0, 2.0, 5.0))
    ]
    record = simulate(Scenario(Settings(dt=0.01, steps=100, gravity=(0, -9.81, 0)), tuple(bodies)), every=100)
    start, end = record.frames[0], record.frames[-1]
    masses = {b.name: b.mass for b in bodies}

    def energy(frame_bodies: tuple) -> float:  # from the frames: kinetic plus -m g.x
        return sum(masses[b.name] * (0.5 * b.velocity.length_squared() + 9.81 * b.position.y) for b in frame_bodies)

    gained = energy(end.bodies) - energy(start.bodies)
    assert gained == pytest.approx(8 * 9.81**2 * 0.01 * 1.0 / 2, rel=1e-9)
    assert record.ledger.integrator == pytest.approx(gained, rel=1e-9)


def test_a_kinematic_paddle_reflects_a_ball_in_its_own_frame() -> None:
    # A paddle of infinite mass moving up at 1 m/s; the ball arrives at v and leaves at 2*1 - v
    # (e = 1, reflection in the paddle's frame); the paddle neither slows nor falls.
    paddle = Body("paddle", AABB((-1, -0.1, -1), (1, 0.1, 1)), velocity=(0, 1, 0), mass=math.inf)
    ball = Body("ball", Sphere((0, 2, 0), 0.5), velocity=(0, -1, 0))
    for mode in ("euler", "exact"):
        settings = Settings(dt=0.01, steps=100, restitution=1.0, gravity=(0, -9.81, 0), mode=mode)
        record = simulate(Scenario(settings, (paddle, ball)))
        (event,) = record.events
        before, after = event.velocities_before["ball"].y, event.velocities_after["ball"].y
        assert after == pytest.approx(2.0 - before, abs=1e-12)
        assert all(f.bodies[0].velocity.y == 1.0 for f in record.frames)


def test_a_permutation_of_the_bodies_permutes_the_run() -> None:
    rng = np.random.default_rng(5)
    bodies = []
    for k in range(30):
        x, y = (k % 6) * 1.3, (k // 6) * 1.3
        shape = AABB((x - 0.4, y - 0.3), (x + 0.4, y + 0.3)) if k % 3 == 0 else Circle((x, y), 0.5)
        bodies.append(Body(f"b{k}", shape, velocity=tuple(rng.uniform(-2, 2, 2)), mass=float(rng.uniform(0.5, 2))))
    walls = [Obstacle("floor", AABB((-5, -3), (15, -1)))]
    settings = Settings(dt=0.01, steps=200, restitution=0.7, gravity=(0, -3, 0))
    one = simulate(Scenario(settings, tuple(bodies), tuple(walls)), every=200)
    order = rng.permutation(len(bodies))
    two = simulate(Scenario(settings, tuple(bodies[i] for i in order), tuple(walls)), every=200)
    end_one = {b.name: b for b in one.frames[-1].bodies}
    end_two = {b.name: b for b in two.frames[-1].bodies}
    assert end_one == end_two
    # the events too, in order (within a step deepest first, ties by position); which body of
    # a pair is A follows the order they are given in
    assert [(e.step, set(e.bodies)) for e in one.events] == [(e.step, set(e.bodies)) for e in two.events]
    assert len(one.events) > 10


@pytest.mark.parametrize("mode", ["euler", "exact"])
def test_compiled_and_python_kernels_agree_to_the_last_bit(mode: str) -> None:
    text = f"""
    [simulation]
    mode = "{mode}"
    dt = 0.005
    steps = 60
    restitution = 0.8
    gravity = [0, -9.81, 0]
    [[gas]]
    name = "ball"
    shape = "sphere"
    radius = 0.1
    region = [[-1, 0.2, -1], [1, 1.5, 1]]
    count = 60
    seed = 3
    [[gas]]
    name = "crate"
    shape = "aabb"
    size = [0.3, 0.2, 0.3]
    region = [[-1, 1.6, -1], [1, 2.2, 1]]
    count = 6
    seed = 4
    [[static]]
    name = "incline"
    shape = "plane"
    point = [0, 0, 0]
    normal = [0.3, 1, 0]
    """
    scenario = parse_scenario(tomllib.loads(text))
    slow = World(scenario, WorldParams(compiled=False)).run(every=20)
    fast = World(scenario, WorldParams(compiled=True)).run(every=20)
    assert [f.bodies for f in slow.frames] == [f.bodies for f in fast.frames]
    assert slow.events == fast.events
    assert len(slow.events) > 0


# --- [[gas]] tables -----------------------------------------------------------------------------
def _gas(extra: str, shape: str = "circle", size: str = "radius = 0.5") -> Scenario:
    return parse_scenario(tomllib.loads(f'[[gas]]\nname = "g"\nshape = "{shape}"\n{size}\n{extra}'), "f.toml")


def test_a_gas_table_places_its_bodies_without_overlap() -> None:
    scenario = _gas("region = [[0, 0], [20, 20]]\ncount = 300\nseed = 9\nkT = 2.0\nmass = 0.5")
    centres = np.array([b.position.as_tuple()[:2] for b in scenario.bodies])
    assert len(centres) == 300 and [b.name for b in scenario.bodies[:2]] == ["g0", "g1"]
    gaps = [np.linalg.norm(p - q) for p, q in itertools.combinations(centres, 2)]
    assert min(gaps) > 1.0  # diameter 1: brute force over all 44,850 pairs
    assert np.all(centres >= 0.5) and np.all(centres <= 19.5)  # inside the region
    # Maxwell-Boltzmann: each component's variance kT/m = 4; 600 samples: standard error of a
    # variance sqrt(2/600) = 5.8%, so 20% is more than 3 sigma.
    v = np.array([b.velocity.as_tuple()[:2] for b in scenario.bodies]).ravel()
    assert np.var(v) == pytest.approx(4.0, rel=0.2)
    again = _gas("region = [[0, 0], [20, 20]]\ncount = 300\nseed = 9\nkT = 2.0\nmass = 0.5")
    assert again.bodies == scenario.bodies  # the seed decides everything


def test_a_gas_fraction_gives_the_count() -> None:
    # 3D spheres r = 1 in a 10 x 10 x 10 box at fraction 0.2: 0.2 * 1000 / (4/3 pi) = 47.7 -> 48.
    scenario = _gas("region = [[0, 0, 0], [10, 10, 10]]\nfraction = 0.2", "sphere", "radius = 1.0")
    assert len(scenario.bodies) == 48


@pytest.mark.parametrize(
    ("extra", "field"),
    [
        ("region = [[0, 0], [3, 3]]\ncount = 10", "gas[0].count"),  # a 3 x 3 region holds 2 x 2
        ("region = [[0, 0], [9, 9]]\ncount = 4\nfraction = 0.1", "gas[0].count"),
        ("region = [[0, 0], [9, 9]]", "gas[0].count"),
        ("region = [[0, 0], [9, 0]]\ncount = 2", "gas[0].region"),
        ("region = [0, 0]\ncount = 2", "gas[0].region"),
        ("region = [[0, 0], [9, 9]]\ncount = 2\nkT = 1\nvelocity = [1, 0]", "gas[0].kT"),
        ("region = [[0, 0], [9, 9]]\ncount = -2", "gas[0].count"),
        ("region = [[0, 0], [9, 9]]\ncount = 2\ncolour = 1", "gas[0].colour"),
    ],
)
def test_bad_gas_tables_name_the_field(extra: str, field: str) -> None:
    with pytest.raises(ScenarioError, match=rf"^f\.toml: {re.escape(field)}:"):
        _gas(extra)


def test_a_gas_table_meets_the_scenario_schema_and_a_bad_one_does_not() -> None:
    good = '[simulation]\nallow_initial_overlap = true\n[[gas]]\nshape = "circle"\nradius = 1\n'
    good += "region = [[0, 0], [9, 9]]\ncount = 4\n"
    check_scenario_text(good)
    assert len(parse_scenario(tomllib.loads(good)).bodies) == 4
    with pytest.raises(jsonschema.ValidationError):
        check_scenario_text(good.replace("count = 4", "count = 4\nfraction = 0.1"))


def test_the_cli_refuses_a_file_whose_bodies_start_overlapping(tmp_path) -> None:
    from tests.cli_helpers import run_cli

    # Centres 1.5 apart, radii 1 + 1: 0.5 m deep.
    text = '[[body]]\nname = "a"\nshape = "circle"\nposition = [0, 0]\nradius = 1\n'
    text += '[[body]]\nname = "b"\nshape = "circle"\nposition = [1.5, 0]\nradius = 1\n'
    path = tmp_path / "overlap.toml"
    path.write_text(text)
    result = run_cli(["run", str(path)])
    assert result.status == 65
    assert "'a' and 'b' overlap by 0.5 m" in result.err and len(result.err.strip().splitlines()) == 1
    path.write_text("[simulation]\nallow_initial_overlap = true\n" + text)
    result = run_cli(["run", str(path), "--steps", "2"])
    assert result.status == 0 and "overlapped at the start" in result.out


def test_allow_initial_overlap_must_be_true_or_false() -> None:
    text = '[simulation]\nallow_initial_overlap = "yes"\n[[body]]\nshape = "circle"\nposition = [0, 0]\nradius = 1\n'
    with pytest.raises(ScenarioError, match=r"^f\.toml: simulation\.allow_initial_overlap: must be true or false"):
        parse_scenario(tomllib.loads(text), "f.toml")


def test_an_oblique_perfectly_inelastic_impact_is_one_kick() -> None:
    # Found by hypothesis: after this e = 0 impact the approach speed left is rounding (-1.7e-17
    # m/s); its impulse is below one ulp of the velocities, so kicking it again changes nothing and
    # the stepper used to loop (122,910 impulses in one step). One impact, one kick.
    # e = 0 along n: the normal velocities become the centre of mass's, (m_a v_a + m_b v_b) . n /
    # (m_a + m_b); with n = (0.99499, 0, 0.1), v_a . n = 0.5 * 0.99499, v_b . n = -0.99499:
    # v_n after = (0.125 * 0.497494 - 0.994987) / 1.125 = -0.829156 for both.
    a = Body("a", Sphere((0, 0, 0), 0.5), velocity=(0.5, 0, 0), mass=0.125)
    b = Body("b", Sphere((3, 0, 0.1), 0.5), velocity=(-1, 0, 0), mass=1.0)
    world = World(Scenario(Settings(dt=0.01, steps=317, restitution=0.0, mode="exact"), (a, b), ()))
    record = world.run()
    assert len(record.events) == 1 and not record.warnings
    assert int(world._stepper.status[1]) <= 2  # impulses applied in the whole run
    n = record.events[0].normal
    after = record.events[0].velocities_after
    assert after["a"].dot(n) == pytest.approx(-0.829156, abs=1e-6)
    assert after["b"].dot(n) == pytest.approx(-0.829156, abs=1e-6)


class _Collector:
    """A RunObserver that keeps what it is told, in order."""

    def __init__(self) -> None:
        self.told: list[tuple[str, object]] = []

    def begin(self, record: RunRecord) -> None:
        self.told.append(("begin", record.title))

    def frame(self, frame: object) -> None:
        self.told.append(("frame", frame))

    def events(self, events: list[object], skipped: list[object], reached: int) -> None:
        self.told += [("event", e) for e in events] + [("skipped", s) for s in skipped]

    def warning(self, text: str) -> None:
        self.told.append(("warning", text))

    def end(self, record: RunRecord) -> None:
        self.told.append(("end", record.collision_total))


def _newtons_cradle() -> Scenario:
    # Five balls in a row, the first moving: e = 1 passes the blow down the row every time the
    # ends meet the walls; many events over a long run.
    balls = [Body(f"b{i}", Circle((2.0 * i, 0), 1), velocity=(3 if i == 0 else 0, 0)) for i in range(5)]
    walls = [Obstacle("left", Line((-5, 0), (0, 1))), Obstacle("right", Line((13, 0), (0, 1)))]
    return Scenario(Settings(dt=0.01, steps=2000, restitution=1.0), tuple(balls), tuple(walls))


@pytest.mark.parametrize("mode", ["euler", "exact"])
def test_a_streamed_run_tells_everything_and_keeps_nothing(mode: str) -> None:
    scenario = _newtons_cradle().with_settings(mode=mode)
    kept = World(scenario).run(every=10)
    collector = _Collector()
    streamed = World(scenario).run(every=10, observer=collector, keep=False)
    # Nothing held but the first and latest frames: memory does not grow with the run.
    assert streamed.events == [] and len(streamed.frames) == 2
    assert streamed.collision_total == kept.collision_total == len(kept.events) > 10
    assert [e for kind, e in collector.told if kind == "event"] == kept.events
    assert [f for kind, f in collector.told if kind == "frame"] == kept.frames
    assert collector.told[0] == ("begin", scenario.title) and collector.told[-1] == ("end", len(kept.events))
    # Each event is told before the frame of a later (or its own) step.
    last_frame = -1
    for kind, item in collector.told:
        if kind == "frame":
            last_frame = item.step  # type: ignore[attr-defined]
        elif kind == "event":
            assert item.step > last_frame  # type: ignore[attr-defined]
    assert streamed.ledger == kept.ledger


@pytest.mark.parametrize("mode", ["euler", "exact"])
def test_the_ledger_does_not_depend_on_how_the_run_is_split_into_calls(mode: str) -> None:
    # The compiled run sizes its calls by wall time; the ledger must be the same to the last bit
    # (it is one running sum in event order, not a sum of per-call sums).
    rng = np.random.default_rng(7)
    discs = [
        Body(f"d{i}", Circle((-4 + 2 * (i % 5), -4 + 2 * (i // 5)), 0.4), velocity=tuple(rng.uniform(-5, 5, 2)))
        for i in range(20)
    ]
    walls = [
        Obstacle(name, Line(point, direction))
        for name, point, direction in (
            ("left", (-5, 0), (0, 1)),
            ("right", (5, 0), (0, 1)),
            ("bottom", (0, -5), (1, 0)),
            ("top", (0, 5), (1, 0)),
        )
    ]
    settings = Settings(dt=0.01, steps=300, restitution=0.8, gravity=(0, -9.81), mode=mode)
    whole, pieces = (
        World(Scenario(settings, tuple(discs), tuple(walls))),
        World(Scenario(settings, tuple(discs), tuple(walls))),
    )
    whole.step(300)
    for count in (1, 2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 61):  # 300 steps (they add up to 300)
        pieces.step(count)
    assert whole.record.ledger == pieces.record.ledger
    assert whole.record.ledger.collisions < 0.0 and whole.record.collision_total > 50


def test_a_compiled_world_loads_its_kernels_with_the_collector_paused(monkeypatch: pytest.MonkeyPatch) -> None:
    """numba's import and its loading of cached code run with Python's collector paused (it would
    walk their objects several times over); the collector is on again afterwards."""
    import gc

    from collisionlab.engine import exact_stepper, stepper

    seen: list[tuple[str, bool]] = []
    for cls in (stepper.EulerStepper, exact_stepper.ExactStepper):
        advance = cls.advance

        def spy(self: object, *args: object, _advance: object = advance, _name: str = cls.__name__) -> None:
            seen.append((_name, gc.isenabled()))
            _advance(self, *args)  # type: ignore[operator]

        monkeypatch.setattr(cls, "advance", spy)
    ball = Body("ball", Sphere((0, 1, 0), 0.5), velocity=(0, -1, 0))
    for mode in ("euler", "exact"):
        scenario = Scenario(Settings(dt=0.01, steps=3, mode=mode), (ball,), ())
        world = World(scenario, WorldParams(compiled=True))
        world.step(1)
        world.step(1)
        world.step(1)
        assert gc.isenabled()
    # The first call of each stepper's compiled kernels with the collector paused, later ones not.
    assert [enabled for _, enabled in seen] == [False, True, True, False, True, True]


@pytest.mark.parametrize("cached", [True, False])
def test_a_world_compiling_its_kernels_holds_the_compile_lock(monkeypatch: pytest.MonkeyPatch, cached: bool) -> None:
    """Kernels not in numba's cache yet are compiled under a lock another process would wait on
    (numba_cache.compile_lock), once per world and kernel, with Python's collector on (a compile
    makes garbage for minutes), and said once per world; cached ones are loaded unlocked, and
    nothing is said. The cache is asked about the kernel that is about to be called."""
    import contextlib
    import gc

    from collisionlab.engine import compiled, kernel_loading

    locked: list[str] = []

    @contextlib.contextmanager
    def spy(package: object, stem: str) -> Iterator[None]:
        assert gc.isenabled()
        locked.append(stem)
        yield

    asked: list[tuple[str, str]] = []

    def is_cached(stem: str, entry: str) -> bool:
        asked.append((stem, entry))
        return cached

    monkeypatch.setattr(compiled, "is_cached", is_cached)
    monkeypatch.setattr(kernel_loading, "compile_lock", spy)
    ball = Body("ball", Sphere((0, 1, 0), 0.5), velocity=(0, -1, 0))
    said: list[str] = []
    for mode in ("euler", "exact"):
        scenario = Scenario(Settings(dt=0.01, steps=3, mode=mode), (ball,), ())
        world = World(scenario, WorldParams(compiled=True), notify=said.append)
        world.step(1)
        world.step(2)
    # The check of overlaps at the start is NumPy's: no kernel is compiled for it.
    called = [("step_kernels", "run_steps"), ("exact_kernels", "run_exact_steps")]
    if cached:
        assert asked == called
        assert locked == []
        assert said == []
    else:  # the exact world's notice also asks about the exact kernel, to say how long
        assert asked == [called[0], *called[1:] * 2]
        assert locked == [stem for stem, _ in called]
        assert [line.split("; ")[1] for line in said] == ["up to a minute)...", "one to three minutes)..."]


# --- issue 28: the compiled kernels loaded ahead of the first step ---------------------------------
@pytest.mark.parametrize(("mode", "contacts"), [("euler", "events"), ("exact", "events"), ("exact", "solve")])
def test_load_kernels_ahead_changes_nothing_of_the_run(mode: str, contacts: str) -> None:
    from collisionlab.demos import load_demo

    settings = {"mode": mode} if contacts == "events" else {"mode": mode, "contacts": contacts}
    scenario = load_demo("bouncing-ball").with_settings(**settings)
    python = World(scenario, WorldParams(compiled=False))
    assert python.load_kernels() == 0.0  # the Python form loads nothing
    compiled = World(scenario, WorldParams(compiled=True))
    assert compiled.load_kernels() >= 0.0
    assert compiled.load_kernels() == 0.0  # loaded already in this process
    first, second = compiled.run(), python.run()
    assert [e.to_dict() for e in first.events] == [e.to_dict() for e in second.events]
    assert first.frames[-1].to_dict() == second.frames[-1].to_dict()


def test_a_compile_announced_is_said_to_be_done_and_a_load_says_nothing(monkeypatch: pytest.MonkeyPatch) -> None:
    # Issue 28: "a command that still has to compile says so ... and says when it is done". The
    # world that compiles (here a stand-in that announces a compile, or not, as a world does at
    # its first compiled call) is the one load_stepper_kernels steps.
    from collisionlab.engine import world as engine_world

    class Compiling:
        def __init__(self, scenario: Scenario, params: WorldParams, notify: object, events: bool) -> None:
            self.notify = notify

        def step(self, steps: int) -> None:
            if callable(self.notify) and announce:
                self.notify("compiling the engine's kernels (once per machine; up to a minute)...")

    monkeypatch.setattr(engine_world, "World", Compiling)
    monkeypatch.setattr(engine_world, "_LOADED", set())
    said: list[str] = []
    announce = True
    engine_world.load_stepper_kernels("euler", said.append)
    assert said[0].startswith("compiling the engine's kernels")
    assert re.fullmatch(r"compiled the engine's kernels in \d+ s", said[1]) and len(said) == 2
    said.clear()
    announce = False  # loaded from the cache: nothing to say
    engine_world.load_stepper_kernels("exact", said.append)
    assert said == []


def test_the_event_driven_compile_is_said_to_be_done(monkeypatch: pytest.MonkeyPatch) -> None:
    from collisionlab.edmd import compile as edmd_compile
    from collisionlab.engine import ahead

    monkeypatch.setattr(edmd_compile, "is_cached", lambda: False)  # as on a machine's first run
    said: list[str] = []
    ahead._event_driven(said.append)
    assert said[0].startswith("compiling the event-driven kernels (once per machine;")
    assert re.fullmatch(r"compiled the event-driven kernels in \d+ s", said[1]) and len(said) == 2
    monkeypatch.setattr(edmd_compile, "is_cached", lambda: True)
    said.clear()
    ahead._event_driven(said.append)
    assert said == []


def test_load_kernels_of_an_unknown_kind_names_it() -> None:
    from collisionlab.engine.ahead import load_kernels
    from collisionlab.errors import InvalidInputError

    with pytest.raises(InvalidInputError, match="kind"):
        load_kernels("fortran")


# --- a pile in exact mode without the contact solver is named -----------------------------------
def _pour(n: int, width: float, contacts: str) -> Scenario:
    # n circles (r 0.5, 1 kg) on a lattice 1.2 diameters apart, dropped into a box of three lines
    cols = int(width / 1.2) - 1
    k = np.arange(n)
    pos = np.c_[-width / 2 + 1.1 + 1.2 * (k % cols) + 0.05 * np.sin(1.7 * k), 2.0 + 1.2 * (k // cols)]
    block = BodyBlock("ball", "circle", (0.5, 0.5, 0.5), pos, np.zeros_like(pos))
    statics = (
        Obstacle("floor", Line((0, 0), (1, 0))),
        Obstacle("left", Line((-width / 2, 0), (0, 1))),
        Obstacle("right", Line((width / 2, 0), (0, 1))),
    )
    settings = Settings(dt=0.01, steps=200, restitution=0.5, gravity=(0, -9.81, 0), mode="exact", contacts=contacts)
    return Scenario(settings, (block,), statics)


def test_a_pile_resolved_as_impacts_says_once_that_the_contact_solver_is_made_for_it() -> None:
    # 30 circles settling in a 4 m box: resting contact as micro-impacts (about 250 impulses per
    # body and step by step 150): one warning naming contacts = "solve".
    world = World(_pour(30, 4.0, "events"), WorldParams(compiled=True))
    world.step(200)
    hints = [w for w in world.record.warnings if 'contacts = "solve"' in w]
    assert len(hints) == 1


@pytest.mark.parametrize("name", ["bouncing-ball", "stack"])
def test_a_ball_bouncing_or_a_stack_in_exact_mode_under_gravity_gets_no_pile_hint(name: str) -> None:
    # The shipped examples run exact with contacts = "events" under gravity: 0.06 and 0.02
    # impulses per body and step over their whole runs, far below the hint's 100.
    scenario = load_scenario(EXAMPLES / f"{name}.toml")
    assert scenario.settings.mode == "exact" and scenario.settings.contacts == "events"
    assert any(scenario.settings.gravity.as_tuple())
    world = World(scenario)
    world.step(scenario.settings.steps)
    assert not any('contacts = "solve"' in w for w in world.record.warnings)


def test_exact_chunks_stay_short_when_the_steps_slow_down() -> None:
    # Circles poured into a box: 64 exact steps took 0.18 s while they fell, so the next chunk was
    # sized at 88 steps, and it took 36 s once they landed (each step a hundred times dearer): the
    # progress count, the output and the event buffer (every row of a chunk) waited for it. On a
    # clock where steps cost 1 ms, then 100 ms from step 100, no chunk may pass the exact aim at
    # the pace of the last (EXACT_CHUNK_SECONDS: 25 steps of 1 ms), nor grow past one step after.
    from collisionlab.engine.chunks import EXACT_CHUNK_SECONDS

    world = World(load_scenario(EXAMPLES / "bouncing-ball.toml").with_settings(steps=200), WorldParams(compiled=True))
    assert not world.event_driven
    chunks: list[int] = []

    def clock() -> float:
        return 0.001 * min(world.step_index, 100) + 0.1 * max(world.step_index - 100, 0)

    world.advance(200, lambda done, total: chunks.append(done - sum(chunks)), clock)
    assert sum(chunks) == 200
    assert max(chunks) <= round(EXACT_CHUNK_SECONDS / 0.001)
    assert chunks[-50:] == [1] * 50  # at 0.1 s a step: one at a time
