"""Trajectories of a gas for the field's tools: HOOMD's GSD (``.gsd``, through the ``gsd``
package) or extended XYZ (``.xyz``, written here, no package needed), frames at equal times.

What ``collisionlab gas --trajectory FILE --frames K`` writes: ``K`` frames at the times
``T k / (K - 1)``, ``k = 0 .. K - 1`` (the start and the end included; ``K = 1``: the end only),
each with every ball's position, velocity and diameter, its type (species) name and id, ids in
the order the balls were made, the box and the step. One kind of ball is one type, named
:data:`TYPE_NAME` (type id 0); a mixture (``--species``) has one type per species, in the order
given, each ball its own diameter (:class:`Types`).

* **GSD** (HOOMD-blue's schema, read by ``gsd.hoomd``, OVITO, freud, MDAnalysis): the box is
  centred on the origin, so positions are collisionlab's (box ``[0, L]``) minus ``L / 2``;
  in 2D ``configuration.dimensions`` is 2, the box's ``Lz`` is 0 and ``z`` is 0. Positions,
  velocities and diameters are single precision (the schema's); ``particles/types`` holds the
  type names, ``particles/typeid`` each ball's. ``configuration.step`` is the step number (an
  event-driven run has no steps: the frame's index) and the chunk ``log/time`` the simulated
  time (double precision).
* **Extended XYZ** (ASE, OVITO): the box ``[0, L]`` as it is (``Lattice``, origin at 0; in 2D its
  third vector is zero and ``z`` is 0), ``pbc`` ``T`` along periodic axes, ``Time`` and ``Step``
  in the comment line, and per ball ``species pos velo radius id typeid Z`` with numbers written
  to 17 digits (read back to the last bit). ``species`` is the ball's type name (OVITO's
  particle type), ``typeid`` its index among the types. ``Z`` (atomic number) is 0: ASE needs a
  chemical element, and 0 is its dummy one (``X``; ASE then keeps ``typeid`` but not the name).

With walls, the box written is the one the walls bound (``pbc`` ``F`` in XYZ; GSD's box has no
flag for it). A file is written beside its target and renamed over it only when the run ends
well (:mod:`collisionlab.atomic`): an error or an interrupt leaves no half-written file.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, Protocol

import numpy as np
from numpy.typing import NDArray

from .atomic import atomic_path, atomic_stream
from .errors import InvalidInputError

if TYPE_CHECKING:
    from .engine.world import World

__all__ = [
    "MAX_FRAMES",
    "TRAJECTORY_FORMATS",
    "TYPE_NAME",
    "FrameWriter",
    "Types",
    "advance_in_frames",
    "check_frames",
    "frame_steps",
    "require_gsd",
    "steps_for_frames",
    "trajectory_file",
    "trajectory_format",
]

#: File extensions and the format each means.
TRAJECTORY_FORMATS: dict[str, str] = {".gsd": "gsd", ".xyz": "xyz"}
#: The type (species) name of the balls of one kind (type id 0).
TYPE_NAME = "A"
#: At most this many frames (each a step of the run: an event-driven run's steps shrink with them).
MAX_FRAMES = 1_000_000

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Types:
    """The balls' types (species) and sizes for a trajectory: ``names`` (one per type, in
    order), each ball's type id ``ids`` (``(n,)``, indices into ``names``) and radius ``radii``
    (``(n,)``), in the order the balls were made.

    >>> t = Types.one_kind(3, 0.5)
    >>> t.names, t.ids.tolist(), t.radii.tolist()
    (('A',), [0, 0, 0], [0.5, 0.5, 0.5])
    """

    names: tuple[str, ...]
    ids: NDArray[np.int64]
    radii: FloatArray

    @classmethod
    def one_kind(cls, n: int, radius: float, name: str = TYPE_NAME) -> Types:
        """``n`` balls of one type ``name`` and one ``radius``."""
        return cls((name,), np.zeros(n, dtype=np.int64), np.full(n, float(radius)))

    def checked(self) -> Types:
        """The same types, validated (:class:`InvalidInputError`, field ``species``): names
        printable, without spaces (an XYZ column) and unique, ids within them, one id and one
        positive finite radius per ball."""
        names = tuple(str(name) for name in self.names)
        for name in names:
            if not name or not name.isprintable() or any(c.isspace() for c in name):
                raise InvalidInputError("species", "a name in a trajectory must be printable, without spaces", got=name)
        if len(set(names)) != len(names):
            raise InvalidInputError("species", "each name once in a trajectory", got=", ".join(names))
        ids = np.asarray(self.ids, dtype=np.int64).reshape(-1)
        radii = np.asarray(self.radii, dtype=np.float64).reshape(-1)
        if ids.shape != radii.shape:
            raise InvalidInputError("species", "one type id and one radius per ball", got=(ids.size, radii.size))
        if ids.size and (ids.min() < 0 or ids.max() >= len(names)):
            raise InvalidInputError("species", f"type ids must be 0 to {len(names) - 1}", got=int(ids.max()))
        if not np.all(np.isfinite(radii) & (radii > 0)):
            raise InvalidInputError("species", "radii must be finite and > 0")
        return Types(names, ids, radii)


class FrameWriter(Protocol):
    """Writes one frame: its step number, time, and every ball's positions and velocities
    (``(n, dim)``, in the order the balls were made)."""

    def __call__(self, step: int, time: float, positions: FloatArray, velocities: FloatArray) -> None: ...


def trajectory_format(path: str | Path) -> str:
    """``"gsd"`` or ``"xyz"`` from the file's extension (:class:`InvalidInputError` otherwise).

    >>> trajectory_format("run.GSD"), trajectory_format("run.xyz")
    ('gsd', 'xyz')
    >>> trajectory_format("run.dcd")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    collisionlab.errors.InvalidInputError: trajectory: must end in .gsd (HOOMD's GSD) or .xyz (...) (got 'run.dcd')
    """
    kind = TRAJECTORY_FORMATS.get(Path(path).suffix.lower())
    if kind is None:
        raise InvalidInputError("trajectory", "must end in .gsd (HOOMD's GSD) or .xyz (extended XYZ)", got=str(path))
    return kind


def check_frames(frames: int) -> int:
    """``frames`` if it is a whole number from 1 to :data:`MAX_FRAMES` (:class:`InvalidInputError`
    otherwise)."""
    if isinstance(frames, bool) or not isinstance(frames, int) or not 1 <= frames <= MAX_FRAMES:
        raise InvalidInputError("frames", f"must be a whole number from 1 to {MAX_FRAMES:,}", got=frames)
    return frames


def frame_steps(steps: int, frames: int) -> list[int]:
    """The steps (from the run's start) at which ``frames`` frames fall at equal times: ``0``,
    ``steps / (frames - 1)``, ..., ``steps``; one frame: ``steps`` (the end). ``frames - 1`` must
    divide ``steps`` (:class:`InvalidInputError` naming ``frames`` otherwise).

    >>> frame_steps(100, 5), frame_steps(100, 1), frame_steps(7, 2)
    ([0, 25, 50, 75, 100], [100], [0, 7])
    """
    frames = check_frames(frames)
    if frames == 1:
        return [steps]
    if steps % (frames - 1):
        raise InvalidInputError("frames", f"frames at equal times need K - 1 to divide the {steps:,} steps", got=frames)
    return [k * (steps // (frames - 1)) for k in range(frames)]


def steps_for_frames(steps: int, frames: int) -> int:
    """The fewest steps, at least ``steps``, that ``frames - 1`` divides (an event-driven run's
    steps only say when to stop: their number changes nothing else).

    >>> steps_for_frames(1000, 5), steps_for_frames(1000, 7), steps_for_frames(1000, 1)
    (1000, 1002, 1000)
    """
    spans = max(1, check_frames(frames) - 1)
    return spans * math.ceil(steps / spans)


def advance_in_frames(
    world: World,
    steps: int,
    frames: int,
    write: FrameWriter,
    between: Callable[[int, int], None] | None = None,
    calling: Callable[[Callable[[], None]], None] | None = None,
) -> float:
    """:meth:`World.advance <collisionlab.engine.world.World.advance>` ``steps`` steps, stopping
    at :func:`frame_steps` to ``write`` a frame (the start's before any step); ``between(done,
    steps)`` as ``advance`` calls it, counted over the whole run. The step written is the
    world's step number, or the frame's index for an event-driven run (it has no steps). Returns
    the seconds spent stepping (writing frames not counted). ``calling`` as ``advance`` takes it."""
    dim = world.dims
    start = world.step_index
    spent = 0.0
    for index, stop in enumerate(frame_steps(steps, frames)):
        todo = start + stop - world.step_index
        if todo > 0:
            done_before = world.step_index - start
            relay = None
            if between is not None:
                relay = lambda done, _total, base=done_before: between(base + done, steps)  # noqa: E731
            spent += world.advance(todo, relay, calling=calling)
        step = index if world.event_driven else world.step_index
        write(step, float(world.time), world.position_array[:, :dim], world.velocity_array[:, :dim])
    return spent


def _box3(sides: tuple[float, ...]) -> tuple[float, float, float]:
    """The box's three lengths, the third 0 in 2D (GSD's and XYZ's flat box)."""
    return (float(sides[0]), float(sides[1]), float(sides[2]) if len(sides) > 2 else 0.0)


def _padded(values: FloatArray) -> FloatArray:
    """``(n, dim)`` as ``(n, 3)``, ``z = 0`` in 2D."""
    out = np.zeros((values.shape[0], 3))
    out[:, : values.shape[1]] = values
    return out


class _XyzWriter:
    def __init__(self, out: IO[str], sides: tuple[float, ...], periodic: bool, types: Types) -> None:
        self._out = out
        lx, ly, lz = _box3(sides)
        flags = " ".join("T" if periodic and k < len(sides) else "F" for k in range(3))
        self._head = (
            f'Lattice="{lx!r} 0 0 0 {ly!r} 0 0 0 {lz!r}" '
            "Properties=species:S:1:pos:R:3:velo:R:3:radius:R:1:id:I:1:typeid:I:1:Z:I:1 "
            f'pbc="{flags}"'
        )
        n = types.ids.size
        # the columns that do not change: species first, radius, id and type id after the numbers
        self._names = np.array(types.names, dtype=object)[types.ids]
        self._radii = types.radii.astype(object)
        self._ids = np.arange(n).astype(object)
        self._typeids = types.ids.astype(object)
        self._row = "%s" + " %.17g" * 7 + " %d %d 0"

    def __call__(self, step: int, time: float, positions: FloatArray, velocities: FloatArray) -> None:
        n = positions.shape[0]
        self._out.write(f"{n}\n{self._head} Time={float(time)!r} Step={int(step)}\n")
        table = np.empty((n, 10), dtype=object)
        table[:, 0] = self._names
        table[:, 1:7] = np.column_stack([_padded(positions), _padded(velocities)])
        table[:, 7] = self._radii
        table[:, 8] = self._ids
        table[:, 9] = self._typeids
        np.savetxt(self._out, table, fmt=self._row)


class _GsdWriter:
    def __init__(self, trajectory: Any, sides: tuple[float, ...], periodic: bool, types: Types) -> None:
        self._file, self._periodic = trajectory, periodic
        self._types = list(types.names)
        self._typeid = types.ids.astype(np.uint32)
        self._diameter = (2.0 * types.radii).astype(np.float32)
        self._dim = len(sides)
        self._box = np.array(_box3(sides))

    def __call__(self, step: int, time: float, positions: FloatArray, velocities: FloatArray) -> None:
        import gsd.hoomd

        n = positions.shape[0]
        frame = gsd.hoomd.Frame()
        frame.configuration.step = int(step)
        frame.configuration.dimensions = self._dim
        frame.configuration.box = [*self._box.tolist(), 0.0, 0.0, 0.0]
        centred = (_padded(positions) - self._box / 2.0).astype(np.float32)
        if self._periodic:  # rounding to single precision may reach +L/2: the same point as -L/2
            half = (self._box / 2.0).astype(np.float32)
            centred = np.where((centred >= half) & (half > 0), centred - 2 * half, centred)
        frame.particles.N = n
        frame.particles.types = self._types
        frame.particles.typeid = self._typeid
        frame.particles.position = centred
        frame.particles.velocity = _padded(velocities).astype(np.float32)
        frame.particles.diameter = self._diameter
        frame.log["time"] = np.array([time], dtype=np.float64)
        self._file.append(frame)


def require_gsd() -> None:
    """The ``gsd`` package, or one line naming the ``trajectory`` extra
    (:class:`~collisionlab.extras.MissingExtraError`)."""
    from .extras import require

    require("gsd.hoomd", "trajectory", "GSD trajectories")


@contextlib.contextmanager
def trajectory_file(
    path: str | Path,
    sides: tuple[float, ...],
    periodic: bool,
    types: Types,
) -> Iterator[FrameWriter]:
    """A :class:`FrameWriter` into ``path`` (``.gsd`` or ``.xyz``), for the balls ``types``
    names (each one's type and radius; :meth:`Types.one_kind` for balls of one kind) in the box
    ``[0, sides]`` (2 or 3 lengths; ``periodic`` or walled). The file replaces ``path`` when the
    block ends without error; otherwise nothing is left (see the module's docstring)."""
    kind = trajectory_format(path)
    sides = tuple(float(s) for s in sides)
    types = types.checked()  # before a file is opened
    if kind == "xyz":
        with atomic_stream(path) as out:
            yield _XyzWriter(out, sides, periodic, types)
        return
    require_gsd()
    import gsd.hoomd

    with atomic_path(path) as temporary, gsd.hoomd.open(name=str(temporary), mode="w") as trajectory:
        yield _GsdWriter(trajectory, sides, periodic, types)
