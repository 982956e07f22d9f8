"""``collisionlab gas --mode exact``: the event-driven run, a mixture of species, a run continued
from its checkpoint (``--resume``), and the picture of the last frame (``--plot``)."""

from __future__ import annotations

import argparse
import contextlib
from typing import Any

from ..engine.ahead import load_kernels
from ..engine.world import World
from ..errors import InvalidInputError, OutOfRangeError
from .gas_common import (
    GIVEN,
    PROG,
    bad_value,
    cannot_write,
    exact_gas,
    kernels_choice,
    no_memory,
    observe_checked,
    open_trajectory,
    trajectory_checked,
    warn_if_gaining,
)
from .gas_text import emit_report
from .interrupts import ChunkWatch, deferred_interrupts, interruptible
from .progress import ProgressBar
from .streams import Streams

__all__ = [
    "KEPT_ON_RESUME",
    "MAY_CHANGE",
    "NOT_WITH_CHECKPOINTS",
    "contradictions",
    "observation_kept",
    "plot_balls",
    "run_checkpointed",
    "run_exact",
    "run_mixture",
]


#: Options of a run's physics and start: a run continued with ``--resume`` takes them from its
#: checkpoint, and refuses one given with another value.
KEPT_ON_RESUME = ("n", "dim", "fraction", "boundary", "seed", "restitution", "gravity", "tc", "species")


def run_exact(args: argparse.Namespace, streams: Streams) -> int:
    from ..edmd.events_file import event_file, event_format
    from ..edmd.exact_gas import FRAMES, parse_species
    from ..edmd.observables import run_exact_gas
    from ..trajectory import Types, steps_for_frames

    if args.checkpoint is not None or args.resume is not None:
        return run_checkpointed(args, streams)
    notes = not args.quiet
    try:
        if args.checkpoint_every is not None:
            raise InvalidInputError("checkpoint_every", "needs --checkpoint FILE (or --resume FILE)")
        if args.plot is not None:  # the path checked before the run (matplotlib loads only for a plot)
            from ..plotting.balls import check_balls_plot_path

            check_balls_plot_path(args.plot)
        species = tuple(parse_species(text) for text in args.species or ())
        observe = observe_checked(args)
        gas = exact_gas(args, species).checked()
        if kernels_choice(args) == "python":
            raise InvalidInputError(
                "kernels", "python is not available with --mode exact (its loop runs compiled only)"
            )
        if args.events is not None:
            event_format(args.events)
        frames = trajectory_checked(args)
        # The loop loaded (or compiled, saying so) and timed apart, then the start checked,
        # before any file is opened.
        # (In a thread of its own: a signal stops the command at once, even inside LLVM's calls.)
        compile_seconds = interruptible(lambda: load_kernels("event-driven", streams.err if notes else None))
        if species or observe:  # a mixture, or an observed run, runs on its event-driven world alone
            return run_mixture(args, streams, gas, compile_seconds, observe, frames)
        steps = steps_for_frames(FRAMES, frames) if frames else FRAMES  # a frame ends a step
        world = World(gas.scenario(steps), notify=streams.err if notes else None, events=args.events is not None)
    except InvalidInputError as err:
        return bad_value(streams, err)
    except MemoryError:
        return no_memory(streams, args.n)
    warn_if_gaining(streams, gas.restitution)
    bar = ProgressBar(streams, label="gas time")
    try:
        with deferred_interrupts() as pending:  # Ctrl-C is looked for while a chunk of the loop runs too
            watch = ChunkWatch(pending, bar if notes else None)
            side = world.scenario.box.sides if world.scenario.box is not None else ()
            with contextlib.ExitStack() as files:
                if args.events is not None:
                    world.listen(files.enter_context(event_file(args.events)))
                types = Types.one_kind(gas.n, gas.radius)
                write = files.enter_context(open_trajectory(args, side, gas.boundary == "periodic", types))
                report = run_exact_gas(gas, world, watch.between, frames=frames, write_frame=write, calling=watch.call)
        _note_outputs(report, args, frames, compile_seconds)
    except OSError as err:
        return cannot_write(streams, args, err)
    finally:
        bar.close()
    if args.plot is not None:
        d = gas.dim
        state = (world.position_array[:, :d], world.velocity_array[:, :d])
        if not plot_balls(args, streams, gas, state, types, tuple(float(x) for x in side), report):
            return 1
    return emit_report(args, streams, report)


def _note_outputs(report: dict[str, Any], args: argparse.Namespace, frames: int, compile_seconds: float) -> None:
    """The report's entries for what the run wrote beside it (``--events``, ``--trajectory``)
    and the compile's seconds, timed apart from the run."""
    if args.events is not None:
        report["events_file"] = args.events
    if frames:
        report["trajectory"], report["trajectory_frames"] = args.trajectory, frames
    report["compile_seconds"] = compile_seconds


def plot_balls(
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
        streams.err(f"{PROG}: --plot: cannot write {args.plot}: {err.strerror or err}")
        return False
    report["plot"] = args.plot
    return True


#: What a resumed run may change (the rest is the checkpoint's), for the messages.
MAY_CHANGE = "only --time, --checkpoint, --checkpoint-every, --format and --quiet may change"


#: Options whose files a continued run could not continue.
NOT_WITH_CHECKPOINTS = ("events", "trajectory", "frames", "plot")


def contradictions(args: argparse.Namespace, gas: Any) -> None:
    """:class:`InvalidInputError` naming the first option given with ``--resume`` whose value
    is not the checkpoint's run's (``gas``, as it was given)."""
    from ..edmd.exact_gas import parse_species

    given: frozenset[str] = getattr(args, GIVEN, frozenset())
    if "mode" in given and args.mode != "exact":
        raise InvalidInputError("resume", "continues an exact run: --mode must be exact or left out")
    for name in KEPT_ON_RESUME:
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
                name, f"contradicts the checkpoint, whose run has {shown} (a resumed run keeps its own; {MAY_CHANGE})"
            )


def observation_kept(args: argparse.Namespace, resumed: Any) -> None:
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
        observe_checked(args)  # (--samples alone: needs --observe)
        return
    stored = ",".join(observer.observe)
    if args.observe is not None and set(observe_checked(args)) != set(observer.observe):
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
    if "time" in getattr(args, GIVEN, frozenset()) and args.time != resumed.gas.time:
        raise InvalidInputError(
            "time",
            f"an observed run ends at the time it was started with, {resumed.gas.time!r} (its samples are laid "
            "out over it): leave --time out or give that",
            got=args.time,
        )


def run_checkpointed(args: argparse.Namespace, streams: Streams) -> int:
    """``--mode exact`` with ``--checkpoint FILE`` or ``--resume FILE``: the run on its
    event-driven world (one kind of ball or a mixture; the same numbers as the scenario's run),
    saved atomically every ``--checkpoint-every`` of simulated time and at the end
    (:mod:`collisionlab.edmd.checkpoint`); a resumed run goes on from its checkpoint to the
    total time ``--time`` (default: its own) and ends as the run done in one go would. An
    observed run (``--observe``) saves its observer with it and, resumed, goes on observing as
    it was started, to its own end (:func:`observation_kept`): its report is the one of the
    observed run done in one go."""
    from dataclasses import replace

    from ..atomic import check_target
    from ..edmd.checkpoint import CheckpointError, read_checkpoint, write_checkpoint
    from ..edmd.exact_gas import parse_species
    from ..edmd.observables import observer_for, run_end, run_on_world
    from ..edmd.structure import DEFAULT_SAMPLES
    from ..validate import positive

    notes = not args.quiet
    resumed = None
    observe: tuple[str, ...] = ()
    try:
        for name in NOT_WITH_CHECKPOINTS:
            if getattr(args, name) is not None:
                raise InvalidInputError(
                    name, "is not available with --checkpoint or --resume (a continued run could not continue its file)"
                )
        if kernels_choice(args) == "python":
            raise InvalidInputError(
                "kernels", "python is not available with --mode exact (its loop runs compiled only)"
            )
        every = None if args.checkpoint_every is None else positive(args.checkpoint_every, "checkpoint_every")
        if args.resume is None:
            species = tuple(parse_species(text) for text in args.species or ())
            observe = observe_checked(args)
            source = exact_gas(args, species)
            gas = source.checked()
            target = args.checkpoint
        else:
            try:
                resumed = read_checkpoint(args.resume)
            except CheckpointError as err:
                streams.err(f"{PROG}: --resume: {err}")
                return 65
            except OSError as err:
                streams.err(f"{PROG}: --resume: cannot read {args.resume}: {err.strerror or err}")
                return 1
            contradictions(args, resumed.gas)
            observation_kept(args, resumed)
            total = args.time if "time" in getattr(args, GIVEN, frozenset()) else resumed.gas.time
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
        return bad_value(streams, err)
    except MemoryError:
        return no_memory(streams, args.n)
    warn_if_gaining(streams, gas.restitution)
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
        streams.err(f"{PROG}: {err}")
        return 65
    except OSError as err:
        streams.err(f"{PROG}: --checkpoint: cannot write {target}: {err.strerror or err}")
        return 1
    finally:
        bar.close()
    return emit_report(args, streams, report)


def run_mixture(
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
        return bad_value(streams, err)
    except MemoryError:
        return no_memory(streams, args.n)
    warn_if_gaining(streams, gas.restitution)
    bar = ProgressBar(streams, label="gas time")
    try:
        with deferred_interrupts() as pending:
            watch = ChunkWatch(pending, bar if notes else None)
            with contextlib.ExitStack() as files:
                sink = files.enter_context(rows_file(args.events)) if args.events is not None else None
                sides = tuple(float(x) for x in balls.sides)
                periodic = gas.boundary == "periodic"
                write = files.enter_context(open_trajectory(args, sides, periodic, trajectory_types(gas)))
                report = run_on_world(
                    gas, balls, watch.between, watch.call, sink, observer=observer, frames=frames, write_frame=write
                )
        _note_outputs(report, args, frames, compile_seconds)
    except OutOfRangeError as err:
        streams.err(f"{PROG}: {err}")
        return 65
    except OSError as err:
        return cannot_write(streams, args, err)
    finally:
        bar.close()
    plotted = args.plot is None or plot_balls(args, streams, gas, balls.state(), trajectory_types(gas), sides, report)
    if not plotted:
        return 1
    return emit_report(args, streams, report)
