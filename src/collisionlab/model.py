"""What a simulation is made of: moving bodies, static obstacles and settings.

A :class:`Scenario` is plain, validated data; :class:`~collisionlab.world.World` steps it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Literal

from .errors import InvalidInputError, UnsupportedPairError
from .limits import check_scenario
from .narrowphase import separation
from .shapes import AABB, Circle, Line, Plane, Sphere
from .validate import non_negative, positive, positive_or_inf, printable, whole_number
from .vector import Vector3D, as_vector, as_vector_3d

__all__ = ["Body", "BodyShape", "Mode", "Obstacle", "ObstacleShape", "Scenario", "Settings"]

BodyShape = Circle | Sphere | AABB
ObstacleShape = Line | Plane | AABB
Mode = Literal["euler", "exact"]
MODES: tuple[Mode, ...] = ("euler", "exact")


def _planar(shape: object) -> bool:
    """A circle or a 2D box: it lives in the x-y plane and must not move out of it."""
    return isinstance(shape, Circle) or (isinstance(shape, AABB) and shape.dim == 2)


@dataclass(frozen=True)
class Body:
    """A moving body: a shape placed at its starting position, a velocity and a mass.
    ``math.inf`` is a kinematic body: it moves at its own velocity, pushes others and is never
    pushed (gravity does not act on it).

    ``restitution`` overrides the scenario's default for collisions of this body. ``velocity``
    has as many numbers as the shape's vectors: three for a sphere or a 3D box (``(0, -1)`` is
    refused, never padded), ``(x, y)`` or ``(x, y, 0)`` for a circle or a 2D box; a ``Vector3D``
    is taken as it is.
    """

    name: str
    shape: BodyShape
    velocity: Vector3D
    mass: float = 1.0
    restitution: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.shape, (Circle, Sphere, AABB)):
            raise InvalidInputError("shape", "a moving body must be a circle, a sphere or an AABB")
        if _planar(self.shape):  # (x, y) or (x, y, 0), as the shape's own vectors
            velocity = as_vector(self.velocity, "velocity")
        else:  # a sphere or a 3D box: (x, y, z), never padded
            owner = "a sphere" if isinstance(self.shape, Sphere) else "a 3D box"
            velocity = as_vector_3d(self.velocity, "velocity", owner)
        object.__setattr__(self, "velocity", velocity)
        object.__setattr__(self, "mass", positive_or_inf(self.mass, "mass"))
        if self.restitution is not None:
            object.__setattr__(self, "restitution", non_negative(self.restitution, "restitution"))
        if _planar(self.shape) and self.velocity.z != 0.0:  # else it would leave its plane
            raise InvalidInputError("velocity", "a circle or a 2D box moves in the x-y plane: z must be 0")

    @property
    def position(self) -> Vector3D:
        return self.shape.center


@dataclass(frozen=True)
class Obstacle:
    """A static boundary: a line, a plane or a fixed box (infinite mass)."""

    name: str
    shape: ObstacleShape
    restitution: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.shape, (Line, Plane, AABB)):
            raise InvalidInputError("shape", "a static obstacle must be a line, a plane or an AABB")
        if self.restitution is not None:
            object.__setattr__(self, "restitution", non_negative(self.restitution, "restitution"))


@dataclass(frozen=True)
class Settings:
    """Time step ``dt`` (s), number of ``steps``, default ``restitution`` e, constant ``gravity``
    (m/s^2) and the stepping ``mode``: ``"euler"`` (the lab's: Forward Euler, then detect) or
    ``"exact"`` (time of impact: nothing tunnels)."""

    dt: float = 0.01
    steps: int = 100
    restitution: float = 1.0
    gravity: Vector3D = field(default_factory=lambda: Vector3D(0.0, 0.0, 0.0))
    mode: Mode = "euler"

    def __post_init__(self) -> None:
        object.__setattr__(self, "dt", positive(self.dt, "dt"))
        object.__setattr__(self, "steps", whole_number(self.steps, "steps", minimum=1))
        object.__setattr__(self, "restitution", non_negative(self.restitution, "restitution"))
        object.__setattr__(self, "gravity", as_vector(self.gravity, "gravity"))
        if self.mode not in MODES:
            raise InvalidInputError("mode", "must be 'euler' or 'exact'", got=self.mode)


@dataclass(frozen=True)
class Scenario:
    """A whole simulation: settings, moving bodies and static obstacles, with a title.

    Validated as a whole: names are unique, every pair that can meet has a collision query,
    and circles (which live in the x-y plane) get no gravity along z.
    """

    settings: Settings
    bodies: tuple[Body, ...]
    obstacles: tuple[Obstacle, ...] = ()
    title: str = "scenario"
    #: Whether bodies may start overlapping (the first step then pushes them apart, with a
    #: warning); otherwise such a scenario is refused when its world is built.
    allow_initial_overlap: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "bodies", tuple(self.bodies))
        object.__setattr__(self, "obstacles", tuple(self.obstacles))
        if not self.bodies:
            raise InvalidInputError("body", "a scenario needs at least one moving body")
        names = [b.name for b in self.bodies] + [o.name for o in self.obstacles]
        fields = [f"body[{i}].name" for i in range(len(self.bodies))]
        fields += [f"static[{i}].name" for i in range(len(self.obstacles))]
        printable(self.title, "simulation.title")
        seen: set[str] = set()
        for index, name in enumerate(names):
            printable(name, fields[index])
            if not name:
                raise InvalidInputError("name", "must not be empty")
            if name in seen:
                raise InvalidInputError("name", "must be unique among bodies and obstacles", got=name)
            seen.add(name)
        flat = [i for i, b in enumerate(self.bodies) if isinstance(b.shape, AABB) and b.shape.dim == 2]
        if flat and any(
            isinstance(b.shape, Sphere) or (isinstance(b.shape, AABB) and b.shape.dim == 3) for b in self.bodies
        ):
            raise InvalidInputError(  # a sphere or a 3D box would push it along z, out of its plane
                f"body[{flat[0]}].shape", "a moving 2D box lives in the x-y plane: it cannot meet a sphere or a 3D box"
            )
        if flat:
            for index, obstacle in enumerate(self.obstacles):  # it would push a 2D box along z
                if isinstance(obstacle.shape, Plane) and obstacle.shape.normal.z != 0.0:
                    raise InvalidInputError(
                        f"static[{index}].normal",
                        "a plane meeting a 2D box must have its normal in the x-y plane (z = 0)",
                    )
        if self.settings.gravity.z != 0.0 and any(_planar(b.shape) for b in self.bodies):
            raise InvalidInputError(
                "gravity", "a scenario with circles or 2D boxes lives in the x-y plane: z must be 0"
            )
        for a, b in self._representative_pairs():
            try:
                separation(a.shape, b.shape)
            except UnsupportedPairError as error:
                raise InvalidInputError(f"{b.name}", f"'{a.name}' and '{b.name}' cannot collide: {error}") from error
        check_scenario(self)  # every magnitude within the range that can be simulated

    def _representative_pairs(self) -> list[tuple[Body | Obstacle, Body]]:
        """One pair for each pair of kinds of shape that can meet (a kind: the shape's type and
        dimension), in the order of :meth:`pairs`: whether a pair has a query depends on the
        kinds only, so a 100,000-body scenario is checked with a handful of queries."""

        def kind(thing: Body | Obstacle) -> tuple[str, int]:
            shape = thing.shape
            return (type(shape).__name__, shape.dim if isinstance(shape, AABB) else 0)

        firsts: dict[tuple[str, int], list[Body]] = {}
        for body in self.bodies:
            group = firsts.setdefault(kind(body), [])
            if len(group) < 2:  # two of a kind make the same-kind pair
                group.append(body)
        reps = [b for group in firsts.values() for b in group]
        order = {id(b): i for i, b in enumerate(self.bodies)}
        reps.sort(key=lambda b: order[id(b)])
        pairs: list[tuple[Body | Obstacle, Body]] = []
        for i, a in enumerate(reps):
            for b in reps[i + 1 :]:
                pairs.append((a, b))
        seen: set[tuple[str, int]] = set()
        for obstacle in self.obstacles:
            if kind(obstacle) not in seen:
                seen.add(kind(obstacle))
                pairs += [(obstacle, body) for body in reps]
        return pairs

    @property
    def dims(self) -> int:
        """2 when everything lives in the x-y plane (circles, lines, 2D boxes), else 3."""
        shapes = [b.shape for b in self.bodies] + [o.shape for o in self.obstacles]
        flat = all(isinstance(s, (Circle, Line)) or (isinstance(s, AABB) and s.dim == 2) for s in shapes)
        return 2 if flat else 3

    def pairs(self) -> list[tuple[Body | Obstacle, Body]]:
        """Every pair that may collide, in the world's fixed order: body-body pairs ``(i, j)``
        with ``i < j``, then obstacle-body pairs (obstacle first, so normals point at the body)."""
        pairs: list[tuple[Body | Obstacle, Body]] = []
        for i, a in enumerate(self.bodies):
            for b in self.bodies[i + 1 :]:
                pairs.append((a, b))
        for obstacle in self.obstacles:
            for body in self.bodies:
                pairs.append((obstacle, body))
        return pairs

    def with_settings(self, **changes: object) -> Scenario:
        """A copy with some settings replaced (``dt``, ``steps``, ``mode``...), re-validated."""
        return replace(self, settings=replace(self.settings, **changes))  # type: ignore[arg-type]

    def energy_warning(self) -> str | None:
        """A warning when some restitution exceeds 1 (each collision then adds kinetic energy)."""
        values = [self.settings.restitution]
        things: tuple[Body | Obstacle, ...] = (*self.bodies, *self.obstacles)
        values += [x.restitution for x in things if x.restitution is not None]
        worst = max(values)
        if worst > 1.0:
            return f"restitution {worst:g} > 1: every collision adds kinetic energy (the postlab's question 4)"
        return None


def mass_of(thing: Body | Obstacle) -> float:
    """Mass of a body; ``math.inf`` for a static obstacle."""
    return thing.mass if isinstance(thing, Body) else positive_or_inf(math.inf, "mass")
