"""The range of magnitudes collisionlab simulates, decided here and nowhere else.

A scenario is refused before it runs (:func:`check_scenario`, called by
:class:`~collisionlab.model.Scenario`) when a number lies outside these bounds, with a one-line
:class:`~collisionlab.errors.InvalidInputError` naming the field. Inside them every product the
simulation forms (``m v^2``, ``m g x``, the squared distances of time of impact) stays far from
overflow, and the absolute tolerances of :mod:`collisionlab.tolerances` (nanometres) still
resolve the scene. A run whose numbers grow out of range anyway (restitution above 1 adds energy
at each collision) stops with :class:`~collisionlab.errors.OutOfRangeError` at that step
(:class:`~collisionlab.run_guard.RangeGuard`), so no output ever holds ``inf`` or ``NaN``.

The bounds (SI units):

==========================  ===================  ==============================================
what                        range                why
==========================  ===================  ==============================================
coordinates (any point)     ``|x| <= 1e9`` m     ``ulp(1e9) ~ 1e-7`` m: ``CONTACT_MARGIN`` still
                                                 resolves a contact there
radius, box edge            ``1e-6 .. 1e9`` m    1000x the contact tolerances at the small end
speed (each component)      ``<= 1e9`` m/s       ``m v^2`` stays below 1e50 J
gravity (each component)    ``<= 1e9`` m/s^2
mass                        ``1e-30 .. 1e30`` kg  or ``inf``: a kinematic body
dt                          ``1e-9 .. 1e6`` s
kept frames x moving bodies ``<= 2e6``           a run kept whole (pictures) holds a frame
                                                 every ``every`` steps: 0.40-0.46 kB per body
                                                 and frame (measured), so at most ~1 GB; a
                                                 table, CSV or JSON streams them (no bound)
restitution                 ``0 .. 10``
exact mode: travel per      ``<= 1e6`` x the     time of impact resolves a touch to about
step (relative)             smallest radius or   ``sqrt(eps) = 1.5e-8`` of the distance
                            half edge            travelled; beyond ~1e7 sizes per step it misses
during a run: positions     ``|x| <= 1e12`` m,   beyond: the run stops (exit status 65)
and speeds                  ``|v| <= 1e12`` m/s
gas: balls                  ``<= 1e7``           the exact gas: ~475 bytes a ball in arrays,
                                                 ~1 kB resident (measured at 1e6): ~10 GB
exact gas: time             ``1e-9 .. 1e6``      event times are absolute: at 1e6 a double
                                                 still resolves 1e-10 of a time unit
exact gas: packing fraction ``>= 1e-6``          sparser, a ball meets another less than once
                                                 in 1e6 time units
scenario file               ``<= 1,000,000``
                            bytes
==========================  ===================  ==============================================

>>> within(2.0, "dt", MIN_DT, MAX_DT, "s")
2.0
>>> within(1e308, "dt", MIN_DT, MAX_DT, "s")
Traceback (most recent call last):
...
collisionlab.errors.InvalidInputError: dt: must be at most 1e+06 s, the largest collisionlab simulates (got 1e+308)
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, Protocol

import numpy as np

from .body_block import Bodies, BodyBlock, BodyColumns
from .errors import InvalidInputError
from .tolerances import MAX_RUN_SPEED as _MAX_RUN_SPEED
from .validate import non_negative, positive, whole_number
from .vector import Vector3D

__all__ = [
    "MAX_ACCELERATION",
    "MAX_BODY_STEPS",
    "MAX_COORDINATE",
    "MAX_DT",
    "MAX_GAS_BALLS",
    "MAX_GAS_TIME",
    "MAX_MASS",
    "MAX_RESTITUTION",
    "MAX_RUN_COORDINATE",
    "MAX_RUN_SPEED",
    "MAX_SCENARIO_BYTES",
    "MAX_SIZE",
    "MAX_SPEED",
    "MAX_STEPS",
    "MAX_TRAVEL_PER_SIZE",
    "MIN_DT",
    "MIN_GAS_FRACTION",
    "MIN_GAS_TIME",
    "MIN_MASS",
    "MIN_SIZE",
    "ScenarioNumbers",
    "check_frames",
    "check_scenario",
    "check_vector",
    "closing_speed",
    "dt",
    "gas_balls",
    "gas_time",
    "reach",
    "restitution",
    "steps",
    "within",
]

#: Metres: the largest coordinate of any point a scenario gives.
MAX_COORDINATE = 1e9
#: Metres: the smallest and largest radius or box edge.
MIN_SIZE = 1e-6
MAX_SIZE = 1e9
#: m/s, per component.
MAX_SPEED = 1e9
#: m/s^2, per component of gravity.
MAX_ACCELERATION = 1e9
#: Kilograms.
MIN_MASS = 1e-30
MAX_MASS = 1e30
#: Seconds.
MIN_DT = 1e-9
MAX_DT = 1e6
#: Frames kept times moving bodies of one run: each kept frame holds every body's state, 0.40-0.46
#: kB per body (measured with tracemalloc on the spheres and newtons-cradle demos), so ~1 GB here.
#: A run keeps a frame every ``every`` steps (``--every``), so long runs fit by keeping fewer.
MAX_BODY_STEPS = 2_000_000
#: Steps of one run (a single body): the same bound.
MAX_STEPS = MAX_BODY_STEPS
#: Dimensionless: the largest coefficient of restitution (above 1 each collision adds energy).
MAX_RESTITUTION = 10.0
#: Exact mode: how many times its smallest radius (or half edge) a body may travel relative to
#: another in one step; measured: misses begin near 1e7-1e8 (tests/test_limits.py).
MAX_TRAVEL_PER_SIZE = 1e6
#: During a run: metres and m/s. Beyond these the run stops with OutOfRangeError. (The speed
#: lives with the tolerances: the exact stepper's kernels read it, and a kernel that read this
#: file would be compiled again whenever a policy here changed.)
MAX_RUN_COORDINATE = 1e12
MAX_RUN_SPEED = _MAX_RUN_SPEED
#: Balls of the many-body gas (both modes of ``collisionlab gas``): the exact gas holds ~475 bytes
#: a ball in arrays, ~1 kB resident (bench/README.md), so at most ~10 GB.
MAX_GAS_BALLS = 10_000_000
#: Time units of the exact gas (radius 1, mass 1, kT 1). Its event times are absolute: at 1e6 a
#: double still resolves 1e-10 of a time unit; below 1e-9 its pressure (momentum given to the
#: walls over the time) could overflow.
MIN_GAS_TIME = 1e-9
MAX_GAS_TIME = 1e6
#: The exact gas's packing fraction (area or volume): a ball's free path is about a radius over
#: the fraction, so below this it would meet another less than once in ``MAX_GAS_TIME``.
MIN_GAS_FRACTION = 1e-6
#: Bytes: the largest scenario file read (a file is read up to this and one byte more).
MAX_SCENARIO_BYTES = 1_000_000


# The scenario as this file reads it. The model's Scenario validates itself with check_scenario
# (model imports limits), so limits names the parts it reads instead of importing model: an
# import circle otherwise (issue 30). mypy checks that model.Scenario has them where it calls.
class _SettingsNumbers(Protocol):
    @property
    def dt(self) -> float: ...
    @property
    def steps(self) -> int: ...
    @property
    def restitution(self) -> float: ...
    @property
    def gravity(self) -> Vector3D: ...
    @property
    def mode(self) -> str: ...


class _ObstacleNumbers(Protocol):
    @property
    def shape(self) -> object: ...
    @property
    def restitution(self) -> float | None: ...


class ScenarioNumbers(Protocol):
    """What :func:`check_scenario` and :class:`RangeGuard` read of a
    :class:`~collisionlab.model.Scenario`: its settings, bodies, obstacles and dimension."""

    @property
    def settings(self) -> _SettingsNumbers: ...
    @property
    def bodies(self) -> Bodies: ...
    @property
    def obstacles(self) -> Sequence[_ObstacleNumbers]: ...
    @property
    def dims(self) -> int: ...


def within(value: float, field: str, low: float, high: float, unit: str = "") -> float:
    """``value`` when ``low <= |value| <= high`` (``low = 0`` allows 0), else an error naming ``field``."""
    units = f" {unit}" if unit else ""
    if isinstance(value, float) and not math.isfinite(value):  # (an int is finite, however large)
        raise InvalidInputError(field, "must be a finite number", value)
    if abs(value) > high:
        raise InvalidInputError(field, f"must be at most {high:g}{units}, the largest collisionlab simulates", value)
    if abs(value) < low:
        raise InvalidInputError(field, f"must be at least {low:g}{units}, the smallest collisionlab simulates", value)
    return value


def dt(value: object, field: str) -> float:
    """A time step: a number > 0 within ``[MIN_DT, MAX_DT]`` (a flag's check, as a file's)."""
    return within(positive(value, field), field, MIN_DT, MAX_DT, "s")


def steps(value: object, field: str) -> int:
    """A number of steps: a whole number >= 1, at most ``MAX_STEPS``."""
    count = whole_number(value, field, minimum=1)
    within(count, field, 0, MAX_STEPS)
    return count


def gas_balls(value: object, field: str) -> int:
    """A number of balls of the many-body gas: a whole number >= 1, at most ``MAX_GAS_BALLS``."""
    count = whole_number(value, field, minimum=1)
    within(count, field, 0, MAX_GAS_BALLS)
    return count


def gas_time(value: object, field: str) -> float:
    """How long the exact gas runs: a number within ``[MIN_GAS_TIME, MAX_GAS_TIME]``."""
    return within(positive(value, field), field, MIN_GAS_TIME, MAX_GAS_TIME)


def restitution(value: object, field: str) -> float:
    """A coefficient of restitution in ``[0, MAX_RESTITUTION]``."""
    return within(non_negative(value, field), field, 0.0, MAX_RESTITUTION)


def check_vector(vector: Vector3D, field: str, high: float, unit: str) -> Vector3D:
    """``vector`` when every component is at most ``high`` in size."""
    for component in vector:
        if abs(component) > high:
            within(component, field, 0.0, high, unit)
    return vector


def _sizes(shape: object) -> list[float]:
    """A body's radius, or its box's edges (the ones it has: 2 for a 2D box)."""
    from .shapes import AABB

    if isinstance(shape, AABB):
        return list((shape.max_corner - shape.min_corner).as_tuple()[: shape.dim])
    radius = getattr(shape, "radius", None)
    return [] if radius is None else [float(radius)]


def _points(shape: object) -> list[tuple[str, Vector3D]]:
    """The points a shape is placed by, under the name a scenario file gives them."""
    from .shapes import AABB, Circle, Line, Plane, Sphere

    if isinstance(shape, AABB):
        return [("position", shape.min_corner), ("position", shape.max_corner)]
    if isinstance(shape, (Circle, Sphere)):
        return [("position", shape.center)]
    if isinstance(shape, (Line, Plane)):
        return [("point", shape.point)]
    return []


def check_frames(steps: int, every: int, bodies: int, field: str = "steps") -> None:
    """Refuse a run whose kept frames (one every ``every`` steps, and the first and last) times its
    ``bodies`` exceed ``MAX_BODY_STEPS``: it would not fit in memory.

    >>> check_frames(1_000_000, 1000, 2)   # 1,000 frames of 2 bodies (and the first)
    >>> try:
    ...     check_frames(2_000_000, 1, 5)
    ... except InvalidInputError as error:
    ...     print(error.field, "2,000,000 frames of 5 bodies" in str(error))
    steps True
    """
    frames = steps // every + (1 if steps % every else 0)  # after the first: one per `every` and the last
    if frames * bodies > MAX_BODY_STEPS:
        raise InvalidInputError(
            field,
            f"keeps {frames:,} frames of {bodies:,} bodies: at most {MAX_BODY_STEPS:,} body-frames fit in memory; "
            "keep fewer frames (--every) or run fewer steps",
            steps,
        )


def check_scenario(scenario: ScenarioNumbers, columns: BodyColumns | None = None) -> None:
    """Refuse a scenario with a number outside the range above, naming the field as a scenario
    file does (``simulation.dt``, ``body[0].velocity``, ``static[1].point``). ``columns``: the
    bodies as arrays, if the caller has them already."""
    s = scenario.settings
    within(s.dt, "simulation.dt", MIN_DT, MAX_DT, "s")
    within(s.steps, "simulation.steps", 0, MAX_STEPS)
    within(s.restitution, "simulation.restitution", 0.0, MAX_RESTITUTION)
    check_vector(s.gravity, "simulation.gravity", MAX_ACCELERATION, "m/s^2")
    for index, body in enumerate(scenario.bodies.singles):
        where = f"body[{index}]"
        for key, point in _points(body.shape):
            check_vector(point, f"{where}.{key}", MAX_COORDINATE, "m")
        for size in _sizes(body.shape):
            within(size, f"{where}.{'radius' if hasattr(body.shape, 'radius') else 'size'}", MIN_SIZE, MAX_SIZE, "m")
        check_vector(body.velocity, f"{where}.velocity", MAX_SPEED, "m/s")
        if body.mass != math.inf:  # infinite: a kinematic body
            within(body.mass, f"{where}.mass", MIN_MASS, MAX_MASS, "kg")
        if body.restitution is not None:
            within(body.restitution, f"{where}.restitution", 0.0, MAX_RESTITUTION)
    for index, block in enumerate(scenario.bodies.blocks):
        _check_block(block, f"gas[{index}]")
    for index, obstacle in enumerate(scenario.obstacles):
        where = f"static[{index}]"
        for key, point in _points(obstacle.shape):
            check_vector(point, f"{where}.{key}", MAX_COORDINATE, "m")
        for size in _sizes(obstacle.shape):
            within(size, f"{where}.size", MIN_SIZE, MAX_SIZE, "m")
        if obstacle.restitution is not None:
            within(obstacle.restitution, f"{where}.restitution", 0.0, MAX_RESTITUTION)
    if s.mode == "exact":
        _check_travel(scenario, scenario.bodies.columns() if columns is None else columns)


def closing_speed(speeds: Sequence[float]) -> float:
    """The fastest two bodies can close on each other: the sum of the two largest speeds."""
    top = sorted(speeds, reverse=True)[:2]
    return sum(top)


def _smallest_halves(scenario: ScenarioNumbers, columns: BodyColumns) -> Any:
    """Each body's smallest half size: its radius, or half its box's shortest edge."""
    dims = scenario.dims
    return np.where(columns.kind <= 1, columns.ext[:, 0], columns.ext[:, :dims].min(axis=1))


def reach(scenario: ScenarioNumbers, columns: BodyColumns | None = None) -> float:
    """How far bodies may close in one step in exact mode: ``MAX_TRAVEL_PER_SIZE`` times the
    smallest sum of two bodies' sizes (radius, or half the shortest edge), the distance at which
    time of impact must resolve a touch; a lone body against obstacles, its own size."""
    sizes = np.sort(_smallest_halves(scenario, scenario.bodies.columns() if columns is None else columns))[:2]
    return MAX_TRAVEL_PER_SIZE * float(sizes.sum())


def _check_travel(scenario: ScenarioNumbers, columns: BodyColumns) -> None:
    """Exact mode: two bodies may close by at most ``reach`` in one step, else time of impact
    cannot resolve the touch (measured: it misses beyond ~1e7 sizes per step)."""
    velocities = columns.vel
    speeds = np.sqrt(np.einsum("ij,ij->i", velocities, velocities))
    travel = closing_speed(np.sort(speeds)[-2:].tolist()) * scenario.settings.dt
    if travel > reach(scenario, columns):
        fastest = int(np.argmax(speeds))
        raise InvalidInputError(
            _body_field(scenario, fastest, "velocity"),
            f"bodies close by {travel:.3g} m in a step of {scenario.settings.dt:g} s, more than "
            f"{MAX_TRAVEL_PER_SIZE:g} times their sizes, beyond what exact mode resolves; use a smaller dt",
            tuple(velocities[fastest].tolist()),
        )


def _body_field(scenario: ScenarioNumbers, index: int, key: str) -> str:
    """The field of body ``index`` as a scenario file names it: ``body[i].key`` for a body given
    alone, ``gas[k].key`` for one of a block."""
    singles = blocks = 0
    for part in scenario.bodies.parts:
        if index < len(part):
            return f"gas[{blocks}].{key}" if isinstance(part, BodyBlock) else f"body[{singles + index}].{key}"
        index -= len(part)
        if isinstance(part, BodyBlock):
            blocks += 1
        else:
            singles += len(part)
    return f"body.{key}"


def _check_block(block: BodyBlock, where: str) -> None:
    """:func:`check_scenario` for a block's arrays at once."""
    for key, rows, high, unit in (
        ("position", block.positions, MAX_COORDINATE, "m"),
        ("velocity", block.velocities, MAX_SPEED, "m/s"),
    ):
        worst = float(np.abs(rows).max(initial=0.0))
        if worst > high:
            within(worst, f"{where}.{key}", 0.0, high, unit)
    box = block.shape == "aabb"
    for size in [2.0 * h for h in block.half[: block.dims]] if box else [block.half[0]]:
        within(size, f"{where}.{'size' if box else 'radius'}", MIN_SIZE, MAX_SIZE, "m")
    if block.mass != math.inf:
        within(block.mass, f"{where}.mass", MIN_MASS, MAX_MASS, "kg")
    if block.restitution is not None:
        within(block.restitution, f"{where}.restitution", 0.0, MAX_RESTITUTION)
