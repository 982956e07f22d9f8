"""What a simulation is made of: moving bodies, static obstacles, a box and settings.

A :class:`Scenario` is plain, validated data; :class:`~collisionlab.world.World` steps it.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from .body import Body, BodyShape, planar
from .body_block import Bodies, BodyBlock, BodyColumns
from .box import BOUNDARIES, Box
from .errors import InvalidInputError, UnsupportedPairError
from .limits import check_scenario
from .narrowphase import separation
from .shapes import AABB, Circle, Line, Plane, Sphere
from .validate import non_negative, positive, printable, whole_number
from .vector import Vector3D, as_vector

__all__ = [
    "BOUNDARIES",
    "BallSpecies",
    "Bodies",
    "Body",
    "BodyBlock",
    "BodyShape",
    "Box",
    "Mode",
    "Obstacle",
    "ObstacleShape",
    "Scenario",
    "Settings",
]

ObstacleShape = Line | Plane | AABB
Mode = Literal["euler", "exact"]
MODES: tuple[Mode, ...] = ("euler", "exact")
Contacts = Literal["events", "solve"]
#: How exact mode treats contacts: ``"events"``, every touch an impact at its time of impact
#: (:mod:`collisionlab.engine.exact_kernels`); ``"solve"``, impacts as events and slow or resting
#: contacts solved together at mid-step, bodies at rest asleep (:mod:`collisionlab.engine.contact_kernels`).
CONTACTS: tuple[Contacts, ...] = ("events", "solve")


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
    ``"exact"`` (time of impact: nothing tunnels). ``tc`` (s) is the TC model's time of the
    event-driven stepper (balls in a box, see :attr:`Scenario.event_driven`): a collision of a
    body that collided less than ``tc`` ago is elastic; ``None`` gives ``DEFAULT_TC_STEPS * dt``
    when some collision is inelastic or under gravity (inelastic collapse), else 0. ``contacts``
    (exact mode): ``"events"`` or ``"solve"`` (:data:`CONTACTS`; piles, pours and stacks want
    ``"solve"``)."""

    dt: float = 0.01
    steps: int = 100
    restitution: float = 1.0
    gravity: Vector3D = field(default_factory=lambda: Vector3D(0.0, 0.0, 0.0))
    mode: Mode = "euler"
    tc: float | None = None
    contacts: Contacts = "events"

    def __post_init__(self) -> None:
        object.__setattr__(self, "dt", positive(self.dt, "dt"))
        object.__setattr__(self, "steps", whole_number(self.steps, "steps", minimum=1))
        object.__setattr__(self, "restitution", non_negative(self.restitution, "restitution"))
        object.__setattr__(self, "gravity", as_vector(self.gravity, "gravity"))
        if self.mode not in MODES:
            raise InvalidInputError("mode", "must be 'euler' or 'exact'", got=self.mode)
        if self.tc is not None:
            object.__setattr__(self, "tc", non_negative(self.tc, "tc"))
        if self.contacts not in CONTACTS:
            raise InvalidInputError("contacts", "must be 'events' or 'solve'", got=self.contacts)


@dataclass(frozen=True)
class BallSpecies:
    """One kind of ball of an event-driven scenario (:meth:`Scenario.ball_species`): its
    ``name`` (the ``[[gas]]`` table's), ``radius``, ``mass`` and ``count`` of balls."""

    name: str
    radius: float
    mass: float
    count: int


@dataclass(frozen=True, init=False)
class Scenario:
    """A whole simulation: settings, moving bodies and static obstacles, with a title, and
    optionally a box (walls or periodic) around it all.

    ``bodies`` are :class:`Body` objects and :class:`~collisionlab.body_block.BodyBlock` s (many
    bodies as arrays, a ``[[gas]]`` table), kept as one
    :class:`~collisionlab.body_block.Bodies` sequence. Validated as a whole: names are unique,
    every pair that can meet has a collision query, circles (which live in the x-y plane) get no
    gravity along z, and every body starts inside the box.
    """

    settings: Settings
    bodies: Bodies
    obstacles: tuple[Obstacle, ...] = ()
    title: str = "scenario"
    #: Whether bodies may start overlapping (the first step then pushes them apart, with a
    #: warning); otherwise such a scenario is refused when its world is built.
    allow_initial_overlap: bool = False
    box: Box | None = None

    def __init__(
        self,
        settings: Settings,
        bodies: Iterable[Body | BodyBlock],
        obstacles: Iterable[Obstacle] = (),
        title: str = "scenario",
        allow_initial_overlap: bool = False,
        box: Box | None = None,
    ) -> None:
        object.__setattr__(self, "settings", settings)
        object.__setattr__(self, "bodies", bodies if isinstance(bodies, Bodies) else Bodies(bodies))
        object.__setattr__(self, "obstacles", tuple(obstacles))
        object.__setattr__(self, "title", title)
        object.__setattr__(self, "allow_initial_overlap", allow_initial_overlap)
        object.__setattr__(self, "box", box)
        self._validate()

    def _validate(self) -> None:
        bodies = self.bodies
        if not len(bodies):
            raise InvalidInputError("body", "a scenario needs at least one moving body")
        printable(self.title, "simulation.title")
        self._check_names()
        reps = bodies.representatives()
        flat = [b for b in reps if isinstance(b.shape, AABB) and b.shape.dim == 2]
        if flat and any(isinstance(b.shape, Sphere) or (isinstance(b.shape, AABB) and b.shape.dim == 3) for b in reps):
            raise InvalidInputError(  # a sphere or a 3D box would push it along z, out of its plane
                flat[0].name, "a moving 2D box lives in the x-y plane: it cannot meet a sphere or a 3D box"
            )
        if flat:
            for index, obstacle in enumerate(self.obstacles):  # it would push a 2D box along z
                if isinstance(obstacle.shape, Plane) and obstacle.shape.normal.z != 0.0:
                    raise InvalidInputError(
                        f"static[{index}].normal",
                        "a plane meeting a 2D box must have its normal in the x-y plane (z = 0)",
                    )
        if self.settings.gravity.z != 0.0 and any(planar(b.shape) for b in reps):
            raise InvalidInputError(
                "gravity", "a scenario with circles or 2D boxes lives in the x-y plane: z must be 0"
            )
        for a, b in self._representative_pairs(reps):
            try:
                separation(a.shape, b.shape)
            except UnsupportedPairError as error:
                raise InvalidInputError(f"{b.name}", f"'{a.name}' and '{b.name}' cannot collide: {error}") from error
        columns = bodies.columns()  # the bodies as arrays, once for the checks below
        check_scenario(self, columns)  # every magnitude within the range that can be simulated
        if self.box is not None:
            self._check_box(self.box, columns)

    def _check_names(self) -> None:
        """Names are printable, not empty, and unique among bodies, obstacles and walls (a
        block's bodies are its name and a number: checked without listing them)."""
        singles = self.bodies.singles
        names = [b.name for b in singles] + [o.name for o in self.obstacles]
        fields = [f"body[{i}].name" for i in range(len(singles))]
        fields += [f"static[{i}].name" for i in range(len(self.obstacles))]
        if self.box is not None:
            names += [name for name, _, _ in self.box.walls()]
            fields += ["box"] * (2 * self.box.dims)
        seen: set[str] = set()
        for index, name in enumerate(names):
            printable(name, fields[index])
            if not name:
                raise InvalidInputError(fields[index], "must not be empty")
            if name in seen:
                raise InvalidInputError(fields[index], "must be unique among bodies, obstacles and walls", got=name)
            seen.add(name)
        blocks = self.bodies.blocks
        for i, block in enumerate(blocks):
            clash = next((name for name in names if block.names_clash(name)), None)
            for other in blocks[i + 1 :]:
                if clash is None and (_blocks_clash(block, other) or _blocks_clash(other, block)):
                    clash = f"{other.name}..."
            if clash is not None:
                raise InvalidInputError(
                    f"gas[{i}].name",
                    f"must be unique among bodies, obstacles and walls: the bodies of '{block.name}' are "
                    f"'{block.name}0' to '{block.name}{len(block) - 1}'",
                    got=clash,
                )

    def _check_box(self, box: Box, columns: BodyColumns) -> None:
        if box.dims != self.dims:
            raise InvalidInputError("box.region", f"must have {self.dims} numbers per corner, as the bodies")
        axes = slice(0, box.dims)
        low, high = np.array(box.low.as_tuple())[axes], np.array(box.high.as_tuple())[axes]
        if box.boundary == "walls":
            outside = np.any(columns.pos[:, axes] - columns.ext[:, axes] < low, axis=1) | np.any(
                columns.pos[:, axes] + columns.ext[:, axes] > high, axis=1
            )
            where = "inside its walls"
        else:
            outside = np.any(columns.pos[:, axes] < low, axis=1) | np.any(columns.pos[:, axes] >= high, axis=1)
            where = "inside the periodic box (low <= centre < high)"
        if np.any(outside):
            name = self.bodies[int(np.argmax(outside))].name
            raise InvalidInputError("box.region", f"every body must start {where}; '{name}' does not")
        if box.boundary == "periodic" and not self.event_driven:
            raise InvalidInputError(
                "box.boundary",
                'a periodic box needs mode = "exact" with balls (all circles or all spheres, of finite mass, '
                'no restitution of their own), no obstacles and contacts = "events" (the event-driven stepper)',
            )

    def _representative_pairs(self, reps: list[Body]) -> list[tuple[Body | Obstacle, Body]]:
        """One pair for each pair of kinds of shape that can meet (a kind: the shape's type and
        dimension), bodies in order then obstacle-body pairs: whether a pair has a query depends
        on the kinds only, so a 100,000-body scenario is checked with a handful of queries."""

        def kind(thing: Body | Obstacle) -> tuple[str, int]:
            shape = thing.shape
            return (type(shape).__name__, shape.dim if isinstance(shape, AABB) else 0)

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
        shapes = [b.shape for b in self.bodies.representatives()] + [o.shape for o in self.obstacles]
        flat = all(isinstance(s, (Circle, Line)) or (isinstance(s, AABB) and s.dim == 2) for s in shapes)
        return 2 if flat else 3

    @property
    def event_driven(self) -> bool:
        """Whether ``mode = "exact"`` runs on the event-driven stepper (:mod:`collisionlab.edmd`:
        neighbour lists, an event calendar, no time step inside a frame's span): when the scenario
        is hard balls in a box, that is a :class:`Box`, no other obstacles, balls all circles or
        all spheres, of finite masses, with no restitution of their own, and gravity none or along
        -y, unless its contacts are solved (``contacts = "solve"``: balls poured into a box rest in
        it). The balls may differ in radius and mass (a mixture, :meth:`ball_species`: several
        ``[[gas]]`` tables). Any other exact scenario runs on the general exact stepper."""
        if self.settings.mode != "exact" or self.settings.contacts == "solve" or self.box is None or self.obstacles:
            return False
        kinds, finite, own_e = set(), True, False
        for part in self.bodies.parts:
            if isinstance(part, BodyBlock):
                kinds.add(part.shape)
                finite = finite and math.isfinite(part.mass)
                own_e = own_e or part.restitution is not None
            else:
                for body in part:
                    shape = body.shape
                    kinds.add(
                        "circle" if isinstance(shape, Circle) else "sphere" if isinstance(shape, Sphere) else "aabb"
                    )
                    finite = finite and math.isfinite(body.mass)
                    own_e = own_e or body.restitution is not None
        g = self.settings.gravity
        return (
            len(kinds) == 1
            and kinds <= {"circle", "sphere"}
            and finite
            and not own_e
            and g.x == 0.0
            and g.z == 0.0
            and g.y <= 0.0
            and (g.y == 0.0 or self.box.boundary == "walls")
        )

    def ball_species(self) -> tuple[tuple[BallSpecies, ...], NDArray[np.int64]]:
        """The kinds of ball of an event-driven scenario (:attr:`event_driven`) and each body's
        kind (an index into them, the bodies in the order given): one kind per ``[[gas]]`` table
        (a :class:`~collisionlab.body_block.BodyBlock`, named as it is), then one per radius and
        mass among the balls given one by one (named after the first of them).

        >>> big = BodyBlock("big", "circle", (1, 1, 1), [[2, 2], [5, 2]], [[1, 0], [0, 1]])
        >>> small = Body("s", Circle((2, 6), 0.5), (0, 0), mass=0.25)
        >>> kinds, labels = Scenario(Settings(mode="exact"), [big, small], box=Box((0, 0), (10, 10))).ball_species()
        >>> [(k.name, k.radius, k.mass, k.count) for k in kinds], labels.tolist()
        ([('big', 1.0, 1.0, 2), ('s', 0.5, 0.25, 1)], [0, 0, 1])
        """
        kinds = [BallSpecies(b.name, b.half[0], b.mass, len(b)) for b in self.bodies.blocks]
        labels: list[NDArray[np.int64]] = []
        singles: dict[tuple[float, float], int] = {}
        block_index = 0
        for part in self.bodies.parts:
            if isinstance(part, BodyBlock):
                labels.append(np.full(len(part), block_index, np.int64))
                block_index += 1
                continue
            own = np.zeros(len(part), np.int64)
            for i, body in enumerate(part):
                radius = body.shape.radius if isinstance(body.shape, (Circle, Sphere)) else math.nan
                k = singles.setdefault((radius, body.mass), len(kinds))
                if k == len(kinds):
                    kinds.append(BallSpecies(body.name, radius, body.mass, 0))
                kinds[k] = replace(kinds[k], count=kinds[k].count + 1)
                own[i] = k
            labels.append(own)
        return tuple(kinds), np.concatenate(labels) if labels else np.zeros(0, np.int64)

    def with_settings(self, **changes: object) -> Scenario:
        """A copy with some settings replaced (``dt``, ``steps``, ``mode``...), re-validated."""
        return replace(self, settings=replace(self.settings, **changes))  # type: ignore[arg-type]

    def energy_warning(self) -> str | None:
        """A warning when some restitution exceeds 1 (each collision then adds kinetic energy)."""
        values = [self.settings.restitution]
        values += [b.restitution for b in self.bodies.singles if b.restitution is not None]
        values += [o.restitution for o in self.obstacles if o.restitution is not None]
        values += [block.restitution for block in self.bodies.blocks if block.restitution is not None]
        worst = max(values)
        if worst > 1.0:
            return f"restitution {worst:g} > 1: every collision adds kinetic energy (the postlab's question 4)"
        return None


def _blocks_clash(first: BodyBlock, second: BodyBlock) -> bool:
    """Whether a body of ``second`` has the name of a body of ``first``: its name is
    ``first.name`` then digits ``rest``, and ``rest`` followed by ``second``'s smallest numbers
    gives a number of ``first``'s.

    >>> a = BodyBlock("g", "circle", (1, 1, 1), [[0, 0]] * 20, [[0, 0]] * 20)
    >>> b = BodyBlock("g1", "circle", (1, 1, 1), [[0, 0]] * 3, [[0, 0]] * 3)
    >>> _blocks_clash(a, b), _blocks_clash(b, a)       # g1 + 0 = g10, a body of g
    (True, False)
    """
    if first.name == second.name:
        return True
    rest = second.name[len(first.name) :]
    if not second.name.startswith(first.name) or not (rest.isascii() and rest.isdigit()) or rest.startswith("0"):
        return False
    return int(rest + "0") < len(first)
