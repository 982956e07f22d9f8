"""``collisionlab gas``: the many-body particle world on the benchmark's gas, with its speed.

Thin: it parses, builds :func:`collisionlab.particles.gas_scenario`, times
:meth:`~collisionlab.particles.ParticleWorld.step`, and prints (a table or one JSON object) and
plots. With ``--mode exact`` it hands the settings to :func:`collisionlab.edmd.observables.run_exact_gas`
(event-driven, exact) instead. No physics here.
"""

from __future__ import annotations

import argparse
import json
import threading
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from .. import limits
from ..errors import InvalidInputError, OutOfRangeError
from ..particles import BACKENDS, ParticleWorld, gas_scenario, warm_up
from ..particles.scenarios import SPEED_DISTRIBUTIONS
from ..particles.world import StepReport
from .interrupts import Pending, deferred_interrupts
from .progress import SHOW_AFTER, ProgressBar
from .streams import Streams

__all__ = ["add_parser", "run"]

_PROG = "collisionlab gas"
#: Library field name -> the flag a user typed.
_FLAGS = {
    "n": "--n",
    "dim": "--dim",
    "steps": "--steps",
    "seed": "--seed",
    "restitution": "--restitution",
    "gravity": "--gravity",
    "speeds": "--speeds",
    "backend": "--backend",
    "plot": "--plot",
    "fraction": "--fraction",
    "boundary": "--boundary",
    "time": "--time",
    "tc": "--tc",
    "events": "--events",
}
#: ``--mode``: the time-stepped world (default) or the event-driven, exact one.
_MODES = ("stepped", "exact")
#: ``--boundary``: ``collisionlab.edmd.observables.BOUNDARIES``, spelled out so that the command
#: line starts without importing numba (tests/test_edmd_cli.py checks the two agree).
BOUNDARIES = ("walls", "periodic")
#: Seconds of warm-up before the note that the kernels are being compiled (as the progress bar).
_QUIET_SECONDS = SHOW_AFTER
#: Seconds of stepping between two looks at Ctrl-C (a compiled kernel cannot be interrupted):
#: a fraction of a second, so an interrupt stops the run within a second.
CHUNK_SECONDS = 0.1


def add_parser(subparsers: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    """Add the ``gas`` subcommand to ``collisionlab``'s subparsers (sets ``func=run``)."""
    parser = subparsers.add_parser(
        "gas",
        help="a gas of many balls in a box: speed, energy, and the Maxwell-Boltzmann speeds",
        description=(
            "Step N balls of radius 1 at area (volume) fraction 0.2 in a box, from a lattice with "
            "seeded Gaussian velocities, each step moving a typical ball 0.1 radius, and report "
            "the speed. With only --n, --dim and --steps this is the benchmark's scenario."
        ),
    )
    parser.add_argument("--n", type=int, default=10_000, help="number of balls (default 10000)")
    parser.add_argument("--dim", type=int, default=2, help="2 (discs) or 3 (spheres); default 2")
    parser.add_argument("--steps", type=int, default=1000, help="steps to run (default 1000)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the velocities (default 0)")
    parser.add_argument("--restitution", type=float, default=1.0, help="e >= 0 (default 1: elastic; > 1 adds energy)")
    parser.add_argument(
        "--gravity", type=float, default=0.0, help="acceleration along -y, radii per time unit^2 (default 0)"
    )
    parser.add_argument(
        "--speeds",
        choices=SPEED_DISTRIBUTIONS,
        default="gaussian",
        help="initial speeds: gaussian (Maxwell-Boltzmann already) or equal (watch them relax)",
    )
    parser.add_argument("--backend", choices=BACKENDS, default="auto", help="kernels: numba if installed")
    parser.add_argument("--plot", metavar="FILE.png", help="write the speed distribution against Maxwell-Boltzmann")
    parser.add_argument("--format", choices=("table", "json"), default="table", help="output (default table)")
    exact = parser.add_argument_group("exact mode (--mode exact: event-driven, no time step)")
    exact.add_argument("--mode", choices=_MODES, default="stepped", help="stepped (default) or exact (event-driven)")
    exact.add_argument("--boundary", choices=BOUNDARIES, default="walls", help="walls (default) or periodic")
    exact.add_argument("--fraction", type=float, default=0.2, help="area (volume) fraction (default 0.2)")
    exact.add_argument("--time", type=float, default=10.0, help="simulated time (default 10; radius 1, kT 1)")
    exact.add_argument(
        "--tc", type=float, default=None, help="TC model: a collision sooner than this after the last is elastic"
    )
    exact.add_argument("--events", metavar="FILE", help="stream every collision to FILE.csv or FILE.jsonl")
    parser.add_argument("--quiet", action="store_true", help="no progress bar and no notes on stderr")
    parser.set_defaults(func=run)


def _warm_up(streams: Streams, notes: bool) -> None:
    """Compile or load the kernels before timing; say so if it takes a while (first run only)."""
    note = threading.Timer(
        _QUIET_SECONDS, lambda: streams.err("compiling the particle kernels (first run only; cached after)...")
    )
    if notes:
        note.start()
    try:
        warm_up()
    finally:
        note.cancel()


def step_in_chunks(
    world: ParticleWorld,
    dt: float,
    steps: int,
    pending: Pending,
    progress: ProgressBar | None = None,
    clock: Callable[[], float] = time.perf_counter,
) -> StepReport:
    """``world.step(dt, steps)`` in chunks of about ``CHUNK_SECONDS`` (the first chunk is one
    step, then each is sized from the time the last took, at most doubling), checking between
    chunks for an interrupt (``pending``) and that speeds stay in the range that can be
    simulated. With e > 1 each collision adds energy, so the chunks are single steps."""
    done = body = wall = 0
    chunk = 1
    while done < steps:
        count = min(chunk, steps - done)
        began = clock()
        report = world.step(dt, count)
        took = clock() - began
        done += count
        body += report.body_collisions
        wall += report.wall_collisions
        pending.check()
        _check_speeds(world, done)
        if progress is not None:
            progress(done, steps)
        if world.restitution <= 1.0:
            chunk = max(1, min(2 * count, int(count * CHUNK_SECONDS / took) if took > 0 else 2 * count))
    return StepReport(steps, body, wall)


def _check_speeds(world: ParticleWorld, done: int) -> None:
    speeds = np.abs(world.velocities)
    if not (np.all(np.isfinite(speeds)) and speeds.max(initial=0.0) <= limits.MAX_GAS_SPEED):
        raise OutOfRangeError(
            f"the gas at step {done}: speeds grew beyond {limits.MAX_GAS_SPEED:g} (restitution "
            f"{world.restitution:g} > 1 adds energy at every collision): too large to simulate"
        )


def _table(report: dict[str, Any]) -> list[str]:
    shape = "discs" if report["dim"] == 2 else "spheres"
    lines = [
        f"{_PROG}: {report['n']:,} {shape} in {report['dim']}D, {report['steps']:,} steps "
        f"(seed {report['seed']}, e = {report['restitution']:g}, gravity {report['gravity']:g}, "
        f"dt = {report['dt']:.4g})",
        f"  backend          {report['backend']}",
        f"  stepping         {report['seconds']:.3f} s",
        f"  body-steps/s     {report['body_steps_per_s'] / 1e6:.2f} million",
        f"  collisions       {report['collisions']:,} between balls, {report['wall_collisions']:,} with walls",
        f"  energy drift     {report['energy_drift']:.3e} (relative change of kinetic energy)",
        f"  memory           {report['bytes_per_body']:.0f} bytes per ball",
    ]
    if report.get("plot"):
        lines.append(f"  plot             {report['plot']}")
    return lines


def _bad_value(streams: Streams, err: InvalidInputError) -> int:
    streams.err(
        f"{_PROG}: {_FLAGS.get(err.field, err.field)}: {err.problem}"
        + (f" (got {err.got!r})" if err.got is not None else "")
    )
    return 2


def _exact_table(report: dict[str, Any]) -> list[str]:
    shape = "discs" if report["dim"] == 2 else "spheres"
    z_theory = report.get("compressibility_theory")
    lines = [
        f"{_PROG}: {report['n']:,} {shape} in {report['dim']}D, exact (event-driven), {report['boundary']}, "
        f"fraction {report['fraction']:g}, time {report['sim_time']:g} (seed {report['seed']}, "
        f"e = {report['restitution']:g}, gravity {report['gravity']:g})",
        f"  simulation loop  {report['seconds']:.3f} s",
        f"  collisions       {report['collisions']:,} between balls, {report['wall_collisions']:,} with walls"
        + (f" ({report['collisions_per_s'] / 1e6:.3f} million/s)" if report["collisions_per_s"] else ""),
        f"  kT               {report['kT']:.6g}",
        f"  Z = PV/(N kT)    {report['compressibility']:.5f} (collision virial)"
        + (f", theory {z_theory:.5f}" if z_theory is not None else ""),
    ]
    if "compressibility_walls" in report:
        lines.append(f"  Z from walls     {report['compressibility_walls']:.5f} (momentum given to the walls)")
    rate_theory = report.get("collision_rate_enskog")
    lines += [
        f"  collision rate   {report['collision_rate']:.5g} per ball per unit time"
        + (f", Enskog {rate_theory:.5g}" if rate_theory is not None else ""),
        f"  energy drift     {report['energy_drift']:.3e} (relative change of the total energy)",
        f"  max overlap      {report['max_overlap']:.3e} diameters",
        f"  memory           {report['bytes_per_body']:.0f} bytes per ball",
    ]
    if report.get("events_file"):
        lines.append(f"  events           {report['events_file']}")
    return lines


def _run_exact(args: argparse.Namespace, streams: Streams) -> int:
    from ..edmd.events_file import event_file, event_format
    from ..edmd.observables import ExactGas, run_exact_gas

    try:
        if args.plot is not None:
            raise InvalidInputError("plot", "is not available with --mode exact")
        gas = ExactGas(
            n=args.n,
            dim=args.dim,
            fraction=args.fraction,
            boundary=args.boundary,
            time=args.time,
            seed=args.seed,
            restitution=args.restitution,
            gravity=args.gravity,
            tc=args.tc,
        ).checked()
        if args.events is not None:
            event_format(args.events)
        world = gas.world()  # checks the start (and compiles the loop) before any file is opened
    except InvalidInputError as err:
        return _bad_value(streams, err)
    except MemoryError:
        streams.err(f"{_PROG}: --n: not enough memory for {args.n:,} balls")
        return 1
    if gas.restitution > 1.0:
        streams.err(f"warning: restitution {gas.restitution:g} > 1: every collision adds kinetic energy")
    try:
        # The compiled loop cannot be interrupted: Ctrl-C is noted, and looked at between chunks.
        with deferred_interrupts() as pending:
            if args.events is not None:
                with event_file(args.events) as sink:
                    report = run_exact_gas(gas, sink, world, between=pending.check)
                report["events_file"] = args.events
            else:
                report = run_exact_gas(gas, world=world, between=pending.check)
    except OSError as err:
        streams.err(f"{_PROG}: --events: cannot write {args.events}: {err.strerror or err}")
        return 1
    if args.format == "json":
        streams.out(json.dumps(report))
    else:
        for line in _exact_table(report):
            streams.out(line)
    return 0


def run(args: argparse.Namespace, streams: Streams) -> int:
    """Run ``collisionlab gas``: 0 done, 2 a bad value (one line naming the flag), 1 a failure."""
    if args.mode == "exact":
        return _run_exact(args, streams)
    notes = bool(streams.interactive) and not args.quiet
    try:
        steps = limits.steps(args.steps, "steps")
        restitution = limits.restitution(args.restitution, "restitution")
        gravity = limits.within(args.gravity, "gravity", 0.0, limits.MAX_ACCELERATION)
        if args.plot is not None:
            from ..plotting import check_plot_path  # matplotlib loads only when a plot is asked for

            check_plot_path(args.plot)
        scenario = gas_scenario(args.n, args.dim, args.seed, speeds=args.speeds)
        world = scenario.world(restitution=restitution, gravity=gravity, backend=args.backend)
    except InvalidInputError as err:
        return _bad_value(streams, err)
    except MemoryError:
        streams.err(f"{_PROG}: --n: not enough memory for {args.n:,} balls")
        return 1
    if world.restitution > 1.0:
        streams.err(f"warning: restitution {world.restitution:g} > 1: every collision adds kinetic energy")
    if world.backend == "numba":
        _warm_up(streams, notes)
    start_velocities = scenario.velocities
    energy_start = world.kinetic_energy()
    bar = ProgressBar(streams, label="gas steps")
    began = time.perf_counter()
    try:
        with deferred_interrupts() as pending:  # Ctrl-C is checked between chunks of the kernels
            stepped = step_in_chunks(world, scenario.dt, steps, pending, bar if notes else None)
    finally:
        bar.close()
    seconds = time.perf_counter() - began
    energy_end = world.kinetic_energy()
    report: dict[str, Any] = {
        "n": world.n,
        "dim": world.dim,
        "steps": steps,
        "seconds": seconds,
        "body_steps_per_s": world.n * steps / seconds if seconds > 0 else None,
        "collisions": stepped.body_collisions,
        "wall_collisions": stepped.wall_collisions,
        "energy_drift": (energy_end - energy_start) / energy_start if energy_start > 0 else 0.0,
        "kinetic_energy_start": energy_start,
        "kinetic_energy_end": energy_end,
        "dt": scenario.dt,
        "seed": args.seed,
        "restitution": world.restitution,
        "gravity": args.gravity,
        "backend": world.backend,
        "bytes_per_body": world.nbytes / world.n,
    }
    if args.plot is not None:
        try:
            from ..plotting.speeds import save_speed_plot

            save_speed_plot(args.plot, start_velocities, world)
        except OSError as err:
            streams.err(f"{_PROG}: --plot: cannot write {args.plot}: {err.strerror or err}")
            return 1
        report["plot"] = args.plot
    if args.format == "json":
        streams.out(json.dumps(report))
    else:
        for line in _table(report):
            streams.out(line)
    return 0
