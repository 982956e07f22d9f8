"""The record of a run: frames, collision events, skipped contacts, the ledger and a summary.

One record feeds every output (table, CSV, JSON, plots), so nothing is simulated twice.
"""

from __future__ import annotations

import functools
import json
import math
import string
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal, Protocol

import numpy as np
import orjson
from numpy.typing import NDArray

from . import text_kernels
from .built_sequence import BuiltSequence, SequenceChain
from .extras import require
from .vector import Vector3D

if TYPE_CHECKING:
    import pandas
    from matplotlib.figure import Figure

    from .model import Scenario

__all__ = [
    "BodyState",
    "CollisionEvent",
    "EventBlock",
    "Frame",
    "FrameBodies",
    "Ledger",
    "RunObserver",
    "RunRecord",
    "SkippedContact",
]


def _vec(v: Vector3D) -> list[float]:
    """``v`` as a list, ``-0.0`` written ``0.0`` (a signed zero reads as another number)."""
    return [v.x + 0.0, v.y + 0.0, v.z + 0.0]


def _count(n: int, singular: str, plural: str | None = None) -> str:
    return f"{n:,} {singular if n == 1 else plural or singular + 's'}"


@dataclass(frozen=True)
class BodyState:
    name: str
    position: Vector3D
    velocity: Vector3D


class FrameBodies(BuiltSequence[BodyState]):
    """A frame's bodies held as arrays (``positions`` and ``velocities``, ``(n, 3)``, owned), each
    :class:`BodyState` built only when read: a world of thousands of bodies writes its frames
    from the arrays (:meth:`Frame.to_dict`, the table and CSV writers) without making millions of
    vectors. Equal to any sequence of the same body states.

    >>> bodies = FrameBodies(("a",), np.array([[1.0, 2.0, 0.0]]), np.zeros((1, 3)))
    >>> bodies[0].position, bodies == (BodyState("a", Vector3D(1, 2, 0), Vector3D(0, 0, 0)),)
    (Vector3D(x=1.0, y=2.0, z=0.0), True)
    """

    def __init__(self, names: Sequence[str], positions: NDArray[np.float64], velocities: NDArray[np.float64]) -> None:
        self.names, self.positions, self.velocities = names, positions, velocities

    def __len__(self) -> int:
        return len(self.names)

    def _item(self, i: int) -> BodyState:
        return BodyState(self.names[i], Vector3D(*self.positions[i].tolist()), Vector3D(*self.velocities[i].tolist()))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Sequence):
            return NotImplemented
        return len(self) == len(other) and all(a == b for a, b in zip(self, other, strict=True))

    def __hash__(self) -> int:
        return hash(tuple(self))

    def __repr__(self) -> str:
        return repr(tuple(self))

    def dicts(self) -> list[dict[str, Any]]:
        """``Frame.to_dict``'s bodies, from the arrays (``+ 0.0``: no signed zero)."""
        positions, velocities = (self.positions + 0.0).tolist(), (self.velocities + 0.0).tolist()
        return [
            {"name": name, "position": x, "velocity": v}
            for name, x, v in zip(self.names, positions, velocities, strict=True)
        ]


@dataclass(frozen=True)
class Frame:
    """The state after ``step`` steps, at ``time`` seconds (step 0 is the start). ``bodies`` is
    a tuple, or a :class:`FrameBodies` from a world's arrays."""

    step: int
    time: float
    bodies: Sequence[BodyState]

    def to_dict(self) -> dict[str, Any]:
        bodies = self.bodies
        return {
            "step": self.step,
            "time": self.time + 0.0,
            "bodies": bodies.dicts()
            if isinstance(bodies, FrameBodies)
            else [{"name": b.name, "position": _vec(b.position), "velocity": _vec(b.velocity)} for b in bodies],
        }


@dataclass(frozen=True)
class CollisionEvent:
    """One resolved impact, with the working of the impulse (for ``--explain``).

    ``normal`` points from ``bodies[0]`` to ``bodies[1]``; ``approach_speed`` is
    ``v_n = (v_b - v_a) . n`` before (negative when approaching); ``impulse`` is
    ``j = -(1 + e) v_n / (1/m_a + 1/m_b)``. ``restitution`` is the e applied: 0 when the
    approach was slower than the rest threshold, and then ``below_rest_threshold`` is true
    (``REST_SPEED`` in :mod:`collisionlab.tolerances`). ``static`` says that ``bodies[0]`` is an
    obstacle (infinite mass).
    """

    step: int
    time: float
    bodies: tuple[str, str]
    static: bool
    normal: Vector3D
    point: Vector3D
    approach_speed: float
    impulse: float
    restitution: float
    masses: tuple[float, float]
    velocities_before: dict[str, Vector3D]
    velocities_after: dict[str, Vector3D]
    kinetic_energy_before: float
    kinetic_energy_after: float
    below_rest_threshold: bool = False

    def to_dict(self) -> dict[str, Any]:
        return {
            "step": self.step,
            "time": self.time + 0.0,
            "bodies": list(self.bodies),
            "static": self.static,
            "normal": _vec(self.normal),
            "point": _vec(self.point),
            "approach_speed": self.approach_speed + 0.0,
            "impulse": self.impulse + 0.0,
            "restitution": self.restitution + 0.0,
            "velocities_before": {k: _vec(v) for k, v in self.velocities_before.items()},
            "velocities_after": {k: _vec(v) for k, v in self.velocities_after.items()},
            "kinetic_energy_before": self.kinetic_energy_before + 0.0,
            "kinetic_energy_after": self.kinetic_energy_after + 0.0,
            "below_rest_threshold": self.below_rest_threshold,
        }


#: One event's line of JSON, laid out as ``json.dumps(event.to_dict())`` lays it out, with a
#: field in braces for each of its values: ``a`` and ``b`` the bodies' quoted names, a vector's
#: three numbers as ``x, y, z``, ``static`` and ``below_rest`` as ``true`` or ``false``. Against
#: an obstacle (which has no velocities) each of body A's velocity entries, from ``{a}`` to the
#: ``], `` after ``{before_a}`` or ``{after_a}``, is left out.
_EVENT_JSON = (
    '{{"step": {step}, "time": {time}, "bodies": [{a}, {b}], "static": {static}, "normal": [{normal}], '
    '"point": [{point}], "approach_speed": {approach_speed}, "impulse": {impulse}, "restitution": {restitution}, '
    '"velocities_before": {{{a}: [{before_a}], {b}: [{before_b}]}}, '
    '"velocities_after": {{{a}: [{after_a}], {b}: [{after_b}]}}, '
    '"kinetic_energy_before": {kinetic_before}, "kinetic_energy_after": {kinetic_after}, '
    '"below_rest_threshold": {below_rest}}}'
)
#: The fields of :data:`_EVENT_JSON` that are numbers: how many each.
_NUMBER_FIELDS = {
    "time": 1, "normal": 3, "point": 3, "approach_speed": 1, "impulse": 1, "restitution": 1,
    "before_a": 3, "before_b": 3, "after_a": 3, "after_b": 3, "kinetic_before": 1, "kinetic_after": 1,
}  # fmt: skip
#: The fields that are flags: the column of :meth:`EventBlock.json_chunks`'s flags.
_FLAG_FIELDS = {"static": 0, "below_rest": 1}


def _pieces(template: str) -> list[tuple[str, str | None]]:
    """``template`` as (literal text, the field after it), the last field ``None``.

    >>> _pieces("{{a: {x}}}")
    [('{a: ', 'x'), ('}', None)]
    """
    pieces: list[tuple[str, str | None]] = [("", None)]
    for literal, name, _, _ in string.Formatter().parse(template):
        pieces[-1] = (pieces[-1][0] + literal, name)  # an escaped brace ends a literal without a field
        if name is not None:
            pieces.append(("", None))
    return pieces


@functools.cache
def _event_program(separator: str) -> tuple[NDArray[np.int64], NDArray[np.uint8], NDArray[np.int64], list[str]]:
    """:data:`_EVENT_JSON` after ``separator`` as a program of :func:`text_kernels.lay_out
    <collisionlab.text_kernels.lay_out>`: its rows, its literals and their bounds, and the
    number fields in the order it reads them."""
    literals: list[bytes] = []
    rows: list[tuple[int, int, int, int]] = []
    order: list[str] = []

    def literal(text: str, pair_only: bool) -> None:
        if text:
            literals.append(text.encode())
            rows.append((text_kernels.LITERAL, len(literals) - 1, 0, int(pair_only)))

    pieces = _pieces(_EVENT_JSON)
    fields = [name for _, name in pieces]
    entries = {fields.index("before_a"), fields.index("after_a")}  # {a}: [{vector}], : pairs only
    for j, (text, name) in enumerate(pieces):
        if j - 1 in entries:
            assert text.startswith("], ")
            literal("], ", True)
            literal(text[3:], False)
        else:
            literal(separator + text if j == 0 else text, j in entries)
        pair_only = j in entries or (j + 1 in entries and name == "a")
        if name in _NUMBER_FIELDS:
            order.append(name)
            for k in range(_NUMBER_FIELDS[name]):
                literal(", " if k else "", pair_only)
                rows.append((text_kernels.NUMBER, 0, 0, int(pair_only)))
        elif name in _FLAG_FIELDS:
            literals += [b"false", b"true"]
            rows.append((text_kernels.FLAG, len(literals) - 2, _FLAG_FIELDS[name], int(pair_only)))
        elif name is not None:
            operation = {"a": text_kernels.NAME_A, "b": text_kernels.NAME_B, "step": text_kernels.STEP}[name]
            rows.append((operation, 0, 0, int(pair_only)))
    bounds = np.cumsum([0, *map(len, literals)], dtype=np.int64)
    return np.array(rows, dtype=np.int64), np.frombuffer(b"".join(literals), np.uint8), bounds, order


def json_numbers(values: NDArray[np.float64]) -> list[str]:
    """The JSON text of each number of ``values`` (row by row): the shortest that reads back as
    the same double, as ``repr`` finds it, but written by orjson, about ten times faster (the
    text of some numbers is not repr's: ``1e-7`` for ``1e-07``, and ``0.00001`` or ``1e-5``,
    as orjson's version has it, for ``1e-05``; the same doubles), and ``0.0`` for ``-0.0`` (a
    signed zero reads as another number). A NaN or an infinity, which orjson writes ``null``, is
    written as the json module writes it (``NaN``, ``Infinity``: not standard JSON, but what
    the rest of the output writes).

    >>> json_numbers(np.array([[0.1, -0.0], [1.5, 100.0]]))
    ['0.1', '0.0', '1.5', '100.0']
    >>> json_numbers(np.array([np.inf, -np.inf, np.nan, 1.0]))
    ['Infinity', '-Infinity', 'NaN', '1.0']
    """
    flat = np.add(np.ravel(values), 0.0)  # a new, contiguous array (orjson takes no views)
    texts = orjson.dumps(flat, option=orjson.OPT_SERIALIZE_NUMPY).decode()[1:-1].split(",")
    for i in np.flatnonzero(~np.isfinite(flat)).tolist():
        texts[i] = json.dumps(flat[i].item())
    return texts


def _json_array(values: NDArray[np.float64]) -> bytes:
    """The numbers of ``values`` (row by row) as a JSON array, each as :func:`json_numbers`
    writes it."""
    flat = np.add(np.ravel(values), 0.0)
    if np.isfinite(flat).all():
        return orjson.dumps(flat, option=orjson.OPT_SERIALIZE_NUMPY)
    return ("[" + ",".join(json_numbers(flat)) + "]").encode()


class EventBlock(BuiltSequence[CollisionEvent]):
    """Collision events as columns of numbers, one row per event, in the order they happened:
    how a world hands over a stretch of its run. ``block[i]`` (and iteration) builds the
    :class:`CollisionEvent`; :meth:`json_chunks` and :meth:`json_lines` write the JSON form of
    every event without building them (a run of a heap of balls makes millions).

    ``a`` and ``b`` are indices into ``names`` (``a < 0``: the obstacle ``static_names[-1 - a]``),
    ``masses`` the bodies' masses in the order of ``names``; ``normal``, ``point``,
    ``before_a``, ``before_b``, ``after_a`` and ``after_b`` have three columns (an obstacle's
    velocities are rows of zeros, unused); ``below_rest`` is 0 or 1.

    >>> import numpy as np
    >>> one = lambda *v: np.array([v], dtype=np.float64)
    >>> block = EventBlock(np.array([5]), np.array([0.5]), np.array([-1]), np.array([0]), one(0, 1, 0),
    ...     one(0, 0, 0), np.array([-1.0]), np.array([1.5]), np.array([0.5]), np.array([0]), one(0, 0, 0),
    ...     one(0, -1, 0), one(0, 0, 0), one(0, 0.5, 0), ["ball"], ["floor"], np.array([1.0]))
    >>> block[0].bodies, block[0].velocities_after, block[0].kinetic_energy_after
    (('floor', 'ball'), {'ball': Vector3D(x=0.0, y=0.5, z=0.0)}, 0.125)
    >>> import json; json.loads(block.json_lines()[0]) == block[0].to_dict()
    True
    """

    def __init__(
        self,
        step: NDArray[np.int64],
        time: NDArray[np.float64],
        a: NDArray[np.int64],
        b: NDArray[np.int64],
        normal: NDArray[np.float64],
        point: NDArray[np.float64],
        approach_speed: NDArray[np.float64],
        impulse: NDArray[np.float64],
        restitution: NDArray[np.float64],
        below_rest: NDArray[np.int64],
        before_a: NDArray[np.float64],
        before_b: NDArray[np.float64],
        after_a: NDArray[np.float64],
        after_b: NDArray[np.float64],
        names: Sequence[str],
        static_names: Sequence[str],
        masses: NDArray[np.float64],
    ) -> None:
        self.step, self.time, self.a, self.b = step, time, a, b
        self.normal, self.point = normal, point
        self.approach_speed, self.impulse, self.restitution, self.below_rest = (
            approach_speed,
            impulse,
            restitution,
            below_rest,
        )
        self.before_a, self.before_b, self.after_a, self.after_b = before_a, before_b, after_a, after_b
        self.names, self.static_names, self.masses = names, static_names, masses
        # Kinetic energy of the pair before and after (an obstacle's, a kinematic body's: none).
        finite = np.where(np.isfinite(masses), masses, 0.0)
        m_a = np.where(a >= 0, finite[np.maximum(a, 0)], 0.0) if len(masses) else np.zeros(len(a))
        m_b = finite[b] if len(masses) else np.zeros(len(b))

        def kinetic(va: NDArray[np.float64], vb: NDArray[np.float64]) -> NDArray[np.float64]:
            return np.asarray(0.5 * (m_a * np.einsum("ij,ij->i", va, va) + m_b * np.einsum("ij,ij->i", vb, vb)))

        self.kinetic_before = kinetic(before_a, before_b)
        self.kinetic_after = kinetic(after_a, after_b)

    def __len__(self) -> int:
        return int(self.step.shape[0])

    def _name(self, i: int) -> str:
        return self.static_names[-1 - i] if i < 0 else self.names[i]

    def _item(self, k: int) -> CollisionEvent:
        a, b = int(self.a[k]), int(self.b[k])
        names = (self._name(a), self._name(b))
        static = a < 0
        before = {names[1]: Vector3D(*self.before_b[k].tolist())}
        after = {names[1]: Vector3D(*self.after_b[k].tolist())}
        if not static:  # A's velocities first, as the JSON lists them
            before = {names[0]: Vector3D(*self.before_a[k].tolist()), **before}
            after = {names[0]: Vector3D(*self.after_a[k].tolist()), **after}
        return CollisionEvent(
            step=int(self.step[k]),
            time=float(self.time[k]),
            bodies=names,
            static=static,
            normal=Vector3D(*self.normal[k].tolist()),
            point=Vector3D(*self.point[k].tolist()),
            approach_speed=float(self.approach_speed[k]),
            impulse=float(self.impulse[k]),
            restitution=float(self.restitution[k]),
            masses=(math.inf if static else float(self.masses[a]), float(self.masses[b])),
            velocities_before=before,
            velocities_after=after,
            kinetic_energy_before=float(self.kinetic_before[k]),
            kinetic_energy_after=float(self.kinetic_after[k]),
            below_rest_threshold=bool(self.below_rest[k]),
        )

    def json_lines(self) -> list[str]:
        """Each event's JSON (no newline): the text of ``json.dumps(event.to_dict())``, but for
        the numbers' text (:func:`json_numbers`)."""
        return [line for text in self.json_chunks("\n") for line in bytes(text[1:]).decode().split("\n")]

    def json_chunks(self, separator: str, size: int = 16384) -> Iterator[memoryview]:
        """The JSON of every event (:meth:`json_lines`), each after ``separator``, joined in
        pieces of ``size`` events: the numbers' text written by orjson a block at a time, and
        the lines laid out from it by compiled code (:mod:`collisionlab.text_kernels`), with no
        loop over the events in Python (a run of a heap of balls makes millions). Each piece is
        UTF-8 (the JSON is ASCII: the json module escapes the rest of a name) in a buffer of its
        own, a view that goes to a binary file as it is, not decoded and encoded again."""
        if not len(self):
            return
        program, literals, literal_bounds, order = _event_program(separator)
        # The names of the bodies in the block, each quoted once, by the json module: a newline
        # between them (inside a name it is escaped) cuts them apart again.
        ids, index = np.unique(np.concatenate((self.a, self.b)), return_inverse=True)
        quoted = json.dumps(list(map(self._name, ids.tolist())), separators=("\n", ":"))[1:-1].split("\n")
        names = np.frombuffer("".join(quoted).encode(), np.uint8)  # ASCII: the json module escapes the rest
        name_bounds = np.cumsum([0, *map(len, quoted)], dtype=np.int64)
        name_a, name_b = index[: len(self)].astype(np.int64), index[len(self) :].astype(np.int64)
        columns = {
            "time": self.time, "normal": self.normal, "point": self.point, "approach_speed": self.approach_speed,
            "impulse": self.impulse, "restitution": self.restitution, "before_a": self.before_a,
            "before_b": self.before_b, "after_a": self.after_a, "after_b": self.after_b,
            "kinetic_before": self.kinetic_before, "kinetic_after": self.kinetic_after,
        }  # fmt: skip
        numbers = np.column_stack([columns[name] for name in order])
        flags = np.column_stack((self.a < 0, self.below_rest != 0))
        steps = np.ascontiguousarray(self.step, dtype=np.int64)
        lengths = np.diff(name_bounds)
        # Bytes an event writes besides its numbers and names: at most every literal, a step.
        fixed = int(literal_bounds[-1]) + 20
        lay_out = text_kernels.compiled()
        no_values = np.empty((min(size, len(self)), 0))  # the JSON's numbers come as text
        for start in range(0, len(self), size):
            rows = slice(start, start + size)
            text = _json_array(numbers[rows])
            a, b = name_a[rows], name_b[rows]
            out = np.empty(len(text) + len(a) * fixed + 3 * int(lengths[a].sum() + lengths[b].sum()), np.uint8)
            written = lay_out(
                np.frombuffer(text, np.uint8), steps[rows], a, b, flags[rows], names, name_bounds,
                program, literals, literal_bounds, out, no_values[: len(a)], np.empty(len(a) + 1, np.int64),
            )  # fmt: skip
            yield out[:written].data


@dataclass(frozen=True)
class SkippedContact:
    """A contact that got no impulse, and why ("separating", "resting")."""

    step: int
    time: float
    bodies: tuple[str, str]
    reason: str

    def to_dict(self) -> dict[str, Any]:
        return {"step": self.step, "time": self.time + 0.0, "bodies": list(self.bodies), "reason": self.reason}


@dataclass
class Ledger:
    """Where energy went (J): total mechanical energy (kinetic + potential) at the start and the
    end, and the change put down to each cause. ``residual`` is what no cause explains
    (rounding); the causes are measured, phase by phase, not assumed."""

    kinetic_start: float = 0.0
    kinetic_end: float = 0.0
    potential_start: float = 0.0
    potential_end: float = 0.0
    momentum_start: Vector3D = field(default_factory=lambda: Vector3D(0, 0, 0))
    momentum_end: Vector3D = field(default_factory=lambda: Vector3D(0, 0, 0))
    collisions: float = 0.0
    integrator: float = 0.0
    push_apart: float = 0.0
    #: Metres: the deepest overlap the push-apart had to undo over the run (0 when no shapes
    #: ever overlapped at the end of a step's motion; rounding-level in exact mode).
    max_penetration: float = 0.0
    #: The loss predicted by theory for the collisions, sum of (1 - e^2)/2 * mu * v_n^2.
    collisions_predicted: float = 0.0

    @property
    def energy_start(self) -> float:
        return self.kinetic_start + self.potential_start

    @property
    def energy_end(self) -> float:
        return self.kinetic_end + self.potential_end

    @property
    def residual(self) -> float:
        return (self.energy_end - self.energy_start) - (self.collisions + self.integrator + self.push_apart)

    def to_dict(self) -> dict[str, Any]:
        return {
            "kinetic_start": self.kinetic_start,
            "kinetic_end": self.kinetic_end,
            "potential_start": self.potential_start,
            "potential_end": self.potential_end,
            "energy_start": self.energy_start,
            "energy_end": self.energy_end,
            "momentum_start": _vec(self.momentum_start),
            "momentum_end": _vec(self.momentum_end),
            "change_by_cause": {
                "collisions": self.collisions,
                "integrator": self.integrator,
                "push_apart": self.push_apart,
                "residual": self.residual,
            },
            "collisions_predicted": self.collisions_predicted,
            "max_penetration": self.max_penetration,
        }


class RunObserver(Protocol):
    """What a :meth:`World.run <collisionlab.engine.world.World.run>` tells as it happens, in
    order: :meth:`begin` (the record: title, settings, the warnings known at the start), then
    frames, events and warnings as they are produced, then :meth:`end` (the ledger is final).
    Events come in step order, each batch with the step the world has reached (a frame of that
    step may follow); a world hands them over as an :class:`EventBlock` (columns of numbers,
    events built only when read). The CLI's writers are observers, so nothing need be held until
    the end."""

    def begin(self, record: RunRecord) -> None: ...

    def frame(self, frame: Frame) -> None: ...

    def events(self, events: Sequence[CollisionEvent], skipped: Sequence[SkippedContact], reached: int) -> None: ...

    def warning(self, text: str) -> None: ...

    def end(self, record: RunRecord) -> None: ...


@dataclass
class RunRecord:
    """Everything a run produced. ``frames`` holds every recorded step (see ``World.run``)."""

    title: str
    mode: str
    dt: float
    steps: int
    restitution: float
    gravity: Vector3D
    dims: int = 3
    frames: list[Frame] = field(default_factory=list)
    #: The collisions, earliest first: a list, or (from a world) blocks of arrays whose events are
    #: built only when read, so a pile's millions of impacts cost no Python objects unless looked at.
    events: Sequence[CollisionEvent] = field(default_factory=SequenceChain)
    skipped: list[SkippedContact] = field(default_factory=list)
    ledger: Ledger = field(default_factory=Ledger)
    warnings: list[str] = field(default_factory=list)
    #: The scenario that was run (its shapes and masses draw the plot); ``None`` when unknown.
    scenario: Scenario | None = field(default=None, repr=False, compare=False)
    #: Collisions counted by the world, kept or not (a run streamed to an observer with
    #: ``keep=False`` keeps no events, only this count; see :attr:`collision_total`).
    collision_count: int = 0
    #: Each static's total impulse on the moving bodies over the run (N s, by name), when the
    #: stepper measures it (the contact solver); ``None`` otherwise. Their sum balances momentum:
    #: ``P_end - P_start - M g T`` (``M`` the bodies of finite mass).
    static_impulses: dict[str, list[float]] | None = None
    #: How exact mode treated contacts (``Settings.contacts``): ``"events"`` or ``"solve"``.
    contacts: str = "events"
    #: An event-driven mixture's kinds of ball (one per ``[[gas]]`` table), each one's ``name``,
    #: ``count``, ``radius``, ``mass`` and ``kT`` measured (:meth:`EventDrivenStepper.species_report
    #: <collisionlab.engine.event_stepper.EventDrivenStepper.species_report>`); ``None`` otherwise.
    species: list[dict[str, Any]] | None = None

    @property
    def collision_total(self) -> int:
        """The run's collisions: those counted, or those held when the record was built by hand."""
        return max(self.collision_count, len(self.events))

    def __repr__(self) -> str:
        """Counts, not contents (a long run holds thousands of frames)."""
        bodies = len(self.frames[0].bodies) if self.frames else 0
        return (
            f"<RunRecord {self.title!r}: {self.dims}D, mode {self.mode}, {self.steps} steps of {self.dt:g} s, "
            f"{_count(bodies, 'body', 'bodies')}, {_count(len(self.frames), 'frame')}, "
            f"{_count(len(self.events), 'collision')}, {_count(len(self.skipped), 'skipped contact')}, "
            f"{_count(len(self.warnings), 'warning')}>"
        )

    def to_dataframe(self, table: Literal["frames", "events", "skipped"] = "frames") -> pandas.DataFrame:
        """A table of the run as a pandas ``DataFrame`` (pandas is optional: the ``pandas`` extra,
        ``pip install 'collisionlab[pandas]'``; without it, :class:`~collisionlab.extras.MissingExtraError`).

        ``"frames"``: one row per recorded step and body (long form; ``pivot`` gives one column
        per body): ``step, time, body, x, y, z, vx, vy, vz``. ``"events"``: one row per
        collision: ``step, time, body_a, body_b, static, normal_x..z, point_x..z,
        approach_speed, impulse, restitution, below_rest_threshold, mass_a, mass_b,
        kinetic_energy_before, kinetic_energy_after``. ``"skipped"``: ``step, time, body_a,
        body_b, reason``.
        """
        pd = require("pandas", "pandas", "pandas tables (RunRecord.to_dataframe)")
        if table == "frames":
            columns = ["step", "time", "body", "x", "y", "z", "vx", "vy", "vz"]
            rows: list[tuple[Any, ...]] = [
                (f.step, f.time, b.name, *b.position.as_tuple(), *b.velocity.as_tuple())
                for f in self.frames
                for b in f.bodies
            ]
        elif table == "events":
            columns = [
                "step", "time", "body_a", "body_b", "static", "normal_x", "normal_y", "normal_z",
                "point_x", "point_y", "point_z", "approach_speed", "impulse", "restitution",
                "below_rest_threshold", "mass_a", "mass_b", "kinetic_energy_before", "kinetic_energy_after",
            ]  # fmt: skip
            rows = [
                (
                    e.step,
                    e.time,
                    *e.bodies,
                    e.static,
                    *e.normal.as_tuple(),
                    *e.point.as_tuple(),
                    e.approach_speed,
                    e.impulse,
                    e.restitution,
                    e.below_rest_threshold,
                    *e.masses,
                    e.kinetic_energy_before,
                    e.kinetic_energy_after,
                )
                for e in self.events
            ]
        elif table == "skipped":
            columns = ["step", "time", "body_a", "body_b", "reason"]
            rows = [(s.step, s.time, *s.bodies, s.reason) for s in self.skipped]
        else:
            from .errors import InvalidInputError

            raise InvalidInputError("table", "must be one of frames, events, skipped", got=table)
        return pd.DataFrame.from_records(rows, columns=columns)

    def plot(self, scenario: Scenario | None = None, size: tuple[int, int] = (1400, 800)) -> Figure:
        """The picture of ``--plot`` (trajectories, energy, momentum) as a matplotlib ``Figure``;
        ``scenario`` defaults to the one that was run."""
        from .errors import InvalidInputError

        # The one import from below the pictures into them (issue 30): a record draws itself, and
        # only when asked, so matplotlib loads only then. Not a circle: the pictures read a run
        # through their own protocol (plotting/_run.py), never this file.
        from .plotting.static import draw_figure

        scenario = scenario or self.scenario
        if scenario is None:
            raise InvalidInputError("scenario", "this record does not know its scenario; pass plot(scenario)")
        return draw_figure(self, scenario, size)

    def _repr_png_(self) -> bytes | None:
        """Jupyter shows a record as its plot (when the record knows its scenario)."""
        if self.scenario is None or not self.frames:
            return None
        import io

        buffer = io.BytesIO()
        self.plot(size=(1100, 620)).savefig(buffer, format="png")
        return buffer.getvalue()

    def summary(self) -> dict[str, Any]:
        return {
            "collisions": self.collision_total,
            "steps": self.steps,
            "time": self.frames[-1].time if self.frames else 0.0,
            "momentum_start": _vec(self.ledger.momentum_start),
            "momentum_end": _vec(self.ledger.momentum_end),
            "kinetic_energy_start": self.ledger.kinetic_start,
            "kinetic_energy_end": self.ledger.kinetic_end,
            **({} if self.static_impulses is None else {"static_impulses": self.static_impulses}),
            **({} if self.species is None else {"species": self.species}),
        }

    def replay(self, observer: RunObserver) -> None:
        """Tell ``observer`` this record as :meth:`World.run <collisionlab.engine.world.World.run>`
        told it: each frame after the events up to its step."""
        observer.begin(self)
        events, skipped = self.events, self.skipped
        e = s = 0
        for frame in self.frames:
            e2, s2 = e, s
            while e2 < len(events) and events[e2].step <= frame.step:
                e2 += 1
            while s2 < len(skipped) and skipped[s2].step <= frame.step:
                s2 += 1
            if e2 > e or s2 > s:
                observer.events(events[e:e2], skipped[s:s2], frame.step)
            e, s = e2, s2
            observer.frame(frame)
        if e < len(events) or s < len(skipped):
            observer.events(events[e:], skipped[s:], self.steps)
        observer.end(self)

    def header_dict(self) -> dict[str, Any]:
        """The JSON form's first keys: ``title``, ``dims``, ``settings``."""
        return {
            "title": self.title,
            "dims": self.dims,
            "settings": {
                "mode": self.mode,
                "dt": self.dt,
                "steps": self.steps,
                "restitution": self.restitution,
                "gravity": _vec(self.gravity),
                **({"contacts": self.contacts} if self.contacts != "events" else {}),
            },
        }

    def footer_dict(self) -> dict[str, Any]:
        """The JSON form's last keys: ``summary``, ``ledger``, ``warnings``."""
        return {
            "summary": self.summary(),
            "ledger": self.ledger.to_dict(),
            "warnings": list(self.warnings),
        }

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: ``frames``, ``events``, ``summary``, ``ledger`` and more."""
        return {
            **self.header_dict(),
            "frames": [f.to_dict() for f in self.frames],
            "events": [e.to_dict() for e in self.events],
            "skipped": [s.to_dict() for s in self.skipped],
            **self.footer_dict(),
        }
