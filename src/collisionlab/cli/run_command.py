"""``collisionlab run FILE`` and ``collisionlab demo [NAME]``: run scenarios and print them."""

from __future__ import annotations

import argparse
import contextlib
import functools
import shutil
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, TextIO, TypeVar

from .. import limits
from ..atomic import atomic_stream, check_target
from ..demos import LAB_DEMOS, builtin_scenario_path, demo_names, load_demo
from ..engine import WorldParams
from ..engine.ahead import KERNEL_CHOICES, compiled_choice
from ..errors import CollisionLabError, InvalidInputError, OutOfRangeError, did_you_mean, escape_controls, shorten
from ..model import Scenario
from ..record import RunObserver, RunRecord
from ..scenario_file import load_scenario
from ..validate import whole_number
from ..world import World
from .background import BackgroundObserver
from .interrupts import ChunkWatch, interruptible, interrupts_for
from .progress import ProgressBar
from .render import writer_for
from .streams import Streams

__all__ = ["add_run_parsers", "execute"]

T = TypeVar("T")


def _flag_value(
    check: Callable[[object, str], T], parse: Callable[[str], object] = float, form: str = "a number"
) -> Callable[[str], T]:
    """An argparse ``type=`` that parses the text and applies the library's own check, so a
    flag and a scenario field refuse the same values with the same words."""

    def convert(text: str) -> T:
        try:
            value = parse(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {form}, got {text!r}") from None
        try:
            return check(value, "value")
        except InvalidInputError as error:
            raise argparse.ArgumentTypeError(f"{error.problem}, got {text!r}") from None

    return convert


positive_int = _flag_value(whole_number, int, "a whole number >= 1")
dt_flag = _flag_value(limits.dt)
restitution_flag = _flag_value(limits.restitution)
steps_flag = _flag_value(limits.steps, int, "a whole number >= 1")


def _add_common(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--steps", type=steps_flag, help="number of steps (overrides the scenario)")
    parser.add_argument("--dt", type=dt_flag, help="time step in seconds (overrides the scenario)")
    parser.add_argument(
        "--mode",
        choices=("euler", "exact"),
        help="stepping: the lab's Forward Euler, or exact time of impact (nothing tunnels); overrides the scenario",
    )
    parser.add_argument(
        "--contacts",
        choices=("events", "solve"),
        help="exact mode: every touch an impact (events), or resting contacts solved and bodies at rest asleep "
        "(solve: piles, pours, stacks); overrides the scenario",
    )
    parser.add_argument(
        "--restitution",
        type=restitution_flag,
        metavar="E",
        help="default coefficient of restitution (overrides the scenario; > 1 adds energy)",
    )
    parser.add_argument(
        "--kernels",
        choices=KERNEL_CHOICES,
        default="auto",
        help="the kernels' form: auto (compiled for large runs, Python for small ones), python, or compiled "
        "(numba; loaded, or compiled once per machine, before the run starts)",
    )
    parser.add_argument("--every", type=positive_int, default=1, metavar="K", help="print every K-th step")
    parser.add_argument("--format", choices=("table", "csv", "json"), default="table", help="output format")
    parser.add_argument("--output", metavar="FILE", help="write the output to FILE (atomically) instead of stdout")
    parser.add_argument(
        "--quiet", action="store_true", help="table: collisions and summary only, no positions; no progress on stderr"
    )
    parser.add_argument("--explain", action="store_true", help="show the working of every collision")
    parser.add_argument("--plot", metavar="FILE.png", help="save trajectories and energy over time as a picture")
    parser.add_argument("--animate", metavar="FILE.gif", help="save an animation (.gif, or .mp4 with ffmpeg)")
    parser.add_argument("--html", metavar="FILE.html", help="save an interactive 3D page of the run")


def add_run_parsers(sub: Any) -> None:
    run = sub.add_parser("run", help="run a scenario file (TOML) or a built-in scenario by name")
    run.add_argument(
        "file", metavar="FILE.toml", help="the scenario file, or the NAME of a built-in one (collisionlab examples)"
    )
    _add_common(run)
    run.set_defaults(func=_run_file)
    demo = sub.add_parser(
        "demo",
        help="run built-in scenarios (no NAME: the lab's four cases)",
        description=f"Built-in scenarios: {', '.join(demo_names())}. With no NAME, the lab's four cases run.",
    )
    demo.add_argument("name", nargs="?", metavar="NAME", help="one of: " + ", ".join(demo_names()))
    demo.add_argument("--list", action="store_true", help="list the built-in scenarios")
    _add_common(demo)
    demo.set_defaults(func=_run_demo)


def _run_file(args: argparse.Namespace, streams: Streams) -> int:
    path = args.file if Path(args.file).exists() else builtin_scenario_path(args.file) or args.file
    if path == args.file and not Path(path).exists():  # neither a file nor a built-in: a typo?
        hint = did_you_mean(Path(path).name.removesuffix(".toml"), demo_names())
        if hint:
            raise CollisionLabError(
                f"{escape_controls(shorten(args.file))}: no such file or built-in scenario; {hint}"
                "(collisionlab examples lists them)"
            )
    return execute([load_scenario(path)], args, streams, sources=[args.file])


def _run_demo(args: argparse.Namespace, streams: Streams) -> int:
    if args.list:
        for name in demo_names():
            streams.out(f"{name:<16}{load_demo(name).title}")
        return 0
    names = [args.name] if args.name else list(LAB_DEMOS)
    return execute([load_demo(n) for n in names], args, streams, labels=names, sources=[f"demo {n}" for n in names])


def _suffixed(path: str, label: str | None) -> str:
    """With several scenarios, one picture each: the scenario's label (a demo's name) goes
    before the extension: ``lab.png`` becomes ``lab-aabb3d.png``."""
    if label is None:
        return path
    p = Path(path)
    slug = "-".join("".join(c if c.isalnum() else " " for c in label.lower()).split())
    return str(p.with_name(f"{p.stem}-{slug}{p.suffix}"))


def _pictures(
    record: RunRecord, scenario: Scenario, args: argparse.Namespace, streams: Streams, label: str | None
) -> None:
    if not (args.plot or args.animate or args.html):
        return
    from .. import plotting  # matplotlib and plotly load only when a picture is asked for

    for option, save in (
        ("plot", plotting.save_plot),
        ("animate", plotting.save_animation),
        ("html", plotting.save_html),
    ):
        target = getattr(args, option)
        if target:
            path = _suffixed(target, label)
            save(record, scenario, path)
            streams.err(f"wrote {path}")


def execute(
    scenarios: list[Scenario],
    args: argparse.Namespace,
    streams: Streams,
    labels: list[str] | None = None,
    sources: list[str] | None = None,
) -> int:
    """Apply the flags to each scenario, run it, and print or write the output. ``labels`` name
    the scenarios' pictures when there are several (default: their titles); ``sources`` (a file
    or a demo for each scenario) name it when its run goes out of range."""
    if args.explain and args.format != "table":
        raise InvalidInputError(
            "--explain",
            f"works with --format table only, not {args.format}; "
            "--format json already carries each collision's working (normal, approach_speed, impulse, velocities)",
        )
    if args.plot or args.animate or args.html:
        from .. import plotting  # matplotlib and plotly load only when a picture is asked for

        plotting.check_paths(args.plot, args.animate, args.html)  # fail now, not after the run
    if args.output is not None:
        check_target(args.output, "--output")  # as the pictures: before the run
    overrides = {
        k: getattr(args, k) for k in ("steps", "dt", "mode", "restitution", "contacts") if getattr(args, k) is not None
    }
    pictures = bool(args.plot or args.animate or args.html)
    params = WorldParams(compiled=compiled_choice(args.kernels))
    listed = args.format == "json" and len(scenarios) > 1
    # The writers stream into a temporary file (disk, not memory: a run's frames and events are
    # written as they are produced); it reaches stdout or --output only when every run succeeded,
    # so a failed run prints nothing and leaves no file, and the JSON is always whole.
    with _spool(args.output) as spool:
        if listed:
            spool.write("[\n")
        for index, scenario in enumerate(scenarios):
            label = None if len(scenarios) == 1 else labels[index] if labels else scenario.title
            if overrides:
                try:
                    scenario = scenario.with_settings(**overrides)
                except InvalidInputError as error:  # a flag out of range with this scenario: name the flag
                    flag = error.field.replace("simulation.", "--")
                    raise error.renamed(flag) if flag[2:] in overrides else error from None
            if args.kernels == "python" and scenario.event_driven:  # said before anything compiles
                raise InvalidInputError(
                    "--kernels",
                    "python is not available for balls in a box in exact mode: they run event by event, "
                    "in a loop that runs compiled only (use --kernels auto, or --mode euler)",
                )
            if pictures:  # pictures keep every frame: they must fit in memory (said before the run)
                limits.check_frames(scenario.settings.steps, args.every, len(scenario.bodies), "--steps")
            if index:
                spool.write(",\n" if args.format == "json" else "\n")
            writer = writer_for(args.format, spool, args.every, args.quiet, args.explain, streams.err)
            try:
                # The kernels loaded (or compiled: a machine's first run) before the progress bar's
                # clock starts, since compiling is not running, and in a thread of their own, so
                # that a signal stops the command at once even inside one of LLVM's long calls.
                world = interruptible(functools.partial(_loaded_world, scenario, params, streams))
            except OutOfRangeError as error:
                raise error.within(sources[index]) if sources else error from None
            bar = ProgressBar(streams, scenario.title, quiet=args.quiet)
            try:
                # Only pictures need the whole record; the output is written as the run goes.
                with contextlib.ExitStack() as stack:
                    observer: RunObserver = writer
                    if world.compiled:  # its kernels run without the GIL: the writer works beside them
                        observer = stack.enter_context(BackgroundObserver(writer))
                    # Compiled, a signal is only noted (raised inside a compiled call it would surface
                    # as "SystemError: CPUDispatcher returned a result with an exception set"), and each
                    # chunk of steps runs in a thread of its own while this one waits and looks for it:
                    # a chunk may last seconds. The Python form raises it at once: one of its steps may
                    # take seconds too.
                    watch = ChunkWatch(stack.enter_context(interrupts_for(world.compiled)), bar)
                    record = world.run(
                        every=args.every, progress=watch.between, observer=observer, keep=pictures, calling=watch.call
                    )
            except OutOfRangeError as error:
                raise error.within(sources[index]) if sources else error from None
            finally:
                bar.close()
            _pictures(record, scenario, args, streams, label)
            if args.format != "table":  # the table prints its warnings; CSV and JSON stay data
                for warning in record.warnings:
                    streams.err(f"warning: {warning}")
        if args.format == "json":
            spool.write("\n]\n" if listed else "\n")
        if args.output is None:
            spool.seek(0)
            shutil.copyfileobj(spool, streams.stdout)
    if args.output is not None:
        streams.err(f"wrote {args.output}")
    return 0


def _loaded_world(scenario: Scenario, params: WorldParams, streams: Streams) -> World:
    """The world of ``scenario``, its compiled kernels loaded (an event-driven world loads its
    loop as it is made)."""
    world = World(scenario, params, notify=streams.err)
    world.load_kernels()
    return world


@contextlib.contextmanager
def _spool(output: str | None) -> Iterator[TextIO]:
    """The file the writers write to. With ``--output``: the temporary file beside it that
    replaces it once every run has succeeded (:func:`~collisionlab.atomic.atomic_stream`: on an
    error or Ctrl-C it is removed and ``output`` is left as it was; a FIFO or a device is written
    through at the end), so the output is written to disk once. Else an unnamed temporary file,
    copied to stdout at the end by the caller."""
    if output is None:
        with tempfile.TemporaryFile("w+", encoding="utf-8") as spool:
            yield spool
        return
    try:
        with atomic_stream(output) as spool:
            yield spool
    except OSError as error:
        if error.filename != output:  # not about the output (atomic_stream names it so): as it is
            raise
        raise CollisionLabError(
            f"--output: cannot write {escape_controls(output)}: {error.strerror or error}"
        ) from None
