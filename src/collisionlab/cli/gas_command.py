"""``collisionlab gas``: a gas of many balls as a scenario, run on the engine's world, with its speed.

Thin: it parses, builds the scenario (:meth:`collisionlab.particles.GasScenario.scenario`, the
benchmark's gas, for the time-stepped world; :meth:`collisionlab.edmd.observables.ExactGas.scenario`
with ``--mode exact``, run event by event), times :meth:`World.advance
<collisionlab.engine.world.World.advance>`, and prints (a table or one JSON object) and plots.
No physics here.
"""

from __future__ import annotations

import argparse
import contextlib
import json
from typing import Any

from .. import limits
from ..engine import WorldParams
from ..engine.ahead import KERNEL_CHOICES, load_kernels
from ..engine.world import World
from ..errors import InvalidInputError, OutOfRangeError
from ..particles import BACKENDS, gas_scenario
from ..particles.scenarios import SPEED_DISTRIBUTIONS
from .interrupts import ChunkWatch, deferred_interrupts, interruptible, interrupts_for
from .progress import ProgressBar
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
    "kernels": "--kernels",
    "plot": "--plot",
    "fraction": "--fraction",
    "boundary": "--boundary",
    "time": "--time",
    "tc": "--tc",
    "events": "--events",
    "trajectory": "--trajectory",
    "frames": "--frames",
    "species": "--species",
    "checkpoint": "--checkpoint",
    "checkpoint_every": "--checkpoint-every",
    "resume": "--resume",
    "observe": "--observe",
    "samples": "--samples",
}
#: ``--mode``: the time-stepped world (default) or the event-driven, exact one.
_MODES = ("stepped", "exact")
#: ``--boundary``: ``collisionlab.edmd.observables.BOUNDARIES``, spelled out so that the command
#: line starts without importing numba (tests/test_edmd_cli.py checks the two agree).
BOUNDARIES = ("walls", "periodic")
#: ``--frames`` when ``--trajectory`` is given alone: the start and every tenth of the run.
_DEFAULT_FRAMES = 11


#: Options of a run's physics and start: a run continued with ``--resume`` takes them from its
#: checkpoint, and refuses one given with another value.
_KEPT_ON_RESUME = ("n", "dim", "fraction", "boundary", "seed", "restitution", "gravity", "tc", "species")
#: The Namespace attribute listing the options typed on the command line (not left at default).
_GIVEN = "given_options"


def _remember(namespace: argparse.Namespace, dest: str) -> None:
    setattr(namespace, _GIVEN, frozenset(getattr(namespace, _GIVEN, frozenset())) | {dest})


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
        f"end; K = 1: the end only; default {_DEFAULT_FRAMES}); stepped mode: K-1 must divide --steps",
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
    parser.set_defaults(func=run, **{_GIVEN: frozenset()})


def _table(report: dict[str, Any]) -> list[str]:
    shape = "discs" if report["dim"] == 2 else "spheres"
    lines = [
        f"{_PROG}: {report['n']:,} {shape} in {report['dim']}D, {report['steps']:,} steps "
        f"(seed {report['seed']}, e = {report['restitution']:g}, gravity {report['gravity']:g}, "
        f"dt = {report['dt']:.4g})",
        f"  backend          {report['backend']}",
        *_compiling(report),
        f"  stepping         {report['seconds']:.3f} s",
        f"  body-steps/s     {report['body_steps_per_s'] / 1e6:.2f} million",
        f"  collisions       {report['collisions']:,} between balls, {report['wall_collisions']:,} with walls",
        f"  energy drift     {report['energy_drift']:.3e} (relative change of kinetic energy)",
        f"  memory           {report['bytes_per_body']:.0f} bytes per ball",
    ]
    if report.get("plot"):
        lines.append(f"  plot             {report['plot']}")
    lines += _trajectory_line(report)
    return lines


def _compiling(report: dict[str, Any]) -> list[str]:
    """The table's line for the time spent loading (or compiling) the kernels, when any."""
    seconds = report["compile_seconds"]
    return [f"  compiling        {seconds:.3f} s (before the clock: not in the rates)"] if seconds > 0 else []


def _kernels(args: argparse.Namespace) -> str:
    """``--kernels``, or what ``--backend`` (its older name) says: ``auto``, ``python`` or ``compiled``."""
    if args.backend is None:
        return "auto" if args.kernels is None else str(args.kernels)
    alias = "compiled" if args.backend == "numba" else str(args.backend)
    if args.kernels is not None and args.kernels != alias:
        raise InvalidInputError(
            "kernels", f"{args.kernels} disagrees with --backend {args.backend} (its older name); give one of them"
        )
    return alias


def _no_memory(streams: Streams, n: int) -> int:
    """The one line for a gas of ``n`` balls that this machine's memory cannot hold; status 1."""
    streams.err(f"{_PROG}: --n: not enough memory for {n:,} balls")
    return 1


def _warn_if_gaining(streams: Streams, restitution: float) -> None:
    """A warning when ``e > 1``: allowed (the lab's postlab asks what it does), but every collision
    then adds kinetic energy."""
    if restitution > 1.0:
        streams.err(f"warning: restitution {restitution:g} > 1: every collision adds kinetic energy")


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
        *_compiling(report),
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
    lines += _species_lines(report)
    lines += _observed_lines(report)
    lines += _checkpoint_lines(report)
    if report.get("events_file"):
        lines.append(f"  events           {report['events_file']}")
    lines += _trajectory_line(report)
    if report.get("plot"):
        lines.append(f"  plot             {report['plot']}")
    return lines


def _species_lines(report: dict[str, Any]) -> list[str]:
    """A mixture's lines: each species, then each ordered pair's collision rate."""
    lines = [
        f"  species {sp['name']:<8} {sp['count']:,} balls, radius {sp['radius']:g}, mass {sp['mass']:g}, "
        f"kT {sp['kT']:.6g}"
        for sp in report.get("species", ())
    ]
    for pair in report.get("pair_collision_rates", ()):
        theory = pair["rate_enskog"]
        a, b = pair["species"]
        lines.append(
            f"  rate {a} -> {b} ".ljust(19)
            + f"{pair['rate']:.5g} per {a} ball per unit time"
            + (f", Enskog {theory:.5g}" if theory is not None else "")
        )
    return lines


def _observed_lines(report: dict[str, Any]) -> list[str]:
    """``--observe``'s lines: g's contact values and Z from them, the self-diffusion."""
    lines = []
    if "rdf" in report:
        for pair in report["rdf"]["pairs"]:
            a, b = pair["species"]
            lines.append(f"  g({a}-{b}) contact   {pair['contact']:.5g} at r = {pair['sigma']:g}")
        window = report.get("compressibility_window")
        lines.append(
            f"  Z from g(sigma)  {report['compressibility_contact']:.5f}"
            + (f", collisions over the same window {window:.5f}" if window is not None else "")
        )
    if "msd" in report:
        diffusion, enskog = report["diffusion"], report["diffusion_enskog"]
        lines.append(
            "  self-diffusion   "
            + (f"{diffusion:.5g}" if diffusion is not None else "n/a")
            + (f", Enskog {enskog:.5g}" if enskog is not None else "")
            + f" (MSD at {len(report['msd']['t'])} times)"
        )
    return lines


def _checkpoint_lines(report: dict[str, Any]) -> list[str]:
    """The checkpoint written and, for a continued run, the one it started from."""
    lines = []
    if "resumed_from" in report:
        lines.append(f"  resumed from     {report['resumed_from']} at time {report['resumed_at']:g}")
    if "checkpoint" in report:
        lines.append(f"  checkpoint       {report['checkpoint']} ({report['checkpoints_written']} written)")
    return lines


def _trajectory_line(report: dict[str, Any]) -> list[str]:
    if not report.get("trajectory"):
        return []
    return [f"  trajectory       {report['trajectory']} ({report['trajectory_frames']} frames)"]


def _trajectory_checked(args: argparse.Namespace) -> int:
    """``--frames`` (its default when only ``--trajectory`` is given), the file's format and
    folder checked before the run (:class:`InvalidInputError`; a missing ``gsd``:
    :class:`~collisionlab.extras.MissingExtraError`); 0 without ``--trajectory``."""
    from ..atomic import check_target
    from ..trajectory import check_frames, require_gsd, trajectory_format

    if args.trajectory is None:
        if args.frames is not None:
            raise InvalidInputError("frames", "needs --trajectory FILE")
        return 0
    frames = check_frames(_DEFAULT_FRAMES if args.frames is None else args.frames)
    kind = trajectory_format(args.trajectory)
    check_target(args.trajectory, "trajectory")
    if kind == "gsd":
        require_gsd()
    return frames


def _trajectory(args: argparse.Namespace, sides: tuple[float, ...], periodic: bool, types: Any) -> Any:
    """The frame writer of ``--trajectory`` (a context manager) for the balls ``types``
    (:class:`~collisionlab.trajectory.Types`), or one that yields ``None``."""
    from ..trajectory import trajectory_file

    if args.trajectory is None:
        return contextlib.nullcontext(None)
    return trajectory_file(args.trajectory, sides, periodic, types)


def _cannot_write(streams: Streams, args: argparse.Namespace, err: OSError) -> int:
    """One line naming the file (``--trajectory`` or ``--events``) that could not be written."""
    trajectory = args.trajectory is not None and (args.events is None or err.filename == args.trajectory)
    flag, path = ("--trajectory", args.trajectory) if trajectory else ("--events", args.events)
    streams.err(f"{_PROG}: {flag}: cannot write {path}: {err.strerror or err}")
    return 1


def _run_exact(args: argparse.Namespace, streams: Streams) -> int:
    from ..edmd.events_file import event_file, event_format
    from ..edmd.observables import FRAMES, parse_species, run_exact_gas
    from ..trajectory import Types, steps_for_frames

    if args.checkpoint is not None or args.resume is not None:
        return _run_checkpointed(args, streams)
    notes = not args.quiet
    try:
        if args.checkpoint_every is not None:
            raise InvalidInputError("checkpoint_every", "needs --checkpoint FILE (or --resume FILE)")
        if args.plot is not None:  # the path checked before the run (matplotlib loads only for a plot)
            from ..plotting.balls import check_balls_plot_path

            check_balls_plot_path(args.plot)
        species = tuple(parse_species(text) for text in args.species or ())
        observe = _observe_checked(args)
        gas = _exact_gas(args, species).checked()
        if _kernels(args) == "python":
            raise InvalidInputError(
                "kernels", "python is not available with --mode exact (its loop runs compiled only)"
            )
        if args.events is not None:
            event_format(args.events)
        frames = _trajectory_checked(args)
        # The loop loaded (or compiled, saying so) and timed apart, then the start checked,
        # before any file is opened.
        # (In a thread of its own: a signal stops the command at once, even inside LLVM's calls.)
        compile_seconds = interruptible(lambda: load_kernels("event-driven", streams.err if notes else None))
        if species or observe:  # a mixture, or an observed run, runs on its event-driven world alone
            return _run_mixture(args, streams, gas, compile_seconds, observe, frames)
        steps = steps_for_frames(FRAMES, frames) if frames else FRAMES  # a frame ends a step
        world = World(gas.scenario(steps), notify=streams.err if notes else None, events=args.events is not None)
    except InvalidInputError as err:
        return _bad_value(streams, err)
    except MemoryError:
        return _no_memory(streams, args.n)
    _warn_if_gaining(streams, gas.restitution)
    bar = ProgressBar(streams, label="gas time")
    try:
        with deferred_interrupts() as pending:  # Ctrl-C is looked for while a chunk of the loop runs too
            watch = ChunkWatch(pending, bar if notes else None)
            side = world.scenario.box.sides if world.scenario.box is not None else ()
            with contextlib.ExitStack() as files:
                if args.events is not None:
                    world.listen(files.enter_context(event_file(args.events)))
                types = Types.one_kind(gas.n, gas.radius)
                write = files.enter_context(_trajectory(args, side, gas.boundary == "periodic", types))
                report = run_exact_gas(gas, world, watch.between, frames=frames, write_frame=write, calling=watch.call)
            if args.events is not None:
                report["events_file"] = args.events
            if frames:
                report["trajectory"], report["trajectory_frames"] = args.trajectory, frames
        report["compile_seconds"] = compile_seconds
    except OSError as err:
        return _cannot_write(streams, args, err)
    finally:
        bar.close()
    if args.plot is not None:
        d = gas.dim
        state = (world.position_array[:, :d], world.velocity_array[:, :d])
        if not _plot_balls(args, streams, gas, state, types, tuple(float(x) for x in side), report):
            return 1
    return _emit(args, streams, report)


def _plot_balls(
    args: argparse.Namespace,
    streams: Streams,
    gas: Any,
    state: tuple[Any, Any],
    types: Any,
    sides: tuple[float, ...],
    report: dict[str, Any],
) -> bool:
    """``--plot`` of an event-driven gas: its last frame, species coloured, and its speeds
    (:func:`~collisionlab.plotting.balls.save_balls_plot`); False (said in one line) if the file
    cannot be written."""
    import numpy as np

    from ..plotting.balls import save_balls_plot

    positions, velocities = (np.asarray(a, dtype=np.float64) for a in state)
    if gas.boundary == "periodic":  # each centre shown in the box, as the trajectory has it
        positions = np.mod(positions, np.asarray(sides))
    balls = "discs" if gas.dim == 2 else "spheres"
    title = f"{gas.n:,} {balls} in {gas.dim}D ({gas.boundary}), packing fraction {gas.fraction:g}, t = {gas.time:g}"
    try:
        save_balls_plot(args.plot, positions, velocities, types.radii, types.ids, types.names, sides, title)
    except OSError as err:
        streams.err(f"{_PROG}: --plot: cannot write {args.plot}: {err.strerror or err}")
        return False
    report["plot"] = args.plot
    return True


#: What a resumed run may change (the rest is the checkpoint's), for the messages.
_MAY_CHANGE = "only --time, --checkpoint, --checkpoint-every, --format and --quiet may change"
#: Options whose files a continued run could not continue.
_NOT_WITH_CHECKPOINTS = ("events", "trajectory", "frames", "plot")


def _contradictions(args: argparse.Namespace, gas: Any) -> None:
    """:class:`InvalidInputError` naming the first option given with ``--resume`` whose value
    is not the checkpoint's run's (``gas``, as it was given)."""
    from ..edmd.observables import parse_species

    given: frozenset[str] = getattr(args, _GIVEN, frozenset())
    if "mode" in given and args.mode != "exact":
        raise InvalidInputError("resume", "continues an exact run: --mode must be exact or left out")
    for name in _KEPT_ON_RESUME:
        if name not in given:
            continue
        typed, kept = getattr(args, name), getattr(gas, name)
        if name == "species":
            typed = tuple(parse_species(text) for text in typed)
            shown = " ".join(f"{sp.name}:{sp.fraction:g}:{sp.radius:g}" for sp in kept) or "none (one kind of ball)"
        else:
            shown = "its default" if kept is None else f"{kept!r}"
        if typed != kept:
            raise InvalidInputError(
                name, f"contradicts the checkpoint, whose run has {shown} (a resumed run keeps its own; {_MAY_CHANGE})"
            )


def _observation_kept(args: argparse.Namespace, resumed: Any) -> None:
    """:class:`InvalidInputError` naming ``--observe``, ``--samples`` or ``--time`` when a
    resumed run would not observe as its checkpoint's run did: an observed run goes on observing
    as it was started (``--observe`` and ``--samples`` left out or the same), to the end its
    samples were laid out for (its own ``--time``); a run not observed cannot start observing."""
    observer = resumed.observer
    if observer is None:
        if args.observe is not None:
            raise InvalidInputError(
                "observe", "the checkpoint's run was not observed (an observation starts with its run)"
            )
        _observe_checked(args)  # (--samples alone: needs --observe)
        return
    stored = ",".join(observer.observe)
    if args.observe is not None and set(_observe_checked(args)) != set(observer.observe):
        raise InvalidInputError(
            "observe", f"contradicts the checkpoint, whose run observes {stored} (a resumed run keeps its own)"
        )
    if args.samples is not None and args.samples != observer.samples:
        raise InvalidInputError(
            "samples",
            f"contradicts the checkpoint, whose run observes {stored} at {observer.samples} samples "
            "(a resumed run keeps its own)",
            got=args.samples,
        )
    if "time" in getattr(args, _GIVEN, frozenset()) and args.time != resumed.gas.time:
        raise InvalidInputError(
            "time",
            f"an observed run ends at the time it was started with, {resumed.gas.time!r} (its samples are laid "
            "out over it): leave --time out or give that",
            got=args.time,
        )


def _run_checkpointed(args: argparse.Namespace, streams: Streams) -> int:
    """``--mode exact`` with ``--checkpoint FILE`` or ``--resume FILE``: the run on its
    event-driven world (one kind of ball or a mixture; the same numbers as the scenario's run),
    saved atomically every ``--checkpoint-every`` of simulated time and at the end
    (:mod:`collisionlab.edmd.checkpoint`); a resumed run goes on from its checkpoint to the
    total time ``--time`` (default: its own) and ends as the run done in one go would. An
    observed run (``--observe``) saves its observer with it and, resumed, goes on observing as
    it was started, to its own end (:func:`_observation_kept`): its report is the one of the
    observed run done in one go."""
    from dataclasses import replace

    from ..atomic import check_target
    from ..edmd.checkpoint import CheckpointError, read_checkpoint, write_checkpoint
    from ..edmd.observables import observer_for, parse_species, run_end, run_on_world
    from ..edmd.structure import DEFAULT_SAMPLES
    from ..validate import positive

    notes = not args.quiet
    resumed = None
    observe: tuple[str, ...] = ()
    try:
        for name in _NOT_WITH_CHECKPOINTS:
            if getattr(args, name) is not None:
                raise InvalidInputError(
                    name, "is not available with --checkpoint or --resume (a continued run could not continue its file)"
                )
        if _kernels(args) == "python":
            raise InvalidInputError(
                "kernels", "python is not available with --mode exact (its loop runs compiled only)"
            )
        every = None if args.checkpoint_every is None else positive(args.checkpoint_every, "checkpoint_every")
        if args.resume is None:
            species = tuple(parse_species(text) for text in args.species or ())
            observe = _observe_checked(args)
            source = _exact_gas(args, species)
            gas = source.checked()
            target = args.checkpoint
        else:
            try:
                resumed = read_checkpoint(args.resume)
            except CheckpointError as err:
                streams.err(f"{_PROG}: --resume: {err}")
                return 65
            except OSError as err:
                streams.err(f"{_PROG}: --resume: cannot read {args.resume}: {err.strerror or err}")
                return 1
            _contradictions(args, resumed.gas)
            _observation_kept(args, resumed)
            total = args.time if "time" in getattr(args, _GIVEN, frozenset()) else resumed.gas.time
            source = replace(resumed.gas, time=total)
            gas = source.checked()
            if run_end(gas.time) < resumed.time:
                raise InvalidInputError(
                    "time",
                    f"the total simulated time to reach: must be at least the checkpoint's time {resumed.time!r}",
                    got=total,
                )
            target = args.checkpoint if args.checkpoint is not None else args.resume
            every = resumed.every if args.checkpoint_every is None else every
        check_target(target, "checkpoint")
        compile_seconds = interruptible(lambda: load_kernels("event-driven", streams.err if notes else None))
        balls = gas.world() if resumed is None else resumed.world  # (the start checked: a lattice that fits)
        if resumed is not None:
            observer = resumed.observer  # (as it was: it goes on observing)
        elif observe:
            samples = DEFAULT_SAMPLES if args.samples is None else args.samples
            observer = observer_for(gas, balls, observe, samples)
        else:
            observer = None
    except InvalidInputError as err:
        return _bad_value(streams, err)
    except MemoryError:
        return _no_memory(streams, args.n)
    _warn_if_gaining(streams, gas.restitution)
    written = 0

    def save(energy_start: float, seconds: float) -> None:
        nonlocal written
        write_checkpoint(target, source, balls, energy_start, seconds, every, observer)
        written += 1

    bar = ProgressBar(streams, label="gas time")
    try:
        with deferred_interrupts() as pending:
            watch = ChunkWatch(pending, bar if notes else None)
            report = run_on_world(
                gas,
                balls,
                watch.between,
                calling=watch.call,
                energy_start=None if resumed is None else resumed.energy_start,
                seconds=0.0 if resumed is None else resumed.seconds,
                every=every,
                checkpoint=save,
                observer=observer,
            )
        report["compile_seconds"] = compile_seconds
        report["checkpoint"], report["checkpoints_written"] = target, written
        if resumed is not None:
            report["resumed_from"], report["resumed_at"] = args.resume, resumed.time
    except OutOfRangeError as err:
        streams.err(f"{_PROG}: {err}")
        return 65
    except OSError as err:
        streams.err(f"{_PROG}: --checkpoint: cannot write {target}: {err.strerror or err}")
        return 1
    finally:
        bar.close()
    return _emit(args, streams, report)


def _observe_checked(args: argparse.Namespace) -> tuple[str, ...]:
    """``--observe``'s names and ``--samples`` checked (:class:`InvalidInputError`); ``()``
    without ``--observe``."""
    from ..edmd.structure import parse_observables

    if args.observe is None:
        if args.samples is not None:
            raise InvalidInputError("samples", "needs --observe rdf,msd")
        return ()
    observe = parse_observables(args.observe)
    if args.samples is not None and not 1 <= args.samples <= _MAX_SAMPLES:
        raise InvalidInputError("samples", f"must be 1 to {_MAX_SAMPLES:,}", got=args.samples)
    return observe


#: ``--samples`` at most (each one counts every pair of balls for g(r)).
_MAX_SAMPLES = 100_000


def _run_mixture(
    args: argparse.Namespace,
    streams: Streams,
    gas: Any,
    compile_seconds: float,
    observe: tuple[str, ...] = (),
    frames: int = 0,
) -> int:
    """``--mode exact --species ...`` or ``--observe ...``: the gas's event-driven world made
    (its start checked), run and reported as the exact gas is (the same numbers, to the last
    bit), its collisions streamed to ``--events`` if asked, observed as ``--observe`` asks,
    ``frames`` frames written to ``--trajectory`` (each ball's species and diameter)."""
    from ..edmd.events_file import rows_file
    from ..edmd.observables import observer_for, run_on_world, trajectory_types
    from ..edmd.structure import DEFAULT_SAMPLES

    notes = not args.quiet
    try:
        balls = gas.world()  # the start checked (a lattice that fits) before any file is opened
        samples = DEFAULT_SAMPLES if args.samples is None else args.samples
        observer = observer_for(gas, balls, observe, samples) if observe else None
    except InvalidInputError as err:
        return _bad_value(streams, err)
    except MemoryError:
        return _no_memory(streams, args.n)
    _warn_if_gaining(streams, gas.restitution)
    bar = ProgressBar(streams, label="gas time")
    try:
        with deferred_interrupts() as pending:
            watch = ChunkWatch(pending, bar if notes else None)
            with contextlib.ExitStack() as files:
                sink = files.enter_context(rows_file(args.events)) if args.events is not None else None
                sides = tuple(float(x) for x in balls.sides)
                periodic = gas.boundary == "periodic"
                write = files.enter_context(_trajectory(args, sides, periodic, trajectory_types(gas)))
                report = run_on_world(
                    gas, balls, watch.between, watch.call, sink, observer=observer, frames=frames, write_frame=write
                )
            if args.events is not None:
                report["events_file"] = args.events
            if frames:
                report["trajectory"], report["trajectory_frames"] = args.trajectory, frames
        report["compile_seconds"] = compile_seconds
    except OutOfRangeError as err:
        streams.err(f"{_PROG}: {err}")
        return 65
    except OSError as err:
        return _cannot_write(streams, args, err)
    finally:
        bar.close()
    plotted = args.plot is None or _plot_balls(args, streams, gas, balls.state(), trajectory_types(gas), sides, report)
    if not plotted:
        return 1
    return _emit(args, streams, report)


def run(args: argparse.Namespace, streams: Streams) -> int:
    """Run ``collisionlab gas``: 0 done, 2 a bad value (one line naming the flag), 1 a failure,
    65 a checkpoint that cannot be continued (``--resume``) or a run out of range."""
    if args.mode == "exact" or args.resume is not None:
        return _run_exact(args, streams)
    for name in ("checkpoint", "checkpoint_every"):
        if getattr(args, name) is not None:
            streams.err(f"{_PROG}: {_FLAGS[name]}: needs --mode exact (the event-driven gas)")
            return 2
    if args.species:
        streams.err(f"{_PROG}: --species: needs --mode exact (the stepped gas holds balls of one radius and mass)")
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
        frames = _trajectory_checked(args)
        if frames:
            frame_steps(steps, frames)  # K - 1 must divide the steps
        gas = gas_scenario(args.n, args.dim, args.seed, speeds=args.speeds)
        compiled = _kernels(args) != "python"  # auto: compiled (numba is installed with the package)
        world = World(
            gas.scenario(steps, restitution, gravity),
            WorldParams(compiled=compiled),
            notify=streams.err if notes else None,
            events=False,
        )
    except InvalidInputError as err:
        return _bad_value(streams, err)
    except MemoryError:
        return _no_memory(streams, args.n)
    _warn_if_gaining(streams, restitution)
    compile_seconds = interruptible(world.load_kernels)  # before the clock: compiling is not stepping
    if notes and not world.compiled:  # a first user may not know how much slower it is
        streams.err(f"{_PROG}: stepping with the kernels' Python form: far slower than numba (Ctrl-C stops it)")
    energy_start = world.kinetic_energy()
    bar = ProgressBar(streams, label="gas steps")
    try:
        with interrupts_for(world.compiled) as pending:  # compiled: looked for while a chunk runs too
            watch = ChunkWatch(pending, bar if notes else None)
            if frames:
                with _trajectory(args, (gas.side,) * gas.dim, False, Types.one_kind(gas.n, gas.radius)) as write:
                    seconds = advance_in_frames(world, steps, frames, write, watch.between, watch.call)
            else:
                seconds = world.advance(steps, watch.between, calling=watch.call)
    except OutOfRangeError as err:
        streams.err(f"{_PROG}: {err}")
        return 65
    except OSError as err:
        if not frames:
            raise
        streams.err(f"{_PROG}: --trajectory: cannot write {args.trajectory}: {err.strerror or err}")
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
            streams.err(f"{_PROG}: --plot: cannot write {args.plot}: {err.strerror or err}")
            return 1
        report["plot"] = args.plot
    if args.format == "json":
        streams.out(json.dumps(report))
    else:
        for line in _table(report):
            streams.out(line)
    return 0


def _exact_gas(args: argparse.Namespace, species: tuple[Any, ...]) -> Any:
    """The event-driven gas (``ExactGas``) the options ask for, not yet checked."""
    from ..edmd.observables import ExactGas  # (here: the gas's modules load only when it runs)

    return ExactGas(
        n=args.n,
        dim=args.dim,
        fraction=args.fraction,
        boundary=args.boundary,
        time=args.time,
        seed=args.seed,
        restitution=args.restitution,
        gravity=args.gravity,
        tc=args.tc,
        species=species,
    )


def _emit(args: argparse.Namespace, streams: Streams, report: dict[str, Any]) -> int:
    """Print an exact gas run's report as ``--format`` asks (JSON, or the table); exit status 0."""
    if args.format == "json":
        streams.out(json.dumps(report))
    else:
        for line in _exact_table(report):
            streams.out(line)
    return 0
