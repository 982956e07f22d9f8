"""What the gas command's modes share: its name in messages, the flags behind library fields, the
checks of its options and the one-line messages of a bad value or an unwritable file."""

from __future__ import annotations

import argparse
import contextlib
from typing import Any

from ..errors import InvalidInputError
from .streams import Streams

__all__ = [
    "DEFAULT_FRAMES",
    "FLAGS",
    "GIVEN",
    "MAX_SAMPLES",
    "PROG",
    "bad_value",
    "cannot_write",
    "exact_gas",
    "kernels_choice",
    "no_memory",
    "observe_checked",
    "open_trajectory",
    "trajectory_checked",
    "warn_if_gaining",
]


PROG = "collisionlab gas"


#: Library field name -> the flag a user typed.
FLAGS = {
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


#: ``--frames`` when ``--trajectory`` is given alone: the start and every tenth of the run.
DEFAULT_FRAMES = 11


#: The Namespace attribute listing the options typed on the command line (not left at default).
GIVEN = "given_options"


def kernels_choice(args: argparse.Namespace) -> str:
    """``--kernels``, or what ``--backend`` (its older name) says: ``auto``, ``python`` or ``compiled``."""
    if args.backend is None:
        return "auto" if args.kernels is None else str(args.kernels)
    alias = "compiled" if args.backend == "numba" else str(args.backend)
    if args.kernels is not None and args.kernels != alias:
        raise InvalidInputError(
            "kernels", f"{args.kernels} disagrees with --backend {args.backend} (its older name); give one of them"
        )
    return alias


def no_memory(streams: Streams, n: int) -> int:
    """The one line for a gas of ``n`` balls that this machine's memory cannot hold; status 1."""
    streams.err(f"{PROG}: --n: not enough memory for {n:,} balls")
    return 1


def warn_if_gaining(streams: Streams, restitution: float) -> None:
    """A warning when ``e > 1``: allowed (the lab's postlab asks what it does), but every collision
    then adds kinetic energy."""
    if restitution > 1.0:
        streams.err(f"warning: restitution {restitution:g} > 1: every collision adds kinetic energy")


def bad_value(streams: Streams, err: InvalidInputError) -> int:
    streams.err(
        f"{PROG}: {FLAGS.get(err.field, err.field)}: {err.problem}"
        + (f" (got {err.got!r})" if err.got is not None else "")
    )
    return 2


def trajectory_checked(args: argparse.Namespace) -> int:
    """``--frames`` (its default when only ``--trajectory`` is given), the file's format and
    folder checked before the run (:class:`InvalidInputError`; a missing ``gsd``:
    :class:`~collisionlab.extras.MissingExtraError`); 0 without ``--trajectory``."""
    from ..atomic import check_target
    from ..trajectory import check_frames, require_gsd, trajectory_format

    if args.trajectory is None:
        if args.frames is not None:
            raise InvalidInputError("frames", "needs --trajectory FILE")
        return 0
    frames = check_frames(DEFAULT_FRAMES if args.frames is None else args.frames)
    kind = trajectory_format(args.trajectory)
    check_target(args.trajectory, "trajectory")
    if kind == "gsd":
        require_gsd()
    return frames


def open_trajectory(args: argparse.Namespace, sides: tuple[float, ...], periodic: bool, types: Any) -> Any:
    """The frame writer of ``--trajectory`` (a context manager) for the balls ``types``
    (:class:`~collisionlab.trajectory.Types`), or one that yields ``None``."""
    from ..trajectory import trajectory_file

    if args.trajectory is None:
        return contextlib.nullcontext(None)
    return trajectory_file(args.trajectory, sides, periodic, types)


def cannot_write(streams: Streams, args: argparse.Namespace, err: OSError) -> int:
    """One line naming the file (``--trajectory`` or ``--events``) that could not be written."""
    trajectory = args.trajectory is not None and (args.events is None or err.filename == args.trajectory)
    flag, path = ("--trajectory", args.trajectory) if trajectory else ("--events", args.events)
    streams.err(f"{PROG}: {flag}: cannot write {path}: {err.strerror or err}")
    return 1


def observe_checked(args: argparse.Namespace) -> tuple[str, ...]:
    """``--observe``'s names and ``--samples`` checked (:class:`InvalidInputError`); ``()``
    without ``--observe``."""
    from ..edmd.structure import parse_observables

    if args.observe is None:
        if args.samples is not None:
            raise InvalidInputError("samples", "needs --observe rdf,msd")
        return ()
    observe = parse_observables(args.observe)
    if args.samples is not None and not 1 <= args.samples <= MAX_SAMPLES:
        raise InvalidInputError("samples", f"must be 1 to {MAX_SAMPLES:,}", got=args.samples)
    return observe


#: ``--samples`` at most (each one counts every pair of balls for g(r)).
MAX_SAMPLES = 100_000


def exact_gas(args: argparse.Namespace, species: tuple[Any, ...]) -> Any:
    """The event-driven gas (``ExactGas``) the options ask for, not yet checked."""
    from ..edmd.exact_gas import ExactGas  # (here: the gas's modules load only when it runs)

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
