"""The lab's menu's questions (part VI.A-B): each asks one field, with its default, the form it
expects, and the parser that turns an answer into a value or a one-line reason
(:class:`~collisionlab.errors.InvalidInputError`, the menu asks again). The parsers check what a
scenario file's validation checks, with the same limits; :mod:`.menu` asks them, case by case.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from .. import limits
from ..errors import InvalidInputError
from ..shapes import Plane
from ..validate import finite_number, positive
from ..vector import Vector3D

__all__ = ["Answers", "Question"]

Answers = dict[str, Any]


@dataclass(frozen=True)
class Question:
    """One prompt: ``key`` names the answer, ``parse`` turns the text into a value or raises
    :class:`InvalidInputError` (it also sees the earlier answers, for the plane's third point)."""

    key: str
    text: str
    form: str
    default: str
    parse: Callable[[str, Answers], Any]
    #: A default that depends on the earlier answers (the plane's third point), else ``default``.
    suggest: Callable[[Answers], str] | None = None

    def default_for(self, answers: Answers) -> str:
        return self.suggest(answers) if self.suggest is not None else self.default


def _numbers(text: str, count: int, field: str) -> list[float]:
    parts = text.replace(",", " ").split()
    values = []
    for part in parts:  # text first: "abc" is not a number, whatever the count
        try:
            values.append(float(part))
        except ValueError:
            raise InvalidInputError(field, f"'{part}' is not a number") from None
    if len(parts) != count:
        expected = "one number" if count == 1 else f"{count} numbers like '{' '.join('xyz'[:count])}'"
        raise InvalidInputError(field, f"expected {expected}, got {len(parts)}")
    return [finite_number(v, field) for v in values]


def _vector(
    dims: int, field: str, high: float = limits.MAX_COORDINATE, unit: str = "m"
) -> Callable[[str, Answers], list[float]]:
    """A vector of ``dims`` numbers, each at most ``high`` in size (the range that can be simulated)."""

    def parse(text: str, answers: Answers) -> list[float]:
        values = _numbers(text, dims, field)
        limits.check_vector(Vector3D(*values), field, high, unit)
        return values

    return parse


def _direction(dims: int) -> Callable[[str, Answers], list[float]]:
    def parse(text: str, answers: Answers) -> list[float]:
        values = _numbers(text, dims, "direction")
        Vector3D(*values).normalized("direction")
        return values

    return parse


def _size(dims: int) -> Callable[[str, Answers], list[float]]:
    def parse(text: str, answers: Answers) -> list[float]:
        sizes = [positive(v, "size") for v in _numbers(text, dims, "size")]
        return [limits.within(v, "size", limits.MIN_SIZE, limits.MAX_SIZE, "m") for v in sizes]

    return parse


def _positive(field: str, low: float, high: float, unit: str) -> Callable[[str, Answers], float]:
    return lambda text, answers: limits.within(positive(_numbers(text, 1, field)[0], field), field, low, high, unit)


def _restitution(text: str, answers: Answers) -> float:
    return limits.restitution(_numbers(text, 1, "restitution")[0], "restitution")


def _dt(text: str, answers: Answers) -> float:
    return limits.dt(_numbers(text, 1, "dt")[0], "dt")


def _steps(bodies: int) -> Callable[[str, Answers], int]:
    """A number of steps; with ``bodies`` moving bodies, at most ``MAX_BODY_STEPS / bodies``."""

    def parse(text: str, answers: Answers) -> int:
        steps = limits.steps(_numbers(text, 1, "steps")[0], "steps")
        return int(limits.within(steps, "steps", 0, limits.MAX_BODY_STEPS // bodies))

    return parse


def _mode(text: str, answers: Answers) -> str:
    choice = text.strip().lower()
    if choice not in ("euler", "exact"):
        raise InvalidInputError("mode", "expected 'euler' (the lab's Forward Euler) or 'exact' (time of impact)")
    return choice


def _third_point(text: str, answers: Answers) -> list[float]:
    point = _vector(3, "point 3")(text, answers)
    try:
        Plane.from_points(answers["p1"], answers["p2"], point)
    except InvalidInputError:
        raise InvalidInputError("point 3", "the three points are collinear or coincident: they span no plane") from None
    return point


def _suggest_third_point(answers: Answers) -> str:
    """A third point off the line through the first two: the first point moved one unit along
    the first axis that does it (so Enter always gives a plane)."""
    first = answers["p1"]
    for axis in range(3):
        candidate = [c + (1.0 if i == axis else 0.0) for i, c in enumerate(first)]
        try:
            Plane.from_points(first, answers["p2"], candidate)
        except InvalidInputError:
            continue
        return " ".join(f"{c:g}" for c in candidate)
    return "1 0 0"  # not reached: two distinct points leave two axes off their line


def _body(label: str, key: str, dims: int, kind: str, position: str, extent: str, velocity: str) -> list[Question]:
    form = "x y z, three numbers" if dims == 3 else "x y, two numbers"
    where = f"the centre of {label}" if kind == "aabb" else label
    questions = [Question(f"{key}.position", f"initial position of {where}", form, position, _vector(dims, "position"))]
    if kind == "aabb":
        size_form = "edge lengths along x y z, three numbers > 0" if dims == 3 else "edge lengths along x y, > 0"
        questions.append(Question(f"{key}.size", f"extent of {label}", size_form, extent, _size(dims)))
    else:
        radius = _positive("radius", limits.MIN_SIZE, limits.MAX_SIZE, "m")
        questions.append(Question(f"{key}.radius", f"radius of {label}", "a number > 0", extent, radius))
    speed = _vector(dims, "velocity", limits.MAX_SPEED, "m/s")
    questions.append(Question(f"{key}.velocity", f"initial velocity of {label}", form, velocity, speed))
    return questions


def _mass(label: str, key: str, default: str) -> Question:
    mass = _positive("mass", limits.MIN_MASS, limits.MAX_MASS, "kg")
    return Question(f"{key}.mass", f"mass of {label}", "kg, a number > 0", default, mass)


def _common(e: str, dt: str, steps: str, bodies: int = 1) -> list[Question]:
    return [
        Question("restitution", "coefficient of restitution e", "a number >= 0; 1 elastic, 0 sticks", e, _restitution),
        Question("dt", "time step dt", "seconds, > 0", dt, _dt),
        Question("steps", "number of steps", "a whole number >= 1", steps, _steps(bodies)),
        Question("mode", "stepping", "euler (the lab's) or exact (nothing tunnels)", "euler", _mode),
    ]


def _two_bodies(kind: str, shape: str, dims: int, defaults: tuple[str, ...]) -> list[Question]:
    pa, ea, va, pb, eb, vb = defaults
    return [
        *_body(f"{kind} A", "a", dims, shape, pa, ea, va),
        _mass(f"{kind} A", "a", "1"),
        *_body(f"{kind} B", "b", dims, shape, pb, eb, vb),
        _mass(f"{kind} B", "b", "1"),
    ]
