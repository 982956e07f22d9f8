"""The stateful simulation: a :class:`World` owns a scenario's state in arrays and steps it. Its
runs in chunks (:meth:`World.run`, :meth:`World.advance`) are :mod:`.world_runs`', what it reads of
its state (positions, energies, frames) :mod:`.world_readings`'.

Two steppers act on the same state:

* ``mode = "euler"`` (the lab's part VI): :func:`~collisionlab.engine.step_kernels.run_steps`,
  Forward Euler then detect, resolve and push apart, in the order its module documents. It runs
  as Python for small worlds and compiled by numba for large ones (same source, same numbers).
* ``mode = "exact"``: :func:`~collisionlab.engine.exact_kernels.run_exact_steps`, exact flight
  between impacts found by time of impact, earliest first: nothing tunnels. The same two forms.

What happens is recorded in one :class:`~collisionlab.record.RunRecord`: frames every ``every``
steps (never every step unless asked, so memory follows what is kept, not the run's length),
collision events, contacts skipped as separating, the energy ledger and warnings.

Bodies that start overlapping by more than ``slop`` are refused (:class:`InitialOverlapError`,
naming both and the depth; less is rounding, as for a ball placed on a tilted plane) unless the
scenario says ``allow_initial_overlap``: then the first step resolves them and a warning says so.
"""

from __future__ import annotations

import contextlib
import functools
import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from ..built_sequence import SequenceChain
from ..model import Scenario
from ..numba_cache import compiled_notice
from ..record import CollisionEvent, RunObserver, RunRecord
from . import contact_kernels, exact_kernels, pair_separation, step_kernels
from .chunks import PileHint
from .contact_stepper import ContactStepper
from .event_stepper import EventDrivenStepper
from .exact_stepper import ExactStepper
from .kernel_loading import KernelCalls
from .overlap import InitialOverlapError, find_overlaps, overlap_message
from .params import COMPILE_ABOVE, SOLVE_COMPILE_ABOVE, WorldParams
from .recorded_events import recorded_events
from .state import bodies_of, static_names, statics_of
from .stepper import EulerStepper, near_pairs
from .tunnelling import thickness, tunnelling
from .world_runs import WorldRuns

__all__ = [
    "InitialOverlapError",
    "World",
    "load_stepper_kernels",
    "simulate",
]


class World(WorldRuns):
    """A running simulation. Build it from a scenario, then :meth:`step` or :meth:`run`.

    >>> from collisionlab import Sphere, Plane
    >>> from collisionlab.model import Body, Obstacle, Settings, Scenario
    >>> ball = Body("ball", Sphere((0, 0.96, 0), 0.5), velocity=(0, -1, 0))
    >>> floor = Obstacle("floor", Plane((0, 0, 0), (0, 1, 0)))
    >>> world = World(Scenario(Settings(dt=0.1, steps=10, restitution=0.5), (ball,), (floor,)))
    >>> world
    World('scenario', 1 body, 1 static, euler, step 0 of 10)
    """

    def __init__(
        self,
        scenario: Scenario,
        params: WorldParams | None = None,
        notify: Callable[[str], None] | None = None,
        events: bool = True,
    ) -> None:
        """``notify`` hears what takes time (compiling kernels); ``events=False`` records no
        collision events (a gas counts its impulses, :meth:`impulses`, and keeps no rows)."""
        self.scenario = scenario
        #: Where the world says what takes time (compiling its kernels); the CLI passes stderr.
        self._notify = notify
        self.params = params or WorldParams()
        settings = scenario.settings
        self.dims = scenario.dims
        self.step_index = 0
        self.time = 0.0
        self._bodies = bodies_of(scenario)
        self._statics = statics_of(scenario)
        self._names = scenario.bodies.names()
        self._static_names = static_names(scenario)
        with np.errstate(divide="ignore"):
            self._mass_array = np.where(self._bodies.ima > 0.0, 1.0 / self._bodies.ima, math.inf)
        self._finite_masses = np.where(np.isfinite(self._mass_array), self._mass_array, 0.0)
        #: Whether the stepper keeps the state in its own order (by grid cell; ``ids`` then says
        #: which body each row is), or in the order given (the event-driven stepper's copy).
        self._storage_sorts = False
        self._gravity = np.array(settings.gravity.as_tuple())
        self._tunnel_warned = False
        #: Where :meth:`run` sends what happens, and whether the record keeps it too.
        self._observer: RunObserver | None = None
        self._keep = True
        self._events: SequenceChain[CollisionEvent] = SequenceChain()  # the record's, a block per chunk
        #: How :meth:`run` and :meth:`advance` make each compiled call (``None``: directly).
        self._calling: Callable[[Callable[[], None]], None] | None = None
        self.record = RunRecord(
            title=scenario.title,
            mode=settings.mode,
            dt=settings.dt,
            steps=settings.steps,
            restitution=settings.restitution,
            gravity=settings.gravity,
            dims=scenario.dims,
            scenario=scenario,
            contacts=settings.contacts,
            events=self._events,
        )
        ledger = self.record.ledger
        ledger.kinetic_start = ledger.kinetic_end = self.kinetic_energy()
        ledger.potential_start = ledger.potential_end = self.potential_energy()
        ledger.momentum_start = ledger.momentum_end = self.momentum()
        warning = scenario.energy_warning()
        if warning:
            self.record.warnings.append(warning)
        n = self._bodies.n
        self._exact = settings.mode == "exact"
        #: Exact mode with its contacts solved (``contacts = "solve"``): the contact stepper.
        self._solving = self._exact and settings.contacts == "solve" and not scenario.event_driven
        self._impact_limit_warned = False
        self._pile_hint = PileHint(n)
        kind = "event-driven" if scenario.event_driven else "solve" if self._solving else settings.mode
        self._calls = KernelCalls(kind, notify)  # the compiled kernels, and their first calls
        #: Whether chunks are sized as an exact stepper's among obstacles (chunks.next_chunk).
        self._exact_chunks = self._exact and not scenario.event_driven
        self._check_initial_overlap()
        self._stepper: EulerStepper | EventDrivenStepper | ContactStepper
        if self._solving:
            self._stepper = ContactStepper(self._bodies, self._statics, self.dims, self._gravity, self.params, events)
        elif scenario.event_driven:
            assert scenario.box is not None
            # Several kinds of ball (radii, masses or [[gas]] tables): a mixture, counted by kind.
            species = scenario.ball_species()
            self._stepper = EventDrivenStepper(
                self._bodies, self._statics, self.dims, self._gravity, self.params, scenario.box,
                settings.restitution, settings.tc, events, notify, species if len(species[0]) > 1 else None,
            )  # fmt: skip
            if self._stepper.species:  # each kind's kT at the start, until the first steps
                self.record.species = self._stepper.species_report()
        else:
            stepper = ExactStepper if self._exact else EulerStepper
            self._stepper = stepper(self._bodies, self._statics, self.dims, self._gravity, self.params, events)
            self._storage_sorts = True
        # Per body in the order given (storage is still that order here).
        kinds, extents = self._bodies.kind, self._bodies.ext
        self._thickness = thickness(kinds, extents, self.dims)
        self._thinnest = float(self._thickness.min())
        compiled = self.params.compiled
        above = SOLVE_COMPILE_ABOVE if self._solving else COMPILE_ABOVE
        self._compiled = n * settings.steps > above if compiled is None else compiled

    def __repr__(self) -> str:
        n, m = self._bodies.n, self._statics.m
        return (
            f"World({self.scenario.title!r}, {n} bod{'y' if n == 1 else 'ies'}, {m} static{'' if m == 1 else 's'}, "
            f"{self.scenario.settings.mode}, step {self.step_index} of {self.scenario.settings.steps})"
        )

    def nbytes(self) -> int:
        """Bytes of every array the world holds: state, statics, scratch and buffers."""
        return self._stepper.nbytes()

    @property
    def stepper(self) -> EulerStepper | EventDrivenStepper | ContactStepper:
        """What steps the state: the Forward Euler, exact or event-driven stepper (its arrays and
        counters, for measurements such as a gas's collision virial)."""
        return self._stepper

    def load_kernels(self) -> float:
        """Load the compiled kernels this world's steps call (or compile them, the first time on
        a machine, saying so), now rather than in the first step, so that a timed run never
        counts the compiler; returns the seconds it took: 0.0 for the Python form, for an
        event-driven world (its loop loads when the world is made) and when loaded already."""
        if not self._compiled or self.event_driven:
            return 0.0
        return load_stepper_kernels(self._calls.kind, None if self._calls.said_compiling else self._notify)

    def impulses(self) -> tuple[int, int]:
        """Impulses applied so far between two bodies and between a body and an obstacle or
        wall: every collision and every resting contact's push (a gas's collision counts)."""
        ledger = self._stepper.ledger
        return int(ledger[5]), int(ledger[6])

    def deepest_overlap(self) -> float:
        """The deepest overlap of two bodies (or a body and an obstacle or wall) now, in metres;
        0 when nothing overlaps."""
        if isinstance(self._stepper, EventDrivenStepper):
            return max(0.0, self._stepper.world.max_overlap())
        _, depths = self._near(0.0)
        return max(0.0, float(depths.max(initial=0.0)))

    def listen(self, observer: RunObserver | None) -> None:
        """Tell ``observer`` the events of every later :meth:`step` as they are produced (what
        :meth:`run` does for its own observer); ``None`` stops it."""
        self._observer = observer

    # --- checks -----------------------------------------------------------------------------------
    def _near(self, margin: float) -> tuple[np.ndarray[Any, np.dtype[np.int64]], np.ndarray[Any, np.dtype[np.float64]]]:
        large = self._bodies.n * max(1, self._statics.m) > COMPILE_ABOVE // 100
        kernels = self._calls.module(stepper=False) if large else step_kernels
        with self._calls.first_call(kernels, "find_near"):
            return near_pairs(kernels, self._bodies, self._statics, self.dims, self.params, margin)

    def _pair_names(self, a: int, b: int) -> tuple[str, str]:
        return (self._static_names[-1 - a] if a < 0 else self._names[a], self._names[b])

    def _check_initial_overlap(self) -> None:
        # NumPy, before any kernel is compiled: a refusal stops at the first overlap it finds.
        # Deeper than the slop: a ball placed "on" a tilted plane overlaps it by rounding (1e-17).
        allowed = self.scenario.allow_initial_overlap
        found = find_overlaps(self._bodies, self._statics, self.dims, self.params.slop, every=allowed)
        if not found.count:
            return
        name_a, name_b = self._pair_names(*found.pair)
        if not allowed:
            raise InitialOverlapError("body", overlap_message(found, name_a, name_b))
        count = found.count
        self.record.warnings.append(
            f"{count} pair{'s' if count > 1 else ''} overlapped at the start (deepest: '{name_a}' and '{name_b}' by "
            f"{found.depth:.6g} m); the first step pushes them apart (allow_initial_overlap)"
        )

    def _check_tunnelling(self) -> None:
        """Warn once when a body moves farther in one step than it takes to pass through
        something (:mod:`.tunnelling`)."""
        if self._tunnel_warned:
            return
        b = self._bodies
        fixed_boxes = bool(np.any(self._statics.kind == pair_separation.STATIC_BOX))
        found = tunnelling(b.vel, self._thickness[b.ids], self._thinnest, self.scenario.settings.dt, fixed_boxes)
        if found is None:
            return
        a, i, moved, limit = found
        name_a = "a static obstacle" if a < 0 else "'" + self._names[int(b.ids[a])] + "'"
        self.record.warnings.append(
            f"'{self._names[int(b.ids[i])]}' moves {moved:.3g} m relative to {name_a} in one step, more than the "
            f"{limit:.3g} m it takes to pass through: collisions can be missed (tunnelling); use --mode exact"
        )
        self._tunnel_warned = True

    # --- stepping -------------------------------------------------------------------------------
    def step(self, steps: int = 1) -> None:
        """Advance ``steps`` steps of ``dt`` in the scenario's mode."""
        self._steps(steps)
        self._settle()

    def _steps(self, steps: int) -> None:
        """The stepping of :meth:`step`, without its bookkeeping (:meth:`_settle`)."""
        if self._exact:
            self._step_exact(steps)
        else:
            self._step_euler(steps)

    def _settle(self) -> None:
        """Bring the world's arrays up to date (the event-driven stepper copies where its balls
        are only when asked) and the ledger's end values with them."""
        if isinstance(self._stepper, EventDrivenStepper):
            self._stepper.copy_state()
            if self._stepper.species:
                self.record.species = self._stepper.species_report()
        ledger, masses = self.record.ledger, self._stored_masses()
        ledger.kinetic_end = self.kinetic_energy(masses)
        ledger.potential_end = self.potential_energy(masses)
        ledger.momentum_end = self.momentum(masses)

    def _step_exact(self, steps: int) -> None:
        stepper = self._stepper
        if isinstance(stepper, EventDrivenStepper):
            self._advance(steps, None)  # its own compiled loop: no step kernels
            return
        # Both exact steppers count in status[0] the steps (half steps) that hit their cap of
        # impacts; the first is said once.
        assert isinstance(stepper, (ExactStepper, ContactStepper))
        solving = isinstance(stepper, ContactStepper)
        limited = int(stepper.status[0])
        work = int(stepper.status[1])
        python_form = contact_kernels if solving else exact_kernels
        self._advance(steps, self._calls.module() if self._compiled else python_form)
        if not solving and any(self.scenario.settings.gravity.as_tuple()):
            hint = self._pile_hint.look(int(stepper.status[1]) - work, steps, self.step_index)
            if hint is not None:
                self.record.warnings.append(hint)
        if int(stepper.status[0]) > limited and not self._impact_limit_warned:
            self._impact_limit_warned = True
            where = "a half step before step" if solving else "step"
            most = python_form.MAX_IMPACTS_PER_STEP
            self.record.warnings.append(
                f"more than {most} impacts in {where} {self.step_index}: the rest of it was flown without them "
                "(said once; later steps may do the same)"
            )

    def _step_euler(self, steps: int) -> None:
        self._check_tunnelling()
        self._advance(steps, self._calls.module() if self._compiled else step_kernels)

    def _advance(self, steps: int, kernels: Any) -> None:
        """Advance ``steps`` steps with the stepper and ``kernels`` (its Python or compiled form)
        and take the ledger's sums and the events."""
        settings = self.scenario.settings
        entry = ("run_contact_steps" if self._solving else "run_exact_steps") if self._exact else "run_steps"
        call = functools.partial(
            self._stepper.advance, kernels, settings.dt, settings.restitution, self.step_index, steps
        )
        with contextlib.nullcontext() if kernels is None else self._calls.first_call(kernels, entry):
            if self._calling is None or not self.compiled:
                call()
            else:  # the caller's way (the command line: a thread of its own while it waits for signals)
                self._calling(call)
        self.step_index += steps
        self.time = self.step_index * settings.dt
        # The stepper's running totals: summed in event order whatever the chunks, so a run's
        # ledger is the same to the last bit however its steps were split into calls.
        sums, ledger = self._stepper.ledger, self.record.ledger
        ledger.integrator = float(sums[0])
        ledger.collisions = float(sums[1])
        ledger.push_apart = float(sums[2])
        ledger.collisions_predicted = float(sums[3])
        ledger.max_penetration = float(sums[4])
        if isinstance(self._stepper, ContactStepper):
            self.record.static_impulses = dict(
                zip(self._static_names, self._stepper.static_impulse.tolist(), strict=True)
            )
        self._record_events(self._stepper.events())

    def _record_events(self, events: np.ndarray[Any, np.dtype[np.float64]]) -> None:
        """The kernel's event rows (``event_rows.EVENT_COLUMNS``) as an :class:`EventBlock` of
        collisions and a list of :class:`SkippedContact`, recorded and told to the observer."""
        if events.shape[0] == 0:
            return
        block, skipped = recorded_events(events, self._names, self._static_names, self._mass_array)
        self._stepper.release_events()
        self.record.collision_count += len(block)
        if self._keep:
            self._events.extend(block)
            self.record.skipped.extend(skipped)
        if self._observer is not None:
            self._observer.events(block, skipped, self.step_index)


def simulate(scenario: Scenario, every: int = 1, params: WorldParams | None = None) -> RunRecord:
    """Run ``scenario`` from the start and return its record.

    >>> from collisionlab import Sphere, Plane
    >>> from collisionlab.model import Body, Obstacle, Settings, Scenario
    >>> ball = Body("ball", Sphere((0, 0.96, 0), 0.5), velocity=(0, -1, 0))
    >>> floor = Obstacle("floor", Plane((0, 0, 0), (0, 1, 0)))
    >>> record = simulate(Scenario(Settings(dt=0.1, steps=10, restitution=0.5), (ball,), (floor,)))
    >>> event = record.events[0]   # y = 0.96 - 0.1 k <= 0.5 first at k = 5 (4.6 rounded up)
    >>> event.step, event.velocities_after["ball"]   # -1 -> +0.5 (lab eq. 24, e = 0.5)
    (5, Vector3D(x=0.0, y=0.5, z=0.0))
    """
    return World(scenario, params).run(every=every)


#: The steppers' kernels this process has loaded (:func:`load_stepper_kernels`).
_LOADED: set[str] = set()


def load_stepper_kernels(kind: str, notify: Callable[[str], None] | None = None) -> float:
    """Load the compiled kernels of one stepper, ``kind`` ``"euler"``, ``"exact"`` or
    ``"solve"``, from numba's cache, or compile them (``notify`` is then told so, once, and
    again when the compile is done, with the seconds it took), by stepping the lab's bouncing
    ball twice in that mode; returns the seconds it took, 0.0 when this process has loaded them
    already. (Here rather than in :mod:`.ahead`, which loads every kind of kernel: a world loading
    its own kernels reaches nothing above the engine.)"""
    from ..demos import load_demo

    if kind in _LOADED:
        return 0.0
    started = time.perf_counter()
    mode, contacts = {"euler": ("euler", "events"), "exact": ("exact", "events"), "solve": ("exact", "solve")}[kind]
    settings = {"mode": mode} if contacts == "events" else {"mode": mode, "contacts": contacts}
    scenario = load_demo("bouncing-ball").with_settings(**settings)
    said: list[str] = []

    def tell(text: str) -> None:
        said.append(text)
        if notify is not None:
            notify(text)

    World(scenario, WorldParams(compiled=True), notify=tell, events=False).step(2)
    _LOADED.add(kind)
    took = time.perf_counter() - started
    if notify is not None and said:  # it compiled: the wait announced is over
        notify(compiled_notice(kind, took))
    return took
