"""Collision events: one (:class:`CollisionEvent`), or many held as rows of arrays
(:class:`EventBlock`, what the compiled steppers write), each built into a ``CollisionEvent``
only when read, and their JSON laid out by the text kernel (:mod:`.text_kernels`) instead of one
``json.dumps`` per event.
"""

from __future__ import annotations

import functools
import json
import math
import string
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import orjson
from numpy.typing import NDArray

from . import text_kernels
from .built_sequence import BuiltSequence
from .vector import Vector3D

__all__ = ["CollisionEvent", "EventBlock", "json_numbers", "json_vector"]


def json_vector(v: Vector3D) -> list[float]:
    """``v`` as a list, ``-0.0`` written ``0.0`` (a signed zero reads as another number)."""
    return [v.x + 0.0, v.y + 0.0, v.z + 0.0]


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
            "normal": json_vector(self.normal),
            "point": json_vector(self.point),
            "approach_speed": self.approach_speed + 0.0,
            "impulse": self.impulse + 0.0,
            "restitution": self.restitution + 0.0,
            "velocities_before": {k: json_vector(v) for k, v in self.velocities_before.items()},
            "velocities_after": {k: json_vector(v) for k, v in self.velocities_after.items()},
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
