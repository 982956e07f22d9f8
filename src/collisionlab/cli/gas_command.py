"""``collisionlab gas``: a gas of many balls as a scenario, run on the engine's world, with its speed.

Thin: it parses, builds the scenario (:meth:`collisionlab.particles.GasScenario.scenario`, the
benchmark's gas, for the time-stepped world; :meth:`collisionlab.edmd.observables.ExactGas.scenario`
with ``--mode exact``, run event by event), times :meth:`World.advance
<collisionlab.engine.world.World.advance>`, and prints (a table or one JSON object) and plots.
No physics here. This file holds the options and the time-stepped run; ``gas_exact.py`` the
event-driven one (mixtures, checkpoints), ``gas_text.py`` the report, ``gas_common.py`` what
they share.
"""

from __future__ import annotations

import argparse
from typing import Any

from .. import limits
from ..engine import WorldParams
from ..engine.ahead import KERNEL_CHOICES
from ..engine.world import World
from ..errors import InvalidInputError, OutOfRangeError
from ..particles import BACKENDS, gas_scenario
from ..particles.scenarios import SPEED_DISTRIBUTIONS
from .gas_common import (
    DEFAULT_FRAMES,
    FLAGS,
    GIVEN,
    PROG,
    bad_value,
    kernels_choice,
    no_memory,
    open_trajectory,
    trajectory_checked,
    warn_if_gaining,
)
from .gas_exact import run_exact
from .gas_text import emit_report, stepped_table
from .interrupts import ChunkWatch, interruptible, interrupts_for
from .progress import ProgressBar
from .streams import Streams

__all__ = ["add_parser", "run"]

#: ``--mode``: the time-stepped world (default) or the event-driven, exact one.
_MODES = ("stepped", "exact")
#: ``--boundary``: ``collisionlab.edmd.observables.BOUNDARIES``, spelled out so that the command
#: line starts without importing numba (tests/test_edmd_cli.py checks the two agree).
BOUNDARIES = ("walls", "periodic")


def _remember(namespace: argparse.Namespace, dest: str) -> None:
    setattr(namespace, GIVEN, frozenset(getattr(namespace, GIVEN, frozenset())) | {dest})


class _Store(argparse._StoreAction):
    """``store``, remembering that the option was given (``--resume`` compares it)."""

    def __call__(self, parser: Any, namespace: argparse.Namespace, values: Any, option: str | None = None) -> None:
        super().__call__(parser, namespace, values, option)
        _remember(namespace, self.dest)


class _Append(argparse._AppendAction):
    """``append``, remembering that the option was given (``--resume`` compares it)."""

    def __call__(self, parser: Any, namespace: argparse.Namespace, values: Any, option: str | None = None) -> None:
        super().__call__(parser, namespace, values, option)
        _remember(namespace, self.dest)


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
    parser.add_argument("--n", type=int, action=_Store, default=10_000, help="number of balls (default 10000)")
    parser.add_argument("--dim", type=int, action=_Store, default=2, help="2 (discs) or 3 (spheres); default 2")
    parser.add_argument("--steps", type=int, default=1000, help="steps to run (default 1000)")
    parser.add_argument("--seed", type=int, action=_Store, default=0, help="seed of the velocities (default 0)")
    parser.add_argument(
        "--restitution", type=float, action=_Store, default=1.0, help="e >= 0 (default 1: elastic; > 1 adds energy)"
    )
    parser.add_argument(
        "--gravity",
        action=_Store,
        type=float,
        default=0.0,
        help="acceleration along -y, radii per time unit^2 (default 0)",
    )
    parser.add_argument(
        "--speeds",
        choices=SPEED_DISTRIBUTIONS,
        default="gaussian",
        help="initial speeds: gaussian (Maxwell-Boltzmann already) or equal (watch them relax)",
    )
    parser.add_argument(
        "--kernels",
        choices=KERNEL_CHOICES,
        default=None,
        help="the kernels' form: compiled (numba; auto means it: a gas is large) or python (far slower); "
        "loaded, or compiled once per machine, before the clock starts",
    )
    parser.add_argument(
        "--backend", choices=BACKENDS, default=None, help="the older name of --kernels (numba: compiled)"
    )
    parser.add_argument(
        "--plot",
        metavar="FILE.png",
        help="write the speed distribution against Maxwell-Boltzmann; with --mode exact, the last frame "
        "(each species its colour) beside each species' speeds (.png, .svg, .pdf or .gif)",
    )
    parser.add_argument("--format", choices=("table", "json"), default="table", help="output (default table)")
    parser.add_argument(
        "--trajectory",
        metavar="FILE",
        help="write frames to FILE.gsd (HOOMD's GSD; the 'trajectory' extra) or FILE.xyz (extended XYZ): "
        "positions, velocities, diameters, types, the box, the step (exact mode: the frame's index)",
    )
    parser.add_argument(
        "--frames",
        type=int,
        default=None,
        metavar="K",
        help=f"with --trajectory: K frames at the times T k/(K-1), k = 0..K-1, T the run's end (the start and the "
        f"end; K = 1: the end only; default {DEFAULT_FRAMES}); stepped mode: K-1 must divide --steps",
    )
    exact = parser.add_argument_group("exact mode (--mode exact: event-driven, no time step)")
    exact.add_argument(
        "--mode", action=_Store, choices=_MODES, default="stepped", help="stepped (default) or exact (event-driven)"
    )
    exact.add_argument(
        "--boundary", action=_Store, choices=BOUNDARIES, default="walls", help="walls (default) or periodic"
    )
    exact.add_argument(
        "--fraction", action=_Store, type=float, default=0.2, help="area (volume) fraction (default 0.2)"
    )
    exact.add_argument(
        "--time",
        action=_Store,
        type=float,
        default=10.0,
        help="simulated time (default 10; radius 1, kT 1); with --resume the total time to reach (default: the "
        "resumed run's own)",
    )
    exact.add_argument(
        "--tc",
        action=_Store,
        type=float,
        default=None,
        help="TC model: a collision sooner than this after the last is elastic",
    )
    exact.add_argument("--events", metavar="FILE", help="stream every collision to FILE.csv or FILE.jsonl")
    exact.add_argument(
        "--species",
        action=_Append,
        metavar="NAME:FRACTION:RADIUS[:MASS]",
        help="a mixture: one species (repeat for each), FRACTION of the balls by number, its RADIUS and MASS "
        "(default radius^dim: a ball of radius 1 weighs 1); --fraction is then the packing fraction of all",
    )
    exact.add_argument(
        "--checkpoint",
        metavar="FILE",
        help="save the run's whole state to FILE (atomically) every --checkpoint-every T and at the end; "
        "--resume FILE continues it",
    )
    exact.add_argument(
        "--checkpoint-every",
        type=float,
        default=None,
        metavar="T",
        help="with --checkpoint: simulated time between two checkpoints (default: at the end only)",
    )
    exact.add_argument(
        "--resume",
        metavar="FILE",
        help="continue the run saved in FILE (--checkpoint) to the total simulated time --time, ending as the "
        "run done in one go would, to the last bit; saves to FILE again unless --checkpoint names another",
    )
    exact.add_argument(
        "--observe",
        metavar="LIST",
        help="structure and transport, a comma list of rdf (g(r) per species pair, its contact value and Z from it) "
        "and msd (mean-squared displacement, self-diffusion and Enskog's); periodic box only; with --checkpoint "
        "the observation is saved too, and --resume goes on observing (its own --observe, --samples and --time)",
    )
    exact.add_argument(
        "--samples",
        type=int,
        default=None,
        metavar="K",
        help="with --observe: samples at equal times over the run's last 80 percent (default 100)",
    )
    parser.add_argument("--quiet", action="store_true", help="no progress bar and no notes on stderr")
    parser.set_defaults(func=run, **{GIVEN: frozenset()})


def run(args: argparse.Namespace, streams: Streams) -> int:
    """Run ``collisionlab gas``: 0 done, 2 a bad value (one line naming the flag), 1 a failure,
    65 a checkpoint that cannot be continued (``--resume``) or a run out of range."""
    if args.mode == "exact" or args.resume is not None:
        return run_exact(args, streams)
    for name in ("checkpoint", "checkpoint_every"):
        if getattr(args, name) is not None:
            streams.err(f"{PROG}: {FLAGS[name]}: needs --mode exact (the event-driven gas)")
            return 2
    if args.species:
        streams.err(f"{PROG}: --species: needs --mode exact (the stepped gas holds balls of one radius and mass)")
        return 2
    from ..trajectory import Types, advance_in_frames, frame_steps

    notes = not args.quiet
    try:
        steps = limits.steps(args.steps, "steps")
        restitution = limits.restitution(args.restitution, "restitution")
        gravity = limits.within(args.gravity, "gravity", 0.0, limits.MAX_ACCELERATION)
        if args.plot is not None:
            from ..plotting import check_plot_path  # matplotlib loads only when a plot is asked for

            check_plot_path(args.plot)
        frames = trajectory_checked(args)
        if frames:
            frame_steps(steps, frames)  # K - 1 must divide the steps
        gas = gas_scenario(args.n, args.dim, args.seed, speeds=args.speeds)
        compiled = kernels_choice(args) != "python"  # auto: compiled (numba is installed with the package)
        world = World(
            gas.scenario(steps, restitution, gravity),
            WorldParams(compiled=compiled),
            notify=streams.err if notes else None,
            events=False,
        )
    except InvalidInputError as err:
        return bad_value(streams, err)
    except MemoryError:
        return no_memory(streams, args.n)
    warn_if_gaining(streams, restitution)
    compile_seconds = interruptible(world.load_kernels)  # before the clock: compiling is not stepping
    if notes and not world.compiled:  # a first user may not know how much slower it is
        streams.err(f"{PROG}: stepping with the kernels' Python form: far slower than numba (Ctrl-C stops it)")
    energy_start = world.kinetic_energy()
    bar = ProgressBar(streams, label="gas steps")
    try:
        with interrupts_for(world.compiled) as pending:  # compiled: looked for while a chunk runs too
            watch = ChunkWatch(pending, bar if notes else None)
            if frames:
                with open_trajectory(args, (gas.side,) * gas.dim, False, Types.one_kind(gas.n, gas.radius)) as write:
                    seconds = advance_in_frames(world, steps, frames, write, watch.between, watch.call)
            else:
                seconds = world.advance(steps, watch.between, calling=watch.call)
    except OutOfRangeError as err:
        streams.err(f"{PROG}: {err}")
        return 65
    except OSError as err:
        if not frames:
            raise
        streams.err(f"{PROG}: --trajectory: cannot write {args.trajectory}: {err.strerror or err}")
        return 1
    finally:
        bar.close()
    energy_end = world.kinetic_energy()
    body_impulses, wall_impulses = world.impulses()
    report: dict[str, Any] = {
        "n": gas.n,
        "dim": gas.dim,
        "steps": steps,
        "compile_seconds": compile_seconds,
        "seconds": seconds,
        "body_steps_per_s": gas.n * steps / seconds if seconds > 0 else None,
        "collisions": body_impulses,
        "wall_collisions": wall_impulses,
        "energy_drift": (energy_end - energy_start) / energy_start if energy_start > 0 else 0.0,
        "kinetic_energy_start": energy_start,
        "kinetic_energy_end": energy_end,
        "dt": gas.dt,
        "seed": args.seed,
        "restitution": restitution,
        "gravity": args.gravity,
        "backend": "numba" if world.compiled else "python",
        "bytes_per_body": world.nbytes() / gas.n,
    }
    if frames:
        report["trajectory"], report["trajectory_frames"] = args.trajectory, frames
    if args.plot is not None:
        try:
            from ..plotting.speeds import save_speed_plot

            save_speed_plot(args.plot, gas.velocities, world.velocity_array[:, : gas.dim], restitution, steps)
        except OSError as err:
            streams.err(f"{PROG}: --plot: cannot write {args.plot}: {err.strerror or err}")
            return 1
        report["plot"] = args.plot
    return emit_report(args, streams, report, stepped_table)
