"""Exceptions raised by collisionlab.

Every error about bad input is an :class:`InvalidInputError` (a ``ValueError``) whose ``field``
names what was wrong, so that a command-line front end can print one line and no traceback.
"""

from __future__ import annotations

import difflib
import unicodedata
from collections.abc import Iterable

__all__ = [
    "MESSAGE_VALUE_CHARS",
    "CollisionLabError",
    "InvalidInputError",
    "OutOfRangeError",
    "UnsupportedPairError",
    "did_you_mean",
    "escape_controls",
    "shorten",
]


def did_you_mean(word: str, choices: Iterable[str]) -> str:
    """``"did you mean 'X'? "`` for the choice closest to ``word`` (a typo), or ``""`` when none
    is close (difflib's ratio at least 0.6).

    >>> did_you_mean("restitutoin", ["restitution", "mode"]), did_you_mean("colour", ["mode"])
    ("did you mean 'restitution'? ", '')
    """
    close = difflib.get_close_matches(word, list(choices), n=1)
    return f"did you mean {close[0]!r}? " if close else ""


#: Characters: the longest value (or field name) an error message repeats; longer ones are cut
#: in the middle, so a 100 MB bad value gives a one-line message, not a 100 MB line.
MESSAGE_VALUE_CHARS = 60


def escape_controls(text: str, keep: str = "") -> str:
    """``text`` with every control or format character (escapes, newlines, NUL, line separators;
    all but those in ``keep``) written as ``\\xNN`` or ``\\uNNNN``, so a value echoed in a message
    can neither break it into lines nor drive the terminal.

    >>> escape_controls("a\\nb\\x1b[2J")
    'a\\\\nb\\\\x1b[2J'
    """
    out = []
    for char in text:
        if char not in keep and unicodedata.category(char) in ("Cc", "Cf", "Cs", "Zl", "Zp"):
            out.append(repr(char)[1:-1] if char.isascii() else f"\\u{ord(char):04x}")
        else:
            out.append(char)
    return "".join(out)


def shorten(text: str, limit: int = MESSAGE_VALUE_CHARS) -> str:
    """``text`` cut to about ``limit`` characters, its start and end kept around "...".

    >>> shorten("x" * 10, 6)
    'xxx...xxx'
    >>> shorten("short")
    'short'
    """
    if len(text) <= limit:
        return text
    half = limit // 2
    return f"{text[:half]}...{text[-half:]}"


class CollisionLabError(Exception):
    """Base class of every error collisionlab raises on purpose."""


class InvalidInputError(CollisionLabError, ValueError):
    """A value that cannot be used: the message names the field and the expected form.

    >>> err = InvalidInputError("radius", "must be > 0", got=-1.0)
    >>> str(err)
    'radius: must be > 0 (got -1.0)'
    >>> err.field
    'radius'
    """

    def __init__(self, field: str, problem: str, got: object = None) -> None:
        self.field = field
        self.problem = problem
        self.got = got
        message = f"{escape_controls(shorten(field))}: {problem}"
        if got is not None:
            message += f" (got {_value_text(got)})"
        super().__init__(message)

    def renamed(self, field: str) -> InvalidInputError:
        """The same error reported under another field name (e.g. a scenario key path)."""
        return InvalidInputError(field, self.problem, self.got)


def _value_text(got: object) -> str:
    """``repr(got)``, shortened; a huge integer is described, not printed (its ``repr`` alone can
    take seconds past 4300 digits and is refused by Python)."""
    if isinstance(got, int) and not isinstance(got, bool) and got.bit_length() > 200:
        return f"an integer of about {int(got.bit_length() * 0.30103)} digits"
    return shorten(repr(got))


class OutOfRangeError(CollisionLabError, ArithmeticError):
    """A run whose numbers grew beyond the range collisionlab simulates (see
    :mod:`collisionlab.limits`): the scenario's numbers are too large to simulate.

    >>> str(OutOfRangeError("step 3: too large").within("drop.toml"))
    'drop.toml: step 3: too large'
    """

    def within(self, source: str) -> OutOfRangeError:
        """The same error, naming the scenario's file (or demo) first."""
        return OutOfRangeError(f"{escape_controls(source)}: {self}")


class UnsupportedPairError(CollisionLabError, TypeError):
    """Raised when no query exists for a pair of shape types; never a silent ``False``."""
