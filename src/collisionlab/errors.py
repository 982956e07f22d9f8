"""Exceptions raised by collisionlab.

Every error about bad input is an :class:`InvalidInputError` (a ``ValueError``) whose ``field``
names what was wrong, so that a command-line front end can print one line and no traceback.
"""

from __future__ import annotations

__all__ = ["CollisionLabError", "InvalidInputError", "UnsupportedPairError"]


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
        message = f"{field}: {problem}"
        if got is not None:
            message += f" (got {got!r})"
        super().__init__(message)

    def renamed(self, field: str) -> InvalidInputError:
        """The same error reported under another field name (e.g. a scenario key path)."""
        return InvalidInputError(field, self.problem, self.got)


class UnsupportedPairError(CollisionLabError, TypeError):
    """Raised when no query exists for a pair of shape types; never a silent ``False``."""
