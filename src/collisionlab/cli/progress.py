"""Progress on standard error for runs that take more than a moment: a bar redrawn in place on
a terminal; in a log (stderr not a terminal), a line every ``LOG_EVERY`` seconds."""

from __future__ import annotations

import time
from collections.abc import Callable

from .streams import Streams

__all__ = ["LOG_EVERY", "REDRAW_EVERY", "SHOW_AFTER", "ProgressBar"]

#: Seconds a run must last before a bar appears: short runs print nothing extra.
SHOW_AFTER = 1.0
#: Seconds between two progress lines when standard error is not a terminal (a log, CI, nohup):
#: often enough to show the run is alive, rarely enough not to flood the log.
LOG_EVERY = 10.0
#: Seconds between two redraws of the bar (a terminal redraws fast; more is only flicker).
REDRAW_EVERY = 0.1
#: Characters of the bar.
_BAR_WIDTH = 30


class ProgressBar:
    """Callable as ``progress(done, total)``. On a terminal (``streams.err_terminal``) a bar
    redrawn in place after ``SHOW_AFTER`` seconds; else a line every ``LOG_EVERY`` seconds (none
    for a run shorter than that); nothing if ``quiet``. ``clock`` is injectable for tests."""

    def __init__(
        self, streams: Streams, label: str = "", quiet: bool = False, clock: Callable[[], float] = time.monotonic
    ) -> None:
        self.streams = streams
        self.label = label
        self.quiet = quiet
        self.clock = clock
        self.started = clock()
        self.drawn = False
        self.last_draw = self.started

    def __call__(self, done: int, total: int) -> None:
        if self.quiet:
            return
        now = self.clock()
        elapsed = now - self.started
        if not self.streams.err_terminal:
            if now - self.last_draw >= LOG_EVERY:
                self.last_draw = now
                left = f", about {(total - done) * elapsed / done:.0f} s left" if done else ""
                self.streams.err(
                    f"{self.label}: {done}/{total} ({100.0 * done / max(total, 1):.0f}%), {elapsed:.0f} s{left}"
                )
            return
        if elapsed < SHOW_AFTER or (now - self.last_draw < REDRAW_EVERY and done < total):
            return
        self.last_draw = now
        filled = int(_BAR_WIDTH * done / max(total, 1))
        rate = done / elapsed  # > SHOW_AFTER here: never zero
        self.streams.stderr.write(
            f"\r{self.label} [{'#' * filled}{'.' * (_BAR_WIDTH - filled)}] {done}/{total} ({rate:,.0f}/s)"
        )
        self.streams.stderr.flush()
        self.drawn = True

    def close(self) -> None:
        if self.drawn:
            self.streams.stderr.write("\n")
            self.drawn = False
