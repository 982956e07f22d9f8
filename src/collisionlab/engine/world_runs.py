"""How a world runs: :meth:`~WorldRuns.run` (frames every ``every`` steps, observers, progress)
and :meth:`~WorldRuns.advance` (no frames), both in chunks of steps (one compiled call each,
sized by :func:`.chunks.next_chunk`), each chunk checked for numbers past the range that can be
simulated (:mod:`collisionlab.run_guard`). :class:`WorldRuns` is one of
:class:`~collisionlab.engine.world.World`'s bases: the world steps (``_steps``) and brings its
arrays up to date (``_settle``); this file only calls them, chunk by chunk, and keeps the record.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from ..errors import InvalidInputError
from ..limits import check_frames
from ..model import Scenario
from ..record import RunObserver, RunRecord
from ..run_guard import RangeGuard, is_overflow
from .chunks import next_chunk
from .contact_stepper import ContactStepper
from .event_stepper import EventDrivenStepper
from .stepper import EulerStepper
from .world_readings import WorldReadings

__all__ = ["WorldRuns"]


class WorldRuns(WorldReadings):
    """Runs of a world in chunks of steps (a base of :class:`~collisionlab.engine.world.World`,
    which sets the attributes and gives the two methods declared below)."""

    scenario: Scenario
    record: RunRecord
    _stepper: EulerStepper | EventDrivenStepper | ContactStepper
    _compiled: bool
    #: Whether chunks are sized as an exact stepper's among obstacles (chunks.next_chunk).
    _exact_chunks: bool
    _exact: bool
    #: Where :meth:`run` sends what happens, and whether the record keeps it too.
    _observer: RunObserver | None
    _keep: bool
    #: How :meth:`run` and :meth:`advance` make each compiled call (``None``: directly).
    _calling: Callable[[Callable[[], None]], None] | None
    #: The world's stepping of ``steps`` steps, without bookkeeping; its arrays brought up to date.
    _steps: Callable[[int], None]
    _settle: Callable[[], None]
    #: The Forward Euler world's warning, once, that a body moves farther in a step than it can.
    _check_tunnelling: Callable[[], None]

    @property
    def event_driven(self) -> bool:
        """Whether the world steps event by event (:mod:`collisionlab.engine.event_stepper`)."""
        return isinstance(self._stepper, EventDrivenStepper)

    @property
    def compiled(self) -> bool:
        """Whether the world runs compiled kernels (numba), not their Python form."""
        return self._compiled or self.event_driven

    def _chunk(self, count: int, look: bool, guard: RangeGuard) -> tuple[Any, Any] | None:
        """Step ``count`` steps (one compiled call, or ``count`` Python steps); with ``look``, bring
        the arrays and the ledger up to date, check that the numbers stay in the range that can
        be simulated (a warning in the record if not) and return the positions and velocities
        (copies, in the order the bodies were given). A number past that range ends the run with
        ``guard``'s error, naming the step."""
        try:
            self._steps(count)
            if look:
                self._settle()
        except (InvalidInputError, ArithmeticError) as error:
            if not is_overflow(error):
                raise
            raise guard.overflowed(self.step_index, error) from None
        if not look:
            return None
        positions, velocities = self.position_array, self.velocity_array  # for the guard and a frame
        warning = guard.check_arrays(self.step_index, self.time, positions, velocities)
        if warning:
            self.record.warnings.append(warning)
        return positions, velocities

    def advance(
        self,
        steps: int,
        between: Callable[[int, int], None] | None = None,
        clock: Callable[[], float] = time.perf_counter,
        calling: Callable[[Callable[[], None]], None] | None = None,
    ) -> float:
        """:meth:`step` ``steps`` times in chunks of about ``CHUNK_SECONDS`` of compiled work
        (one step at a time in Python form), checking after each that the numbers stay in the
        range that can be simulated and calling ``between(done, steps)`` (where a caller shows
        progress and looks for Ctrl-C). No frames are made. Returns the seconds spent stepping
        (``clock``'s). ``calling(call)``, if given, makes each compiled call (``call()``: the
        stepper's kernels over one chunk) as :meth:`run`'s does."""
        guard = RangeGuard(self.scenario)
        gains = self.scenario.energy_warning() is not None  # e > 1: speeds grow, look every step
        # Balls in a box with e <= 1 stay in their box at speeds their energy bounds: the
        # event-driven stepper then copies its state (O(N)) only at the end, not every chunk.
        watch = gains or not self.event_driven
        self._calling = calling
        try:
            return self._advance_chunks(steps, between, clock, guard, gains, watch)
        finally:
            self._calling = None

    def _advance_chunks(
        self,
        steps: int,
        between: Callable[[int, int], None] | None,
        clock: Callable[[], float],
        guard: RangeGuard,
        gains: bool,
        watch: bool,
    ) -> float:
        done, chunk, spent = 0, 1, 0.0
        while done < steps:
            count = min(chunk, steps - done)
            events = self.record.collision_count
            started = clock()
            self._chunk(count, watch, guard)
            took = clock() - started
            spent += took
            done += count
            if between is not None:
                between(done, steps)
            if self.compiled and not gains:
                events = self.record.collision_count - events
                chunk = next_chunk(chunk, count, took, events, self._exact_chunks, self._bodies.n)
        self._settle()
        return spent

    def run(
        self,
        every: int = 1,
        progress: Callable[[int, int], None] | None = None,
        observer: RunObserver | None = None,
        keep: bool = True,
        calling: Callable[[Callable[[], None]], None] | None = None,
    ) -> RunRecord:
        """Run the remaining steps; keep a frame every ``every`` steps (and the first and last).
        ``progress(done, total)`` is called between chunks of steps. ``observer`` is told every
        frame, event and warning as it is produced (:class:`~collisionlab.record.RunObserver`);
        with ``keep=False`` the record then holds no events and only the first and latest
        frames (its counts and ledger stay whole), so memory does not grow with the run.
        ``calling(call)``, if given, makes each compiled call instead of ``call()`` (``call``: the
        stepper's kernels over one chunk of steps, nothing else): the command line runs it in a
        thread of its own and waits, ready for a signal, since a chunk cannot be stopped inside."""
        total = self.scenario.settings.steps
        if keep:
            check_frames(total, every, self._bodies.n)  # the kept frames must fit in memory
        guard = RangeGuard(self.scenario)  # numbers stay in the range that can be simulated
        self._observer, self._keep, self._calling = observer, keep, calling
        if not self._exact:
            self._check_tunnelling()  # known before the first frame, so it heads the output
        if observer is not None:
            observer.begin(self.record)
        told = len(self.record.warnings)
        if not self.record.frames:
            self.record.frames.append(self.frame())
            if observer is not None:
                observer.frame(self.record.frames[0])
        try:
            self._run_chunks(total, every, progress, guard, told)
        finally:
            self._observer, self._keep, self._calling = None, True, None
        if observer is not None:
            observer.end(self.record)
        return self.record

    def _run_chunks(
        self,
        total: int,
        every: int,
        progress: Callable[[int, int], None] | None,
        guard: RangeGuard,
        told: int,
    ) -> None:
        observer = self._observer
        # Balls in a box with e <= 1 stay in the box, their speeds bounded by their energy: the
        # event-driven stepper's state (O(N)) is then read only for frames (see advance()).
        watch = self.scenario.energy_warning() is not None or not self.event_driven
        # Steps per call: one for the Python forms; compiled, as many as take about
        # CHUNK_SECONDS, learnt as it goes, so progress and Ctrl-C are never far away.
        chunk = 1
        while self.step_index < total:
            to_frame = every - self.step_index % every
            count = min(to_frame, chunk, total - self.step_index)
            framing = count == to_frame or self.step_index + count == total
            events = self.record.collision_count
            started = time.perf_counter()
            arrays = self._chunk(count, watch or framing, guard)
            if observer is not None:
                for text in self.record.warnings[told:]:
                    observer.warning(text)
            told = len(self.record.warnings)
            if self.compiled:
                took = time.perf_counter() - started
                events = self.record.collision_count - events
                chunk = next_chunk(chunk, count, took, events, self._exact_chunks, self._bodies.n)
            if framing:
                assert arrays is not None
                frame = self._frame(*arrays)
                if not self._keep and len(self.record.frames) > 1:
                    self.record.frames[-1] = frame  # the first and the latest only
                else:
                    self.record.frames.append(frame)
                if observer is not None:
                    observer.frame(frame)
            if progress is not None:
                progress(self.step_index, total)
        self._settle()
