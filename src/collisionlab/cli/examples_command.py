"""``collisionlab examples``: list the scenario files shipped inside the package, or copy them
out (``--copy DIR``) to read and edit. ``collisionlab run NAME`` runs one by name."""

from __future__ import annotations

import argparse
from typing import Any

from ..demos import builtin_scenario_path, copy_examples, demo_names, load_demo, sweep_names
from .streams import Streams

__all__ = ["add_parser"]


def add_parser(sub: Any) -> None:
    parser = sub.add_parser(
        "examples",
        help="list the shipped scenario files, or copy them to a folder (--copy DIR)",
        description=(
            "The scenario files shipped with collisionlab. Run one with 'collisionlab run NAME'; "
            "copy them all with --copy DIR to read and edit them."
        ),
    )
    parser.add_argument("--copy", metavar="DIR", help="write every example into DIR (created if missing)")
    parser.set_defaults(func=_examples)


def _examples(args: argparse.Namespace, streams: Streams) -> int:
    if args.copy:
        paths = copy_examples(args.copy)
        streams.err(f"wrote {len(paths)} scenario files to {args.copy}")
        return 0
    for name in demo_names():
        streams.out(f"{name:<16}{load_demo(name).title}")
    streams.out("\nsweep files (collisionlab sweep NAME):")
    for name in sweep_names():
        streams.out(f"  {name}")
    streams.out(f"\nshipped in {builtin_scenario_path(demo_names()[0]).parent}")  # type: ignore[union-attr]
    streams.out("run one: collisionlab run NAME; copy them: collisionlab examples --copy DIR")
    return 0
