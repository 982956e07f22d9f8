"""The numbers every picture draws, taken from one :class:`~collisionlab.record.RunRecord`.

Nothing here simulates: positions, velocities and times come from the record's frames, masses
and shapes from the scenario that produced it. Also the shared helpers: frame thinning, the
extent of the action, the geometry of each shape, and checking output paths.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidInputError, OutOfRangeError
from ..limits import MAX_RUN_COORDINATE
from ..model import Scenario
from ..shapes import AABB, Circle, Line, Plane, Sphere
from ..tolerances import PICTURE_MIN_SPAN
from ..vector import Vector3D
from ._run import DrawnEvent, DrawnRun

__all__ = [
    "BOX_TRIANGLES",
    "MAX_EVENT_MARKERS",
    "MAX_LABELLED_EVENTS",
    "Array",
    "Bounds",
    "RunArrays",
    "box_corners",
    "box_edges",
    "check_path",
    "circle_outline",
    "line_segment",
    "plane_patch",
    "sphere_mesh",
    "thin_indices",
    "uncrowded",
]

Array = NDArray[np.float64]

#: At most this many events get a text label ("step N") in a picture; all get a marker.
MAX_LABELLED_EVENTS = 20
#: At most this many event markers are drawn (evenly chosen when a run has more).
MAX_EVENT_MARKERS = 1000


def uncrowded(points: Array, crowd: float, limit: int = MAX_LABELLED_EVENTS) -> list[bool]:
    """Which of ``points`` get a label: in order, at most ``limit``, none closer than ``crowd``
    to one already labelled (so a run of small bounces does not pile its labels up)."""
    chosen: list[Array] = []
    keep = []
    for p in points:
        ok = len(chosen) < limit and all(float(np.linalg.norm(p - q)) >= crowd for q in chosen)
        if ok:
            chosen.append(p)
        keep.append(ok)
    return keep


def thin_indices(count: int, limit: int, keep: Sequence[int] = ()) -> NDArray[np.int64]:
    """Indices ``0 .. count - 1`` thinned to about ``limit``: evenly spaced, always with the first
    and the last, plus every index in ``keep`` (collision frames, so a bounce is not cut off).

    >>> thin_indices(10, 4).tolist()
    [0, 3, 6, 9]
    >>> thin_indices(5, 100).tolist()
    [0, 1, 2, 3, 4]
    >>> thin_indices(10, 3, keep=[6]).tolist()
    [0, 4, 6, 9]
    """
    if count <= 0:
        return np.zeros(0, dtype=np.int64)
    if count <= limit:
        return np.arange(count, dtype=np.int64)
    base = np.rint(np.linspace(0, count - 1, max(2, limit))).astype(np.int64)
    extra = np.asarray([k for k in keep if 0 <= k < count], dtype=np.int64)
    return np.unique(np.concatenate([base, extra]))


def _check_drawable(record: DrawnRun) -> None:
    """Pictures draw coordinates up to ``MAX_RUN_COORDINATE`` (what a run may reach): beyond,
    axis ticks, float32 pages and numpy's arange overflow."""
    farthest = max((abs(c) for frame in record.frames for body in frame.bodies for c in body.position), default=0.0)
    if farthest > MAX_RUN_COORDINATE:
        raise OutOfRangeError(f"the run reaches {farthest:.3g} m, beyond the {MAX_RUN_COORDINATE:g} m a picture draws")


def _vec(v: Vector3D) -> Array:
    return np.array([v.x, v.y, v.z], dtype=np.float64)


@dataclass(frozen=True)
class Bounds:
    """An axis-aligned region of space (m) that holds the action, with a margin."""

    low: Array
    high: Array

    @property
    def center(self) -> Array:
        return (self.low + self.high) / 2.0

    @property
    def span(self) -> float:
        """The largest edge (m), never 0."""
        return float(max(np.max(self.high - self.low), PICTURE_MIN_SPAN))

    def cube(self) -> Bounds:
        """A cube of edge :attr:`span` about the same centre (equal axes in 3D)."""
        half = self.span / 2.0
        return Bounds(self.center - half, self.center + half)


@dataclass(frozen=True)
class RunArrays:
    """A run's frames as arrays: ``times`` (F,), ``steps`` (F,), ``positions`` and ``velocities``
    (F, B, 3), with each body's ``names`` (B,), ``masses`` (B,) and scenario body."""

    record: DrawnRun
    scenario: Scenario
    names: tuple[str, ...]
    masses: Array
    times: Array
    steps: NDArray[np.int64]
    positions: Array
    velocities: Array

    @staticmethod
    def build(record: DrawnRun, scenario: Scenario) -> RunArrays:
        """The arrays of ``record``; refuses a record with no frames or with a body that the
        scenario does not have (the two must belong together)."""
        if not record.frames:
            raise InvalidInputError("record", "the run has no frames to draw")
        by_name = {b.name: b for b in scenario.bodies}
        names = tuple(b.name for b in record.frames[0].bodies)
        for name in names:
            if name not in by_name:
                raise InvalidInputError("record", f"body {name!r} is not in the scenario")
        _check_drawable(record)
        frames = record.frames
        count, nb = len(frames), len(names)
        flat_x = np.empty((count, nb * 6), dtype=np.float64)
        for i, frame in enumerate(frames):
            flat_x[i] = [c for b in frame.bodies for c in (*b.position, *b.velocity)]
        both = flat_x.reshape(count, nb, 6)
        return RunArrays(
            record=record,
            scenario=scenario,
            names=names,
            masses=np.array([by_name[n].mass for n in names], dtype=np.float64),
            times=np.array([f.time for f in frames], dtype=np.float64),
            steps=np.array([f.step for f in frames], dtype=np.int64),
            positions=np.ascontiguousarray(both[:, :, :3]),
            velocities=np.ascontiguousarray(both[:, :, 3:]),
        )

    # --- per-frame conserved quantities ---------------------------------------------------
    def kinetic_energy(self) -> Array:
        """Total kinetic energy (J) at each frame: sum of m |v|^2 / 2."""
        speed2 = np.einsum("fbk,fbk->fb", self.velocities, self.velocities)
        return np.asarray(0.5 * speed2 @ self.masses, dtype=np.float64)

    def potential_energy(self) -> Array:
        """Total potential energy (J) at each frame: -sum of m g . x (zero at the origin)."""
        g = _vec(self.record.gravity)
        return np.asarray(-(self.positions @ g) @ self.masses, dtype=np.float64)

    def momentum(self) -> Array:
        """Total momentum (kg m/s) at each frame, (F, 3): sum of m v."""
        return np.asarray(np.einsum("fbk,b->fk", self.velocities, self.masses), dtype=np.float64)

    # --- events ---------------------------------------------------------------------------
    def event_frames(self) -> list[int]:
        """For each event, the index of the first frame at or after its step (and the one
        before it), so thinning keeps the frames on both sides of every impact."""
        steps = [e.step for e in self.record.events]
        after = np.searchsorted(self.steps, np.asarray(steps, dtype=np.int64), side="left")
        last = len(self.steps) - 1
        keep: set[int] = set()
        for k in after.tolist():
            keep.add(min(int(k), last))
            keep.add(max(int(k) - 1, 0))
        return sorted(keep)

    def shown_events(self) -> list[DrawnEvent]:
        """The events that get a marker: all of them, or an even choice of
        :data:`MAX_EVENT_MARKERS` of them."""
        events = self.record.events
        if len(events) <= MAX_EVENT_MARKERS:
            return list(events)
        return [events[int(i)] for i in thin_indices(len(events), MAX_EVENT_MARKERS)]

    def interpolate(self, times: Array) -> Array:
        """Body positions (T, B, 3) at the given times, linear between recorded frames."""
        out = np.empty((len(times), len(self.names), 3), dtype=np.float64)
        for b in range(len(self.names)):
            for k in range(3):
                out[:, b, k] = np.interp(times, self.times, self.positions[:, b, k])
        return out

    # --- where the action is --------------------------------------------------------------
    def bounds(self) -> Bounds:
        """The region holding every body over the whole run (with its size), every box
        obstacle, every event point and a point of each line or plane, with a 10 % margin."""
        pos = self.positions.reshape(-1, 3)
        low = pos.min(axis=0)
        high = pos.max(axis=0)
        by_name = {b.name: b for b in self.scenario.bodies}
        reach = np.zeros(3)
        for name in self.names:
            shape = by_name[name].shape
            if isinstance(shape, (Circle, Sphere)):
                r = np.full(3, shape.radius)
                if isinstance(shape, Circle):
                    r[2] = 0.0
                reach = np.maximum(reach, r)
            else:
                reach = np.maximum(reach, _vec(shape.half_size))
        low, high = low - reach, high + reach
        points = [e.point for e in self.record.events[:MAX_EVENT_MARKERS]]
        for obstacle in self.scenario.obstacles:
            fixed = obstacle.shape
            if isinstance(fixed, AABB):
                points += [fixed.min_corner, fixed.max_corner]
        if points:
            pts = np.array([p.as_tuple() for p in points], dtype=np.float64)
            low = np.minimum(low, pts.min(axis=0))
            high = np.maximum(high, pts.max(axis=0))
        # An infinite line or plane: bring its closest point to the action into view.
        center = (low + high) / 2.0
        for obstacle in self.scenario.obstacles:
            fixed = obstacle.shape
            if isinstance(fixed, (Line, Plane)):
                p = _closest_point(fixed, center)
                low, high = np.minimum(low, p), np.maximum(high, p)
        span = float(max(np.max(high - low), PICTURE_MIN_SPAN))
        margin = 0.1 * span
        low, high = low - margin, high + margin
        if self.record.dims == 2:
            low[2], high[2] = 0.0, 0.0
        return Bounds(low, high)


def _closest_point(shape: Line | Plane, point: Array) -> Array:
    p0 = _vec(shape.point)
    if isinstance(shape, Line):
        d = _vec(shape.unit_direction)
        return np.asarray(p0 + d * float(np.dot(point - p0, d)), dtype=np.float64)
    n = _vec(shape.unit_normal)
    return np.asarray(point - n * float(np.dot(point - p0, n)), dtype=np.float64)


# --- geometry of the shapes ------------------------------------------------------------------
def sphere_mesh(center: Array, radius: float, n_u: int = 16, n_v: int = 9) -> tuple[Array, Array, Array]:
    """Grid points ``(X, Y, Z)`` (each ``n_v x n_u``) of a sphere's surface."""
    u = np.linspace(0.0, 2.0 * math.pi, n_u)
    v = np.linspace(0.0, math.pi, n_v)
    x = center[0] + radius * np.outer(np.sin(v), np.cos(u))
    y = center[1] + radius * np.outer(np.sin(v), np.sin(u))
    z = center[2] + radius * np.outer(np.cos(v), np.ones_like(u))
    return x, y, z


def circle_outline(center: Array, radius: float, count: int = 48) -> Array:
    """``count`` points (count, 3) around a circle in the x-y plane, closed."""
    t = np.linspace(0.0, 2.0 * math.pi, count)
    return np.stack([center[0] + radius * np.cos(t), center[1] + radius * np.sin(t), np.full(count, center[2])], 1)


#: The 12 edges of a box as pairs of corner indices; corner ``i`` takes bit 0 -> x, 1 -> y, 2 -> z.
_BOX_EDGES = [(a, b) for a in range(8) for b in range(a + 1, 8) if bin(a ^ b).count("1") == 1]


def box_corners(low: Array, high: Array) -> Array:
    """The 8 corners (8, 3) of a box; corner ``i`` takes the high side on x, y, z by bits 0, 1, 2."""
    return np.array(
        [[high[0] if i & 1 else low[0], high[1] if i & 2 else low[1], high[2] if i & 4 else low[2]] for i in range(8)]
    )


def box_edges(low: Array, high: Array) -> list[tuple[Array, Array]]:
    """The 12 edges of a box as (start, end) point pairs (a 2D box gives its 4 edges twice)."""
    c = box_corners(low, high)
    return [(c[a], c[b]) for a, b in _BOX_EDGES]


#: The 12 triangles of a box's 6 faces, over :func:`box_corners`' numbering.
BOX_TRIANGLES: tuple[tuple[int, int, int], ...] = (
    (0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5),  # z low, z high
    (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6),  # y low, y high
    (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3),  # x low, x high
)  # fmt: skip


def line_segment(line: Line, bounds: Bounds) -> tuple[Array, Array]:
    """The part of an infinite line that crosses ``bounds``' square about its centre."""
    p = _closest_point(line, bounds.center)
    d = _vec(line.unit_direction)
    half = bounds.span * 0.75
    return p - d * half, p + d * half


def plane_patch(plane: Plane, bounds: Bounds) -> Array:
    """Four corners (4, 3) of a square piece of a plane around the action, about as wide as it."""
    n = _vec(plane.unit_normal)
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(n, helper)
    u /= np.linalg.norm(u)
    w = np.cross(n, u)
    c = _closest_point(plane, bounds.center)
    h = bounds.span * 0.55
    return np.array([c - h * u - h * w, c + h * u - h * w, c + h * u + h * w, c - h * u + h * w])


# --- files -------------------------------------------------------------------------------------
def check_path(path: str, option: str, suffixes: Sequence[str], form: str) -> Path:
    """``path`` as a :class:`Path` when its extension is one of ``suffixes`` and its folder
    exists; else :class:`InvalidInputError` naming ``option`` and the expected ``form``."""
    target = Path(path)
    if target.suffix.lower() not in suffixes:
        raise InvalidInputError(option, f"expected {form}", got=path)
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise InvalidInputError(option, f"folder {str(folder)!r} does not exist; expected {form}", got=path)
    if target.is_dir():
        raise InvalidInputError(option, f"is a folder; expected {form}", got=path)
    return target
