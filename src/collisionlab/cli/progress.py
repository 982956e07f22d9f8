"""Progress on standard error for runs that take more than a moment: a bar redrawn in place on
a terminal; in a log (stderr not a terminal), a line every ``LOG_EVERY`` seconds (or what the
environment's ``COLLISIONLAB_LOG_EVERY`` says)."""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Mapping

from .streams import Streams

__all__ = ["LOG_EVERY", "LOG_EVERY_VARIABLE", "REDRAW_EVERY", "SHOW_AFTER", "ProgressBar", "log_every", "log_interval"]

#: Seconds a run must last before a bar appears: short runs print nothing extra.
SHOW_AFTER = 1.0
#: Seconds between two progress lines when standard error is not a terminal (a log, CI, nohup):
#: often enough to show the run is alive, rarely enough not to flood the log.
LOG_EVERY = 10.0
#: The environment variable that sets those seconds instead (a number > 0): a CI log that wants
#: a line a second, a batch job that wants one a minute.
LOG_EVERY_VARIABLE = "COLLISIONLAB_LOG_EVERY"
#: Seconds between two redraws of the bar (a terminal redraws fast; more is only flicker).
REDRAW_EVERY = 0.1
#: Characters of the bar.
_BAR_WIDTH = 30


def log_every(environ: Mapping[str, str] = os.environ) -> tuple[float, str | None]:
    """Seconds between two progress lines in a log: :data:`LOG_EVERY_VARIABLE` if it is set to a
    number > 0, else :data:`LOG_EVERY`; and, for a value that is not such a number, the one-line
    warning to print (the run goes on with the default).

    >>> log_every({}), log_every({"COLLISIONLAB_LOG_EVERY": "2.5"})
    ((10.0, None), (2.5, None))
    >>> log_every({"COLLISIONLAB_LOG_EVERY": "soon"})[1]
    "warning: COLLISIONLAB_LOG_EVERY: expected seconds, a number > 0, got 'soon'; using 10"
    """
    text = environ.get(LOG_EVERY_VARIABLE)
    if text is None:
        return LOG_EVERY, None
    try:
        seconds = float(text)
    except ValueError:
        seconds = math.nan
    if not (math.isfinite(seconds) and seconds > 0.0):
        expected = "expected seconds, a number > 0"
        return LOG_EVERY, f"warning: {LOG_EVERY_VARIABLE}: {expected}, got {text!r}; using {LOG_EVERY:g}"
    return seconds, None


def log_interval(streams: Streams, quiet: bool) -> float:
    """:func:`log_every` for a progress display on ``streams``: a bad value's warning goes to
    stderr once, when the display would print lines to a log (not quiet, not a terminal)."""
    seconds, warning = log_every()
    if warning is not None and not quiet and not streams.err_terminal:
        streams.err(warning)
    return seconds


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
        self.log_every = log_interval(streams, quiet)

    def __call__(self, done: int, total: int) -> None:
        if self.quiet:
            return
        now = self.clock()
        elapsed = now - self.started
        if not self.streams.err_terminal:
            if now - self.last_draw >= self.log_every:
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
