"""What a run measures: pressure from the collision virial and from the walls, collision rate,
temperature, energy drift, overlap, of the exact gas behind ``collisionlab gas --mode exact``
(:mod:`.exact_gas`, whose names are importable from here too).

For hard bodies the force is a sum of impulses, so the virial theorem gives the pressure from
the collisions themselves (Allen and Tildesley, *Computer Simulation of Liquids*, 2nd ed.,
eq. 2.69 and section 3.7.2; Smallenburg 2022, eq. 7):

    Z = P V / (N kT) = 1 + W / (d N kT t),   W = sum over collisions of r_ij . dp_i,

with ``d`` the dimension and ``t`` the time simulated. With walls the pressure is also the
momentum given to the walls per unit area and time, ``P = sum_w J_w / A_w / (2 d t)`` (the
mean over the ``2 d`` walls); near walls the density is not the bulk density, so the two
routes differ by a surface term of order ``sigma / L``. ``kT = 2 E_kin / (d N)`` at the end.

A mixture (:class:`Species`) reports the same, and per species ``kT_a = sum_a m v^2 / (d N_a)``
(equipartition: every species at the same ``kT``), and per ordered pair of species ``(a, b)``
how often one ball of ``a`` hits a ball of ``b``, beside Enskog's rate
(:func:`.theory.enskog_pair_rates`); ``Z`` against BMCSL (3D) or Santos, Yuste and Lopez de
Haro's equation (2D), :func:`.theory.mixture_compressibility`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InvalidInputError
from .exact_gas import (  # also importable from here, as before
    BOUNDARIES,
    DEFAULT_TC,
    FRACTION_SUM_TOLERANCE,
    FRAMES,
    SPECIES_FORM,
    ExactGas,
    Species,
    parse_species,
    species_counts,
)
from .species_report import species_report
from .theory import enskog_collision_rate, ideal_compressibility
from .world import EventDrivenWorld, EventSink

if TYPE_CHECKING:
    from ..engine.world import World
    from ..trajectory import FrameWriter, Types
    from .observer import Observer

__all__ = [
    "BOUNDARIES",
    "DEFAULT_TC",
    "FRACTION_SUM_TOLERANCE",
    "FRAMES",
    "SPECIES_FORM",
    "Checkpointer",
    "ExactGas",
    "Species",
    "frame_times",
    "measure",
    "observer_for",
    "parse_species",
    "run_end",
    "run_exact_gas",
    "run_on_world",
    "species_counts",
    "species_report",
    "trajectory_types",
]

#: A mixture's calls of the loop: each runs at least this long (then Python looks at progress
#: and signals), the steps of one call doubling until it does.
CHUNK_SECONDS = 0.05


def measure(world: EventDrivenWorld, energy_start: float, seconds: float) -> dict[str, Any]:
    """The observables of ``world`` after a run from time 0 (see the module's docstring)."""
    tally = world.tally()
    n, dim, t = world.n, world.dim, tally.time
    kinetic = world.kinetic_energy()
    energy = kinetic + world.potential_energy()
    kt = 2.0 * kinetic / (dim * n)
    volume = float(world.sides.prod())
    nkt = n * kt
    report: dict[str, Any] = {
        "sim_time": t,
        "collisions": tally.pair_collisions,
        "wall_collisions": tally.wall_collisions,
        "events": tally.events,
        "seconds": seconds,
        "collisions_per_s": tally.pair_collisions / seconds if seconds > 0 else None,
        "kT": kt,
        "compressibility": 1.0 + tally.virial / (dim * nkt * t) if nkt > 0 and t > 0 else None,
        "collision_rate": 2.0 * tally.pair_collisions / (n * t) if t > 0 else 0.0,
        "energy_drift": (energy - energy_start) / energy_start if energy_start != 0 else 0.0,
        "energy_lost_in_collisions": tally.energy_lost,
        # in diameters: of the smallest ball in a mixture
        "max_overlap": max(tally.max_contact_overlap, world.max_overlap())
        / (2.0 * (float(world.radii.min()) if world.mixed else world.radius)),
        "bytes_per_body": world.nbytes / n,
    }
    if not world.periodic:
        pressures = [
            tally.wall_momentum[w] / (volume / float(world.sides[w // 2])) / t if t > 0 else 0.0 for w in range(2 * dim)
        ]
        pressure = sum(pressures) / len(pressures)
        report["compressibility_walls"] = pressure * volume / nkt if nkt > 0 else None
        report["wall_momentum"] = list(tally.wall_momentum)
    return report


def run_exact_gas(
    gas: ExactGas,
    world: World | None = None,
    between: Callable[[int, int], None] | None = None,
    frames: int = 0,
    write_frame: FrameWriter | None = None,
    calling: Callable[[Callable[[], None]], None] | None = None,
    sink: EventSink | None = None,
    balls: EventDrivenWorld | None = None,
) -> dict[str, Any]:
    """Run ``gas`` on the engine's world (``world``, fresh from ``World(gas.scenario())``, or one
    made now) for ``gas.time`` and report: the JSON of ``collisionlab gas --mode exact``.
    ``between(done, total)`` is called between chunks of steps (progress, Ctrl-C). With
    ``write_frame``, ``frames`` frames at equal times are written through it
    (:func:`collisionlab.trajectory.advance_in_frames`: ``frames - 1`` must divide the
    scenario's steps, see :func:`~collisionlab.trajectory.steps_for_frames`). ``calling`` makes
    each compiled call (:meth:`World.advance <collisionlab.engine.world.World.advance>`).

    A mixture (``gas.species``) runs on its :class:`EventDrivenWorld` alone, the same loop
    (its report, pair rates and theory, is the world's own): ``world`` does not apply,
    ``balls`` is its world if made already (fresh from ``gas.world()``), ``sink`` receives its
    collisions (:meth:`EventDrivenWorld.run`'s blocks; the engine's world streams a scenario's
    itself), and ``frames`` frames are written at the times :func:`frame_times` (``write_frame``
    made for :func:`trajectory_types`)."""
    from ..engine.event_stepper import EventDrivenStepper
    from ..engine.world import World

    gas = gas.checked()
    if gas.species:
        world_of_balls = gas.world() if balls is None else balls
        return run_on_world(gas, world_of_balls, between, calling, sink, frames=frames, write_frame=write_frame)
    world = World(gas.scenario(), events=False) if world is None else world
    stepper = world.stepper
    if not isinstance(stepper, EventDrivenStepper):
        raise InvalidInputError("world", "must run the gas event by event (a world of gas.scenario())")
    balls = stepper.world
    energy_start = balls.kinetic_energy() + balls.potential_energy()
    remaining = world.scenario.settings.steps - world.step_index
    if write_frame is not None and frames > 0:
        from ..trajectory import advance_in_frames

        seconds = advance_in_frames(world, remaining, frames, write_frame, between, calling)
    else:
        seconds = world.advance(remaining, between, calling=calling)
    report: dict[str, Any] = _settings_report(gas)
    report.update(measure(balls, energy_start, seconds))
    report["bytes_per_body"] = world.nbytes() / gas.n
    elastic_gas = gas.restitution == 1.0 and gas.gravity == 0.0
    report["compressibility_theory"] = ideal_compressibility(gas.fraction, gas.dim) if elastic_gas else None
    report["collision_rate_enskog"] = (
        enskog_collision_rate(gas.fraction, gas.dim, gas.radius, gas.mass, report["kT"]) if elastic_gas else None
    )
    return report


def run_end(time: float) -> float:
    """The time a run of ``time`` ends at: :data:`FRAMES` steps of ``time / FRAMES``, as the
    engine steps a scenario (it may differ from ``time`` in the last bit)."""
    return FRAMES * (time / FRAMES)


#: Saves a run: called with the total energy at time 0 and the loop's seconds so far, between
#: two calls of the loop (the world as stored, never brought to one time before it).
Checkpointer = Callable[[float, float], None]


def frame_times(time: float, frames: int) -> list[float]:
    """The times of ``frames`` trajectory frames over a run of ``time`` on an event-driven world
    (:func:`run_on_world`): ``end k / (frames - 1)``, ``k = 0 .. frames - 1``, ``end`` the run's
    :func:`run_end` (the last one exactly); one frame: the end.

    >>> frame_times(2.0, 5), frame_times(2.0, 1)
    ([0.0, 0.5, 1.0, 1.5, 2.0], [2.0])
    """
    end = run_end(time)
    if frames <= 1:
        return [end]
    return [end * k / (frames - 1) for k in range(frames - 1)] + [end]


def trajectory_types(gas: ExactGas) -> Types:
    """The balls of a checked ``gas`` as a trajectory names them
    (:class:`collisionlab.trajectory.Types`): a mixture's species in the order given, each ball
    its own; one kind of ball: type ``A`` of :attr:`ExactGas.radius`."""
    from ..trajectory import Types

    if not gas.species:
        return Types.one_kind(gas.n, gas.radius)
    kinds, radii, _, _ = gas.mixture()
    return Types(tuple(sp.name for sp in gas.species), kinds.astype(np.int64), radii)


def run_on_world(
    gas: ExactGas,
    balls: EventDrivenWorld,
    between: Callable[[int, int], None] | None = None,
    calling: Callable[[Callable[[], None]], None] | None = None,
    sink: EventSink | None = None,
    *,
    energy_start: float | None = None,
    seconds: float = 0.0,
    every: float | None = None,
    checkpoint: Checkpointer | None = None,
    observer: Observer | None = None,
    frames: int = 0,
    write_frame: FrameWriter | None = None,
) -> dict[str, Any]:
    """Run a checked ``gas`` (one kind of ball or a mixture) on its :class:`EventDrivenWorld`
    ``balls`` from its present time to :func:`run_end` of ``gas.time``, in calls ending at the
    ``FRAMES`` step ends of ``time / FRAMES`` (as the engine steps a scenario: the same
    result, to the last bit) of at least :data:`CHUNK_SECONDS` each, then measure it: the
    report of :func:`run_exact_gas`.

    A run continued from a checkpoint passes its ``energy_start`` (the total energy at time 0;
    ``None``: the world is fresh, at time 0) and the loop's ``seconds`` so far. ``checkpoint``
    is called at every multiple of ``every`` (simulated time) before the end, and at the end,
    before anything is measured (measuring brings the bodies to one time). Where the calls of
    the loop end does not change the run (:meth:`EventDrivenWorld.run`), so a run checkpointed
    or not, or continued from any of its checkpoints, ends the same to the last bit.

    ``observer`` (:class:`.observer.Observer`, made for this world and run) is stopped at as
    it asks (its samples, and the stops that unwrap positions between them), which does not
    change the run either; its fields (``rdf``, ``msd``, ...) join the report.

    ``write_frame`` (:class:`collisionlab.trajectory.FrameWriter`) is given ``frames`` frames,
    at the times :func:`frame_times` (step: the frame's index; each ball where :meth:`state`
    puts it), stopping there as the observer does: the run is the same with them or without."""
    import time

    from .guard import RunGuard

    guard = RunGuard(balls)
    if energy_start is None:
        energy_start = balls.kinetic_energy() + balls.potential_energy()  # (at time 0: moves nothing)
    dt = gas.time / FRAMES
    end = run_end(gas.time)
    now = balls.time
    if end < now:
        raise InvalidInputError("time", f"must be at least the run's present time {now!r}", got=gas.time)
    done = min(FRAMES, max(0, int(now // dt)))  # step ends passed already
    while done < FRAMES and (done + 1) * dt <= now:
        done += 1
    interval = math.inf if every is None or checkpoint is None else every
    saves = math.floor(now / interval) + 1 if math.isfinite(interval) else 1  # the next at saves * interval
    while saves * interval <= now:
        saves += 1
    stops = frame_times(gas.time, frames) if write_frame is not None and frames > 0 else []
    shot = 0  # frames written
    while shot < len(stops) and stops[shot] <= now:  # (a fresh world: the start's)
        assert write_frame is not None
        write_frame(shot, balls.time, *balls.state())
        shot += 1
    chunk = 1
    while done < FRAMES:
        step = min(chunk, FRAMES - done)
        until = (done + step) * dt
        save = saves * interval <= until and saves * interval < end
        if save:
            until = saves * interval
        look = observer is not None and observer.next_stop() <= until
        if observer is not None and look:
            until = observer.next_stop()
            save = save and saves * interval <= until
        shoot = shot < len(stops) and stops[shot] <= until
        if shoot:
            until = stops[shot]
            save = save and saves * interval <= until
            look = look and observer is not None and observer.next_stop() <= until

        def work(until: float = until) -> None:
            balls.run(until, sink, bring=False, between=guard, every=guard.every)

        started = time.perf_counter()
        if calling is None:
            work()
        else:
            calling(work)
        took = time.perf_counter() - started
        seconds += took
        if until == (done + step) * dt:
            done += step
        if observer is not None and look:
            observer.stop()
        if shoot and write_frame is not None:
            write_frame(shot, balls.time, *balls.state())
            shot += 1
        if save and checkpoint is not None:  # (a finite interval: there is one)
            checkpoint(energy_start, seconds)
            saves += 1
        if between is not None:  # after every call, a checkpoint's too: signals are looked at here
            between(done, FRAMES)
        if took < CHUNK_SECONDS:
            chunk *= 2
    if checkpoint is not None:
        checkpoint(energy_start, seconds)
    report: dict[str, Any] = _settings_report(gas)
    report.update(measure(balls, energy_start, seconds))
    elastic_gas = gas.restitution == 1.0 and gas.gravity == 0.0
    if gas.species:
        report.update(species_report(gas, balls, report["kT"]))
    else:  # as run_exact_gas reports one kind of ball
        report["compressibility_theory"] = ideal_compressibility(gas.fraction, gas.dim) if elastic_gas else None
        report["collision_rate_enskog"] = (
            enskog_collision_rate(gas.fraction, gas.dim, gas.radius, gas.mass, report["kT"]) if elastic_gas else None
        )
    if observer is not None:
        one_kind = elastic_gas and not gas.species
        report.update(observer.report(report["kT"], gas.fraction, gas.mass if one_kind else None))
    return report


def observer_for(gas: ExactGas, balls: EventDrivenWorld, observe: tuple[str, ...], samples: int) -> Observer:
    """An :class:`.observer.Observer` of ``observe`` (names of
    :data:`.structure.OBSERVABLES`) for a checked ``gas`` run on its fresh world ``balls``:
    ``samples`` equal times to the run's end, the species named as given (one kind: ``A``)."""
    from .observer import Observer

    if gas.species:
        kinds = gas.mixture()[0]
        names = [sp.name for sp in gas.species]
    else:
        kinds, names = np.zeros(gas.n, dtype=np.int64), ["A"]
    return Observer(balls, run_end(gas.time), samples, "rdf" in observe, "msd" in observe, kinds, names)


def _settings_report(gas: ExactGas) -> dict[str, Any]:
    """The head of a gas run's report: the settings it ran with."""
    return {
        "n": gas.n,
        "dim": gas.dim,
        "fraction": gas.fraction,
        "mode": "exact",
        "boundary": gas.boundary,
        "seed": gas.seed,
        "restitution": gas.restitution,
        "gravity": gas.gravity,
        "tc": gas.tc,
    }
