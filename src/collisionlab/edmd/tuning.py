"""The event-driven world's tunables: the neighbour lists' reach, the calendar's blocks and
horizon, the cells' slots and the streamed blocks' size, each fitted or measured where its
comment says (bench/bench_edmd.py). Plain Python, read when a world is made: a change here
compiles nothing again."""

from __future__ import annotations

__all__ = [
    "BUFFER_EVENTS",
    "CELL_SLOTS",
    "EVENTS_PER_BLOCK",
    "HORIZON",
    "MIXED_REACH_2D",
    "SHELL",
    "SHELL_AT_QUARTER",
    "SHELL_EXPONENT",
    "SHELL_MAX",
    "SHELL_MIN",
    "shell_for",
]

#: Neighbour-list reach in diameters (Smallenburg's ``1 + alpha``; he uses 1.5) in 2D and under
#: gravity (where the mean density says little about a pile's).
SHELL = 1.7
#: In 3D without gravity the reach follows the packing fraction: a wider shell means fewer list
#: rebuilds but more neighbours to test at every prediction, and the balance moves to narrower
#: shells as the fluid gets denser. ``SHELL_AT_QUARTER * (fraction / 0.25) ** -SHELL_EXPONENT``,
#: within ``[SHELL_MIN, SHELL_MAX]``, was fitted to the fastest shells of bench/bench_edmd.py.
#: ``SHELL_MAX`` keeps the reach within half of the smallest periodic box (4 diameters).
SHELL_AT_QUARTER = 2.0
SHELL_EXPONENT = 0.38
SHELL_MIN = 1.4
SHELL_MAX = 2.0
#: A gas of discs of several sizes (no gravity) lists neighbours at least this many mean
#: diameters beyond its largest contact distance (fitted in bench/bench_edmd.py --mixtures).
MIXED_REACH_2D = 1.2
#: Calendar: scheduled events per block of the near-future heap, and how many typical event
#: times the ring of lists covers before the overflow list (tuned in bench/bench_edmd.py).
EVENTS_PER_BLOCK = 8.0
HORIZON = 4.0
#: Slots of a cell's row (its count and up to 15 bodies, 256 bytes): doubled when one fills.
CELL_SLOTS = 16
#: Events held before a streamed block is handed to the sink.
BUFFER_EVENTS = 1 << 16


def shell_for(dim: int, fraction: float, gravity: float) -> float:
    """The neighbour-list reach in diameters for a box of packing ``fraction`` (see ``SHELL``).

    >>> shell_for(3, 0.25, 0.0), shell_for(2, 0.25, 0.0), shell_for(3, 0.05, 0.0)
    (2.0, 1.7, 2.0)
    """
    if dim != 3 or gravity > 0.0:
        return SHELL
    if fraction <= 0.0:
        return SHELL_MAX
    return min(SHELL_MAX, max(SHELL_MIN, SHELL_AT_QUARTER * float((fraction / 0.25) ** -SHELL_EXPONENT)))
