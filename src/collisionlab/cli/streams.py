"""The command line's streams, injectable so that tests drive the CLI without a terminal."""

from __future__ import annotations

import sys
from dataclasses import dataclass, field
from typing import TextIO

from ..errors import escape_controls, shorten

__all__ = ["ERROR_LINE_CHARS", "Streams"]

#: Characters: the longest line written to stderr. Error lines echo what was typed (a path, a
#: flag's value: up to 128 kB each on Linux); a longer line is cut in the middle ("..."), so its
#: start (the option or file) and its end (the reason, or the end of the value) both show.
ERROR_LINE_CHARS = 300


@dataclass
class Streams:
    """Where the CLI reads answers and writes output and errors.

    ``interactive`` says whether stdin is a terminal a person types into (it decides whether a
    bare ``collisionlab`` opens the menu); ``err_terminal`` whether stderr is a terminal (a
    progress bar is then redrawn in place; in a log, a line now and then).
    """

    stdin: TextIO = field(default_factory=lambda: sys.stdin)
    stdout: TextIO = field(default_factory=lambda: sys.stdout)
    stderr: TextIO = field(default_factory=lambda: sys.stderr)
    interactive: bool | None = None
    err_terminal: bool | None = None

    def __post_init__(self) -> None:
        if self.interactive is None:
            self.interactive = _is_terminal(self.stdin)
        if self.err_terminal is None:
            self.err_terminal = _is_terminal(self.stderr)

    def out(self, text: str = "") -> None:
        self.stdout.write(text + "\n")

    def err(self, text: str) -> None:
        """One message (a usage error's usage before it); a control character that a value
        carried in is escaped, so it can neither forge lines nor drive the terminal, and each
        line is at most about ``ERROR_LINE_CHARS`` long."""
        lines = escape_controls(text, keep="\n").split("\n")
        self.stderr.write("\n".join(shorten(line, ERROR_LINE_CHARS) for line in lines) + "\n")


def _is_terminal(stream: TextIO) -> bool:
    try:
        return stream.isatty()
    except (AttributeError, ValueError):  # not a file, or a closed one
        return False
