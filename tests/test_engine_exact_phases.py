"""The exact stepper's phases as its compiled form runs them (exact_kernels.py and the files of its
phases, compiled.py): compiled without reference counts (NO_REFCOUNT), so they allocate nothing.
The heap compacts in place; the driver gives the events buffer room before each call (ROOM): a run
is the same however tight."""

from __future__ import annotations

import tomllib
import types
from typing import Any

import numpy as np
import pytest

from collisionlab.engine import (
    broad_phase_grid,
    broad_phase_pairs,
    compiled,
    contact_order,
    euler_clamps,
    euler_impulses,
    euler_push_apart,
    event_heap,
    event_rows,
    exact_flight,
    exact_impacts,
    exact_impulses,
    exact_kernels,
    exact_rest,
    exact_settle,
    exact_step_end,
    exact_sweeps,
    geometry_kernels,
    non_literal,
    pair_separation,
    pair_time_of_impact,
    step_kernels,
    touching_memory,
)
from collisionlab.engine.params import WorldParams
from collisionlab.engine.world import World
from collisionlab.scenario_file import parse_scenario

# 40 balls dropped between four walls onto a tilted floor: impacts, settling and rests in every step.
HEAP_OF_BALLS = """
[simulation]
dt = 0.005
steps = 80
restitution = 0.5
gravity = [0, -9.81, 0]
mode = "exact"

[[gas]]
name = "ball"
shape = "sphere"
radius = 0.05
region = [[-0.4, 0.1, -0.4], [0.4, 0.5, 0.4]]
count = 40
kT = 0.01
seed = 3

[[static]]
name = "floor"
shape = "plane"
point = [0, 0, 0]
normal = [0.2, 1, 0]

[[static]]
name = "left"
shape = "plane"
point = [-0.5, 0, 0]
normal = [1, 0, 0]

[[static]]
name = "right"
shape = "plane"
point = [0.5, 0, 0]
normal = [-1, 0, 0]

[[static]]
name = "back"
shape = "plane"
point = [0, 0, -0.5]
normal = [0, 0, 1]

[[static]]
name = "front"
shape = "plane"
point = [0, 0, 0.5]
normal = [0, 0, -1]
"""


#: The Forward Euler stepper's files: the loop and one file per concept it calls (the exact stepper
#: calls most of them too).
EULER_FILES = (
    non_literal,
    pair_separation,
    broad_phase_grid,
    broad_phase_pairs,
    contact_order,
    touching_memory,
    event_rows,
    euler_impulses,
    euler_push_apart,
    euler_clamps,
    step_kernels,
)

#: The exact stepper's files: the loop and one file per concept it calls.
EXACT_FILES = (
    exact_flight,
    pair_time_of_impact,
    exact_impulses,
    exact_rest,
    exact_settle,
    exact_step_end,
    exact_sweeps,
    exact_impacts,
    exact_kernels,
)


@pytest.mark.parametrize("module", [geometry_kernels, *EULER_FILES, *EXACT_FILES])
def test_every_helper_named_for_the_compiler_is_a_function_of_its_module(module: types.ModuleType) -> None:
    inline = set(getattr(module, "INLINE", ()))
    no_refcount = set(getattr(module, "NO_REFCOUNT", ()))
    assert not inline & no_refcount  # an inlined body is compiled as its caller is
    for name in inline | no_refcount:  # a misspelt name would silently compile the default way
        assert isinstance(getattr(module, name, None), types.FunctionType), name


def test_the_loop_file_gives_the_world_the_numbers_it_reads() -> None:
    """A world reads the cap of impacts per step (its warning) and the counters from the stepper's
    entry, exact_kernels, as from the contact stepper's, in both forms; the phases' files own them."""
    for kernels in (exact_kernels, compiled.exact_kernels()):
        assert kernels.MAX_IMPACTS_PER_STEP == exact_impacts.MAX_IMPACTS_PER_STEP
        assert kernels.RELAX_IMPULSES > 0 and kernels.STATUS_SIZE == 4


def test_the_compiled_phases_take_no_reference_counts_and_the_driver_does() -> None:
    kernels = compiled.exact_kernels()
    phases = []
    for module in EXACT_FILES:
        compiled_file = compiled._module(module.__name__.rpartition(".")[2])
        for name in getattr(module, "NO_REFCOUNT", ()):
            assert getattr(compiled_file, name).targetoptions.get("_nrt") is False, name
            phases.append(name)
    assert {"_rest_passes", "_predict_all", "_impacts", "_end_separations"} <= set(phases)  # the phases are named
    assert kernels.run_exact_steps.targetoptions.get("_nrt", True) is True  # it allocates


def _filled_heap(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, int, np.ndarray]:
    """A full heap of entries for 2 * 30 keys, several versions per key (the highest current)."""
    rng = np.random.default_rng(seed)
    count = 30
    capacity = exact_impacts.HEAP_ROOM * count + 2
    ht, hk, hv = np.zeros(capacity), np.zeros(capacity, np.int64), np.zeros(capacity, np.int64)
    ver = np.zeros(2 * count, np.int64)
    size = 0
    while size < capacity:
        key = int(rng.integers(0, 2 * count))
        ver[key] += 1  # each push takes a new version, as the stepper's do
        when = float(rng.choice([0.25, 0.5, rng.random()]))  # ties in time too
        size = event_heap.heap_push(ht, hk, hv, size, when, key, int(ver[key]))
    return ht, hk, hv, size, ver


@pytest.mark.parametrize("seed", range(10))
def test_a_full_heap_compacts_in_place_to_its_current_entries_in_time_order(seed: int) -> None:
    ht, hk, hv, size, ver = _filled_heap(seed)
    current = sorted((ht[i], hk[i]) for i in range(size) if hv[i] == ver[hk[i]])
    arrays = (ht, hk, hv)
    size = event_heap.heap_compact(ht, hk, hv, size, ver)
    assert size == len(current) <= ht.shape[0] // 2  # room for half the heap again
    assert all(a is b for a, b in zip(arrays, (ht, hk, hv), strict=True))  # nothing new allocated
    popped = []
    while size > 0:
        popped.append((ht[0], hk[0]))
        assert hv[0] == ver[hk[0]]
        size = event_heap.heap_pop(ht, hk, hv, size)
    assert popped == current  # oracle: sorting by (time, key)


def test_a_heap_with_room_is_left_as_it_is() -> None:
    ht, hk, hv, size, ver = _filled_heap(0)
    size = event_heap.heap_pop(ht, hk, hv, size)
    before = (ht.copy(), hk.copy(), hv.copy())
    assert event_heap.heap_compact(ht, hk, hv, size, ver) == size
    assert all(np.array_equal(a, b) for a, b in zip(before, (ht, hk, hv), strict=True))


def test_the_events_buffer_grows_only_when_short_of_room_and_keeps_its_rows() -> None:
    events = np.arange(10.0 * event_rows.EVENT_COLUMNS).reshape(10, event_rows.EVENT_COLUMNS)
    assert event_rows._events_with_room(events, 6, 4) is events  # rows 6-9 are free
    grown = event_rows._events_with_room(events, 6, 5)
    assert grown.shape == (36, event_rows.EVENT_COLUMNS)  # 2 * 10 + 16, at least 6 + 5
    assert np.array_equal(grown[:10], events) and not grown[10:].any()
    assert event_rows._events_with_room(events, 6, 100).shape[0] == 106


def _run(text: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    world = World(parse_scenario(tomllib.loads(text)), WorldParams(compiled=False))  # the Python form: patchable
    world.step(world.scenario.settings.steps)
    stepper = world.stepper
    return world.position_array.copy(), world.velocity_array.copy(), stepper.events().copy(), stepper.ledger.copy()


def test_a_run_is_the_same_when_the_events_buffer_has_only_just_room(monkeypatch: pytest.MonkeyPatch) -> None:
    roomy = _run(HEAP_OF_BALLS)
    returns: list[int] = []
    impacts = exact_impacts._impacts

    def counted(*args: Any) -> tuple[int, ...]:
        result: tuple[int, ...] = impacts(*args)
        returns.append(result[0])
        return result

    def just_room(events: np.ndarray, used: int, room: int) -> np.ndarray:
        if events.shape[0] - used >= room:
            return events
        grown = np.zeros((used + room, events.shape[1]))  # not a row more
        grown[: min(used, events.shape[0])] = events[:used]
        return grown

    monkeypatch.setattr(exact_impacts, "_impacts", counted)
    monkeypatch.setattr(event_rows, "_events_with_room", just_room)
    tight = _run(HEAP_OF_BALLS)
    assert returns.count(exact_impacts.ROOM) > 10  # the impacts stopped for room, and went on
    assert roomy[2].shape[0] > 100  # events enough to matter
    for a, b in zip(roomy, tight, strict=True):
        assert np.array_equal(a, b)


@pytest.mark.parametrize("compiled_form", [False, True])
def test_a_body_kicked_past_its_own_sweep_has_the_candidates_listed_again(compiled_form: bool) -> None:
    """Each body is listed for its own speed bound (SWEEP_GROWTH times its speed relative to the
    frame of the middle velocity, at least SWEEP_FLOOR of the fastest's). A kick past it cuts the
    step and lists again, or a pair it reaches would be missed.

    Along x, radius 0.5, e = 1, dt = 0.01, no gravity: A (x = 0, v = 10) hits B (x = 1.001)
    at t1 = 0.001 / 10 = 1e-4; B touches C (x = 2.001), which takes the impulse on: C leaves at
    10. D (x = 3.111, v = -2) is 0.11 from C. A far body E (v = -10) puts the frame at v = 0,
    so U = 10: C and D are listed for max(0.5 U, 2 |v|) = 5 each, a sweep of 0.05 + 0.05 = 0.1
    in the step, under their 0.11. C then closes on D at 12: at t1 D is 0.11 - 2 t1 = 0.1098
    away, met at t1 + 0.1098 / 12 = 0.00925, inside the first step."""
    from collisionlab import Sphere
    from collisionlab.model import Body, Scenario, Settings

    def ball(name: str, x: float, v: float) -> Body:
        return Body(name, Sphere((x, 0, 0), 0.5), velocity=(v, 0, 0))

    bodies = (ball("A", 0.0, 10.0), ball("B", 1.001, 0.0), ball("C", 2.001, 0.0), ball("D", 3.111, -2.0))
    scenario = Scenario(
        Settings(dt=0.01, steps=1, restitution=1.0, mode="exact"), (*bodies, ball("E", 100.0, -10.0)), ()
    )
    world = World(scenario, WorldParams(compiled=compiled_form))
    record = world.run()
    hits = {tuple(e.bodies): e.time for e in record.events}
    t1 = 0.001 / 10.0
    assert hits[("A", "B")] == pytest.approx(t1, abs=1e-12)
    assert hits[("C", "D")] == pytest.approx(t1 + (0.11 - 2.0 * t1) / 12.0, abs=1e-9)
    status = world._stepper.status  # type: ignore[union-attr]
    assert status[2] >= 1  # the step was cut and the candidates listed again
    assert status[3] == 1 + exact_sweeps.SWEEP_PAUSE  # and every body has the widest sweep for a while
