"""How many steps a world's next compiled call runs (a chunk), and the one look between chunks
that is not a range check: whether exact mode resolves a pile's lasting contact as micro-impacts.

A chunk aims at ``CHUNK_SECONDS`` of work at the pace of the last one, so that progress and
Ctrl-C (looked at between calls) are never far away; the exact steppers of bodies among
obstacles aim lower, since their steps can slow down a hundredfold at once.
"""

from __future__ import annotations

__all__ = [
    "CHUNK_BODY_STEPS",
    "CHUNK_EVENT_ROWS",
    "CHUNK_SECONDS",
    "EXACT_CHUNK_SECONDS",
    "PILE_HINT_STEPS",
    "PILE_HINT_WORK",
    "PileHint",
    "next_chunk",
]

#: Seconds one compiled call aims to run before control returns (for progress and Ctrl-C, which
#: is looked at between calls: it stops a run within a second).
CHUNK_SECONDS = 0.25
#: Exact mode with ``contacts = "events"`` under gravity: more impulses than this per body and
#: step, over at least ``PILE_HINT_STEPS`` steps, is resting contact resolved as a stream of
#: micro-impacts (a pile: tens of thousands per body-step), and the world says once that
#: ``contacts = "solve"`` is made for it (30-60 circles settling: 105-253). The shipped examples
#: in exact mode stay at 0.003-0.06 (a bouncing ball 0.06, a stack 0.02, a cradle 0.005).
PILE_HINT_WORK = 100
PILE_HINT_STEPS = 20
#: What an exact stepper's chunk aims at instead: its steps can grow a hundredfold dearer within a
#: few (2,000 circles landing in a pile: 64 steps took 0.18 s, the next 82 took 36 s, measured),
#: so a chunk sized on fast steps must be short to stay within seconds when they slow down. (A
#: chunk's call costs about 1 ms beside its steps: at this aim, a few per cent at most.)
EXACT_CHUNK_SECONDS = CHUNK_SECONDS / 10
#: Body-steps one exact chunk may hold (32 steps of 2,000 bodies): at its aim alone, steps of
#: falling bodies (0.2 ms each for 2,000 circles) grew a chunk to 128 steps, and the bodies landed
#: inside it (0.4 s a step: a chunk of a minute, 1.4M events). A few per cent more calls while
#: steps are that cheap; worlds of a few bodies are not held back.
CHUNK_BODY_STEPS = 1 << 16
#: Event rows a chunk may produce, going by the last chunk's rate: the kernel keeps a chunk's rows
#: (208 bytes each) until it returns, and a pile's steps make up to 100,000 impacts each.
CHUNK_EVENT_ROWS = 1 << 20


def next_chunk(chunk: int, count: int, took: float, events: int, exact: bool, bodies: int) -> int:
    """Steps for the next compiled call, after one of ``count`` steps (``chunk`` asked) took
    ``took`` seconds and made ``events`` collision events: as many as would take
    ``CHUNK_SECONDS`` at the last call's pace (``EXACT_CHUNK_SECONDS`` for the ``exact``
    steppers of bodies among obstacles, whose steps can slow down a hundredfold at once: their
    chunks also hold ``CHUNK_BODY_STEPS`` body-steps of ``bodies`` at most; not the event-driven
    one's balls in a box), at most 4 times as many as the last, and about ``CHUNK_EVENT_ROWS``
    events at most.

    >>> next_chunk(16, 16, 0.02, 0, False, 1), next_chunk(16, 16, 0.5, 0, False, 1)  # 16 * 0.25 / 0.5
    (64, 8)
    >>> next_chunk(16, 16, 0.0, 0, False, 1)   # too fast to time: 4 times the last
    64
    >>> next_chunk(64, 64, 0.01, 64 * CHUNK_EVENT_ROWS // 2, False, 1)  # events: 2 steps' worth at most
    2
    >>> next_chunk(64, 64, 0.001, 0, True, 2_000)  # 65,536 body-steps / 2,000 bodies
    32
    """
    aim = EXACT_CHUNK_SECONDS if exact else CHUNK_SECONDS
    steps = min(4 * chunk, int(count * aim / took)) if took > 0.0 else 4 * chunk
    if exact:
        steps = min(steps, CHUNK_BODY_STEPS // max(bodies, 1))
    if events > 0:
        steps = min(steps, count * CHUNK_EVENT_ROWS // events)
    return max(1, steps)


class PileHint:
    """Whether exact mode with ``contacts = "events"`` resolves lasting contact as micro-impacts
    (``PILE_HINT_WORK`` impulses per body and step, over ``PILE_HINT_STEPS`` steps at least):
    :meth:`look` returns the warning once, then never again.

    >>> hint = PileHint(bodies=10)
    >>> hint.look(5_000, 10, 10) is None  # 50 a body-step, and too few steps to tell
    True
    >>> # 20 steps now: (5,000 + 300,000) / (10 bodies * 20 steps) = 1,525 a body-step
    >>> print(hint.look(300_000, 10, 20))  # doctest: +ELLIPSIS
    bodies resting on each other: 1.52e+03 impulses per body and step up to step 20, ...
    >>> hint.look(300_000, 10, 30) is None  # said once
    True
    """

    def __init__(self, bodies: int) -> None:
        self._bodies = bodies
        self._work = 0  # impulses since the last look; -1 once said
        self._steps = 0

    def look(self, work: int, steps: int, step_index: int) -> str | None:
        """Add ``work`` impulses over ``steps`` steps (up to step ``step_index``); the warning
        if that makes a pile, else ``None``."""
        if self._work < 0:
            return None
        self._work += work
        self._steps += steps
        if self._steps < PILE_HINT_STEPS:
            return None
        n = self._bodies
        if self._work > PILE_HINT_WORK * n * self._steps:
            rate = self._work / (n * self._steps)
            self._work = -1
            return (
                f"bodies resting on each other: {rate:.3g} impulses per body and step up to step "
                f'{step_index}, resting contact resolved as a stream of impacts; contacts = "solve" (or '
                "--contacts solve) solves it as contact and lets piles come to rest (README, 'Piles, pours and stacks')"
            )
        self._work = self._steps = 0
        return None
