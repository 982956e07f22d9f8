"""Numbers as text without signed zeros: ``-0.0``, or ``-0.000`` from a tiny negative number,
reads as a different value to a person and is never printed."""

from __future__ import annotations

__all__ = ["format_float"]


def format_float(value: float, spec: str) -> str:
    """``format(value, spec)``, with the minus sign dropped when every printed digit is zero.

    >>> format_float(-1e-9, ".3f"), format_float(-0.0, "g"), format_float(-0.5, ".1f")
    ('0.000', '0', '-0.5')
    >>> format_float(-1e-9, ".2e"), format_float(-1e-9, ">+8.2f")
    ('-1.00e-09', '   +0.00')
    """
    text = format(value, spec)
    if "-" in text and not any(c in "123456789" for c in text.lower().split("e")[0]) and "inf" not in text:
        return format(abs(value), spec)  # the same width, padding and sign rules
    return text
