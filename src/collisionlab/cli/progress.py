"""A progress bar on standard error for runs that take more than a moment on a terminal."""

from __future__ import annotations

import time

from .streams import Streams

__all__ = ["ProgressBar"]

#: Seconds a run must last before a bar appears: short runs print nothing extra.
SHOW_AFTER = 1.0


class ProgressBar:
    """Callable as ``progress(done, total)``; draws only when the streams are interactive."""

    def __init__(self, streams: Streams, label: str = "") -> None:
        self.streams = streams
        self.label = label
        self.started = time.monotonic()
        self.drawn = False
        self.last_draw = 0.0

    def __call__(self, done: int, total: int) -> None:
        if not self.streams.interactive:
            return
        now = time.monotonic()
        if now - self.started < SHOW_AFTER or (now - self.last_draw < 0.1 and done < total):
            return
        self.last_draw = now
        width = 30
        filled = int(width * done / max(total, 1))
        rate = done / (now - self.started)  # > SHOW_AFTER here: never zero
        self.streams.stderr.write(
            f"\r{self.label} [{'#' * filled}{'.' * (width - filled)}] {done}/{total} ({rate:,.0f}/s)"
        )
        self.streams.stderr.flush()
        self.drawn = True

    def close(self) -> None:
        if self.drawn:
            self.streams.stderr.write("\n")
            self.drawn = False
