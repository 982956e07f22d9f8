"""The ``collisionlab`` command line: parsing, prompting and printing only; no physics.

Exit status: 0 success, 1 end of input or other failure, 2 bad command-line usage,
65 invalid scenario data (or numbers too large to simulate), 130 interrupted (Ctrl-C),
143 and 129 stopped by SIGTERM and SIGHUP (handled as Ctrl-C).
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import os
import sys
from collections.abc import Sequence

from .. import __version__
from ..errors import CollisionLabError, InvalidInputError, OutOfRangeError, escape_controls
from ..scenario_file import ScenarioError
from ..world import InitialOverlapError
from . import compile_command, examples_command, gas_command, sweep_command
from .interrupts import Stopped, abandoned_work, stop_on_signals
from .run_command import add_run_parsers
from .streams import Streams

__all__ = ["EXIT_DATA", "EXIT_FAILURE", "EXIT_INTERRUPTED", "EXIT_USAGE", "Streams", "entry_point", "main"]

EXIT_FAILURE = 1
EXIT_USAGE = 2
EXIT_DATA = 65  # EX_DATAERR from sysexits.h
EXIT_INTERRUPTED = 130


class UsageError(Exception):
    """Bad command-line usage (exit status 2)."""


class _Parser(argparse.ArgumentParser):
    """argparse that writes to our streams and raises instead of exiting, so tests can drive it."""

    streams: Streams

    def error(self, message: str) -> None:  # type: ignore[override]
        # The message echoes what was typed: escaped, so a newline in an argument stays one line.
        raise UsageError(f"{self.format_usage().rstrip()}\n{self.prog}: error: {escape_controls(message)}")

    def _print_message(self, message: str, file: object = None) -> None:
        if message:
            self.streams.stdout.write(message)

    def exit(self, status: int = 0, message: str | None = None) -> None:  # type: ignore[override]
        if message:
            self.streams.stderr.write(message)
        raise SystemExit(status)


def build_parser(streams: Streams) -> argparse.ArgumentParser:
    class Parser(_Parser):
        pass

    Parser.streams = streams
    parser = Parser(
        prog="collisionlab",
        description=(
            "Collision detection and resolution of simple shapes. With no arguments on a terminal, "
            "the lab's menu asks which case to simulate and its parameters."
        ),
    )
    parser.add_argument("--version", action="version", version=f"collisionlab {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    menu = sub.add_parser("menu", help="the lab's interactive menu (also reads answers from a pipe)")
    menu.set_defaults(func=lambda args, streams: _menu(streams))
    add_run_parsers(sub)
    gas_command.add_parser(sub)
    examples_command.add_parser(sub)
    sweep_command.add_parser(sub)
    compile_command.add_parser(sub)
    return parser


def _menu(streams: Streams) -> int:
    from .menu import run_menu  # here: the other commands start without it

    return run_menu(streams)


def _dispatch(parser: argparse.ArgumentParser, args_list: list[str], streams: Streams) -> int:
    if not args_list:
        if streams.interactive:
            return _menu(streams)
        streams.err(parser.format_usage().rstrip())
        streams.err(
            "collisionlab: no command given and standard input is not a terminal; "
            "use 'collisionlab menu' to answer the menu from a pipe, or 'collisionlab demo'"
        )
        return EXIT_USAGE
    args = parser.parse_args(args_list)
    if args.command is None:
        streams.err(parser.format_usage().rstrip())
        return EXIT_USAGE
    status: int = args.func(args, streams)
    return status


def main(argv: Sequence[str] | None = None, streams: Streams | None = None) -> int:
    """Run the command line with ``argv`` and return the exit status (never raises)."""
    streams = streams or Streams()
    args_list = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser(streams)
    try:
        with stop_on_signals():  # SIGTERM and SIGHUP as Ctrl-C: atomic writes clean up
            return _dispatch(parser, args_list, streams)
    except UsageError as error:
        streams.err(str(error))
        return EXIT_USAGE
    except SystemExit as stop:  # --help and argparse's own exits
        return stop.code if isinstance(stop.code, int) else EXIT_FAILURE
    except (ScenarioError, OutOfRangeError, InitialOverlapError) as error:  # bad data, or too large to simulate
        streams.err(f"collisionlab: invalid scenario: {error}")
        return EXIT_DATA
    except InvalidInputError as error:
        streams.err(f"collisionlab: {error}")
        return EXIT_USAGE
    except CollisionLabError as error:
        streams.err(f"collisionlab: {error}")
        return EXIT_FAILURE
    except Stopped as stop:
        streams.err(f"\ncollisionlab: stopped by {stop.name}")
        return stop.status
    except KeyboardInterrupt:
        streams.err("\ncollisionlab: interrupted")
        return EXIT_INTERRUPTED
    except EOFError:
        streams.err("\ncollisionlab: end of input")
        return EXIT_FAILURE
    except BrokenPipeError:
        return EXIT_FAILURE
    except OSError as error:
        named = f"{error.filename}: " if error.filename else ""
        streams.err(f"collisionlab: {named}{error.strerror or error}")
        return EXIT_FAILURE
    except Exception as error:  # a bug: still one line, no traceback, and a way to report it
        streams.err(f"collisionlab: unexpected error: {type(error).__name__}: {error} (please report this)")
        return EXIT_FAILURE


def entry_point() -> None:
    """The console script (and ``python -m collisionlab``): :func:`main`, then exit with its
    status. Python's last garbage collection, at exit, walks every object still alive, and
    numba's compiler leaves very many (a quarter of a second, bench/README.md); the process
    frees them all anyway, so they are frozen out of that collection first.

    A signal that stopped a compile left it running in its thread (:func:`.interrupts.interruptible`):
    the process then ends at once, its streams flushed, rather than run Python's exit beside it."""
    status = main()
    if abandoned_work():
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(OSError, ValueError):
                stream.flush()
        os._exit(status)
    gc.freeze()
    sys.exit(status)
