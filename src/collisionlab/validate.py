"""Input checks shared by shapes, resolution, the world and scenario files.

Each check returns the cleaned value or raises :class:`InvalidInputError` naming the field.
"""

from __future__ import annotations

import math
import numbers
import unicodedata

import numpy as np

from .errors import InvalidInputError

__all__ = ["finite_number", "non_negative", "positive", "positive_or_inf", "printable", "whole_number"]


def _scalar(value: object) -> object:
    """A numpy 0-d array of a real number as a Python number; anything else unchanged."""
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf":
        return value.item()
    return value


def finite_number(value: object, field: str) -> float:
    """A real, finite number as a float (numpy scalars and 0-d arrays included).

    >>> finite_number(2, "dt")
    2.0
    >>> finite_number(np.array(0.5), "radius"), finite_number(np.float32(0.5), "radius")
    (0.5, 0.5)
    >>> finite_number(True, "dt")
    Traceback (most recent call last):
    ...
    collisionlab.errors.InvalidInputError: dt: must be a number (got True)
    >>> finite_number(float("nan"), "dt")
    Traceback (most recent call last):
    ...
    collisionlab.errors.InvalidInputError: dt: must be a finite number (got nan)
    """
    value = _scalar(value)
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise InvalidInputError(field, "must be a number", got=value)
    try:
        number = float(value)
    except OverflowError:  # an integer (or Fraction) beyond the largest double, 1.8e308
        raise InvalidInputError(field, "must be a finite number; this one is too large", got=value) from None
    if not math.isfinite(number):
        raise InvalidInputError(field, "must be a finite number", got=number)
    return number


def positive(value: object, field: str) -> float:
    """A finite number > 0."""
    number = finite_number(value, field)
    if number <= 0.0:
        raise InvalidInputError(field, "must be > 0", got=number)
    return number


def non_negative(value: object, field: str) -> float:
    """A finite number >= 0."""
    number = finite_number(value, field)
    if number < 0.0:
        raise InvalidInputError(field, "must be >= 0", got=number)
    return number


def positive_or_inf(value: object, field: str) -> float:
    """A number > 0, where ``math.inf`` is allowed (a static body's mass)."""
    value = _scalar(value)
    if isinstance(value, numbers.Real) and not isinstance(value, bool) and value == math.inf:
        return math.inf
    if isinstance(value, numbers.Real) and not isinstance(value, bool) and not value > 0:  # type: ignore[operator]
        raise InvalidInputError(field, "must be > 0 (math.inf for a static body)", got=value)
    return positive(value, field)


def whole_number(value: object, field: str, minimum: int = 1) -> int:
    """An integer >= ``minimum`` (floats with no fractional part are accepted)."""
    value = _scalar(value)
    if isinstance(value, bool) or not isinstance(value, numbers.Integral | numbers.Real):
        raise InvalidInputError(field, f"must be a whole number >= {minimum}", got=value)
    if isinstance(value, numbers.Integral):  # exact, however large (a range check comes later)
        if int(value) < minimum:
            raise InvalidInputError(field, f"must be a whole number >= {minimum}", got=value)
        return int(value)
    try:
        number = float(value)
    except OverflowError:
        raise InvalidInputError(
            field, f"must be a whole number >= {minimum}; this one is too large", got=value
        ) from None
    if not math.isfinite(number) or number != int(number) or number < minimum:
        raise InvalidInputError(field, f"must be a whole number >= {minimum}", got=value)
    return int(number)


def printable(text: str, field: str) -> str:
    """``text`` when it holds no control or format character (an escape sequence, a newline, a
    NUL, a bidi override): names and titles are printed, and must not forge output lines.

    >>> printable("ball A", "name")
    'ball A'
    >>> printable("ball\\x1b[2J", "name")
    Traceback (most recent call last):
    ...
    collisionlab.errors.InvalidInputError: name: must not hold a control character (U+001B) (got 'ball\\x1b[2J')
    """
    for char in text:
        if unicodedata.category(char) in ("Cc", "Cf", "Cs", "Zl", "Zp"):
            raise InvalidInputError(field, f"must not hold a control character (U+{ord(char):04X})", got=text)
    return text
