"""The ``collisionlab`` command line (placeholder until the simulator lands)."""

from __future__ import annotations

import sys

__all__ = ["entry_point", "main"]


def main(argv: list[str] | None = None) -> int:
    return 0


def entry_point() -> None:
    sys.exit(main(sys.argv[1:]))
