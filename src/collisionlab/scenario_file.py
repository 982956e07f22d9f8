"""Scenario files (TOML): read into a :class:`~collisionlab.model.Scenario` (and written back by
:mod:`.scenario_writer`, whose :func:`scenario_to_toml` is re-exported here).

Every problem is a :class:`ScenarioError` naming the file, the field (``body[0].radius``) and
the expected form. Unknown keys are errors, never silently ignored. The format is documented
in the README ("Scenario files").
"""

from __future__ import annotations

import functools
import re
import tomllib
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, TypeVar

from .engine.overlap import InitialOverlapError, refuse_overlaps
from .errors import CollisionLabError, InvalidInputError, did_you_mean, escape_controls
from .gas_spec import GasSpec
from .gas_table import gas_count, place_gas
from .limits import MAX_SCENARIO_BYTES
from .model import Body, BodyBlock, Box, Obstacle, Scenario, Settings
from .scenario_writer import scenario_to_toml
from .shapes import AABB, Circle, Line, Plane, Sphere
from .validate import non_negative, positive, positive_or_inf, whole_number
from .vector import Vector3D, as_vector

__all__ = ["SCENARIO_FIELDS", "ScenarioError", "load_scenario", "parse_scenario", "read_toml", "scenario_to_toml"]

T = TypeVar("T")

_SIMULATION_KEYS = {"dt", "steps", "restitution", "gravity", "mode", "title", "allow_initial_overlap", "tc", "contacts"}
_BOX_KEYS = {"region", "boundary"}
_BODY_KEYS = {"name", "shape", "position", "radius", "size", "velocity", "mass", "restitution"}
_STATIC_KEYS = {"name", "shape", "point", "normal", "points", "direction", "position", "size", "restitution"}
_GAS_KEYS = {
    "name",
    "shape",
    "radius",
    "size",
    "region",
    "count",
    "fraction",
    "mass",
    "kT",
    "velocity",
    "restitution",
    "seed",
}
_BODY_SHAPES = ("circle", "sphere", "aabb")
_STATIC_SHAPES = ("line", "plane", "aabb")
#: The keys each table of a scenario file accepts (``simulation``, each ``body``, each ``static``).
SCENARIO_FIELDS: Mapping[str, frozenset[str]] = {
    "simulation": frozenset(_SIMULATION_KEYS),
    "body": frozenset(_BODY_KEYS),
    "static": frozenset(_STATIC_KEYS),
    "gas": frozenset(_GAS_KEYS),
    "box": frozenset(_BOX_KEYS),
}


class ScenarioError(InvalidInputError):
    """A scenario that cannot be used; ``source`` is the file (or ``<menu>``)."""

    def __init__(self, source: str, field: str, problem: str, got: object = None) -> None:
        super().__init__(field, problem, got)
        self.source = source
        self.args = (f"{escape_controls(source)}: {self.args[0]}",)


def _check(source: str, call: Callable[[], T], field: str, names: Mapping[str, str] | None = None) -> T:
    """Run a constructor or check, re-raising its error under the file and the file's field name:
    ``names`` maps the library's field names (``center``) to the file's (``body[0].position``);
    any other field is reported as ``field``."""
    try:
        return call()
    except InvalidInputError as error:
        if isinstance(error, ScenarioError):
            raise
        root = re.split(r"[.\[]", error.field, maxsplit=1)[0]
        target = names[root] + error.field[len(root) :] if names and root in names else field
        raise ScenarioError(source, target, error.problem, error.got) from None


def _table(source: str, data: object, field: str, allowed: set[str]) -> Mapping[str, Any]:
    if not isinstance(data, Mapping):
        raise ScenarioError(source, field, "must be a table")
    for key in data:
        if key not in allowed:
            hint = did_you_mean(str(key), allowed)
            raise ScenarioError(
                source, f"{field}.{key}", f"unknown key; {hint}expected one of {', '.join(sorted(allowed))}"
            )
    return data


def _get(source: str, data: Mapping[str, Any], field: str, key: str, default: object = ...) -> Any:
    if key in data:
        return data[key]
    if default is ...:
        raise ScenarioError(source, f"{field}.{key}", "is missing")
    return default


def _name(source: str, data: Mapping[str, Any], field: str, fallback: str) -> str:
    name = _get(source, data, field, "name", fallback)
    if not isinstance(name, str) or not name.strip():
        raise ScenarioError(source, f"{field}.name", "must be a non-empty string", got=name)
    return name.strip()


def _vector(source: str, data: Mapping[str, Any], field: str, key: str, dims: int | None = None) -> Vector3D:
    """The vector at ``key``; with ``dims``, it must have exactly that many components."""
    where = f"{field}.{key}"
    value = _get(source, data, field, key)
    vector = _check(source, lambda: as_vector(value, where), where)
    _count(source, value, where, dims)
    return vector


def _count(source: str, value: object, where: str, dims: int | None) -> None:
    """A 3D shape takes ``[x, y, z]``: two numbers are refused, never padded with z = 0. (A 2D
    shape takes ``[x, y]``, or ``[x, y, 0]``: its own check refuses z != 0.)"""
    if dims is not None and isinstance(value, list) and len(value) < dims:
        form = "[x, y]" if dims == 2 else "[x, y, z]"
        raise ScenarioError(source, where, f"must have {dims} numbers, {form}, for this shape", got=value)


def _box_dims(data: Mapping[str, Any]) -> int | None:
    """A box is 2D or 3D as its size says (2 or 3 numbers); its other vectors must agree."""
    size = data.get("size")
    return len(size) if isinstance(size, list) and len(size) in (2, 3) else None


def _number(source: str, data: Mapping[str, Any], field: str, key: str, check: Callable[[object, str], float]) -> float:
    where = f"{field}.{key}"
    return _check(source, lambda: check(_get(source, data, field, key), where), where)


def _optional(source: str, data: Mapping[str, Any], field: str, key: str) -> float | None:
    return None if key not in data else _number(source, data, field, key, non_negative)


def _shape_kind(source: str, data: Mapping[str, Any], field: str, kinds: tuple[str, ...]) -> str:
    kind = _get(source, data, field, "shape")
    if kind not in kinds:
        raise ScenarioError(source, f"{field}.shape", f"must be one of {' | '.join(kinds)}", got=kind)
    return str(kind)


def _box(source: str, data: Mapping[str, Any], field: str) -> AABB:
    center = _get(source, data, field, "position")
    size = _get(source, data, field, "size")
    _count(source, center, f"{field}.position", _box_dims(data))
    names = {"center": f"{field}.position", "size": f"{field}.size"}
    return _check(source, lambda: AABB.from_center_size(center, size), f"{field}.size", names)


def _body(source: str, data: object, index: int) -> Body:
    field = f"body[{index}]"
    table = _table(source, data, field, _BODY_KEYS)
    kind = _shape_kind(source, table, field, _BODY_SHAPES)
    name = _name(source, table, field, f"body{index + 1}")
    shape: Circle | Sphere | AABB
    dims = {"circle": 2, "sphere": 3}.get(kind) or _box_dims(table)
    if kind == "aabb":
        shape = _box(source, table, field)
    else:
        position = _vector(source, table, field, "position", dims)
        radius = _number(source, table, field, "radius", positive)
        maker = Circle if kind == "circle" else Sphere
        shape = _check(source, lambda: maker(position, radius), f"{field}.position")
    velocity = _vector(source, table, field, "velocity", dims) if "velocity" in table else Vector3D(0, 0, 0)
    mass = _number(source, table, field, "mass", positive_or_inf) if "mass" in table else 1.0
    restitution = _optional(source, table, field, "restitution")
    return _check(source, lambda: Body(name, shape, velocity, mass, restitution), f"{field}.velocity")


def _static(source: str, data: object, index: int) -> Obstacle:
    field = f"static[{index}]"
    table = _table(source, data, field, _STATIC_KEYS)
    kind = _shape_kind(source, table, field, _STATIC_SHAPES)
    name = _name(source, table, field, f"static{index + 1}")
    shape: Line | Plane | AABB
    if kind == "aabb":
        shape = _box(source, table, field)
    elif kind == "line":
        point = _vector(source, table, field, "point", 2)
        direction = _vector(source, table, field, "direction", 2)
        shape = _check(source, lambda: Line(point, direction), f"{field}.direction")
    elif "points" in table:
        points = table["points"]
        if not isinstance(points, list) or len(points) != 3:
            raise ScenarioError(source, f"{field}.points", "must be a list of three points [[x, y, z], ...]")
        where = f"{field}.points"
        corners = [_check(source, functools.partial(as_vector, p, where), where) for p in points]
        for p in points:
            _count(source, p, where, 3)
        shape = _check(source, lambda: Plane.from_points(*corners), f"{field}.points")
    else:
        point = _vector(source, table, field, "point", 3)
        normal = _vector(source, table, field, "normal", 3)
        shape = _check(source, lambda: Plane(point, normal), f"{field}.normal")
    restitution = _optional(source, table, field, "restitution")
    return Obstacle(name, shape, restitution)


def _gas(source: str, data: object, index: int) -> BodyBlock:
    """A ``[[gas]]`` table: many bodies placed without overlap (:mod:`collisionlab.gas_table`)."""
    field = f"gas[{index}]"
    table = _table(source, data, field, _GAS_KEYS)
    kind = _shape_kind(source, table, field, _BODY_SHAPES)
    name = _name(source, table, field, f"gas{index + 1}-")
    corners = _get(source, table, field, "region")
    if not isinstance(corners, list) or len(corners) != 2:
        raise ScenarioError(source, f"{field}.region", "must be two opposite corners [[x0, y0, z0], [x1, y1, z1]]")
    where = f"{field}.region"
    low, high = (_check(source, functools.partial(as_vector, c, where), where) for c in corners)
    dims = 2 if kind == "circle" or (low.z == 0.0 and high.z == 0.0 and kind == "aabb") else 3
    if any(h <= lo for lo, h in list(zip(low, high, strict=True))[:dims]):
        raise ScenarioError(source, where, "the second corner must be above the first on every axis")
    if kind == "aabb":
        size = _vector(source, table, field, "size")
        half = tuple(0.5 * c for c in size.as_tuple())
        if any(h <= 0.0 for h in half[:dims]):
            raise ScenarioError(source, f"{field}.size", "must be > 0 on every axis", got=size.as_tuple()[:dims])
    else:
        radius = _number(source, table, field, "radius", positive)
        half = (radius, radius, radius)
    if ("count" in table) == ("fraction" in table):
        raise ScenarioError(source, f"{field}.count", "give either count or fraction (of the region filled)")
    if "count" in table:
        count = _check(source, lambda: whole_number(table["count"], f"{field}.count"), f"{field}.count")
    else:
        fraction = _number(source, table, field, "fraction", positive)
        sizes = tuple(h - lo for lo, h in list(zip(low, high, strict=True))[:dims])
        count = max(1, gas_count(kind, half, sizes, fraction))  # type: ignore[arg-type]
    mass = _number(source, table, field, "mass", positive) if "mass" in table else 1.0
    if "kT" in table and "velocity" in table:
        raise ScenarioError(source, f"{field}.kT", "give either kT (Maxwell-Boltzmann velocities) or velocity")
    kt = _number(source, table, field, "kT", non_negative) if "kT" in table else None
    velocity = _vector(source, table, field, "velocity").as_tuple() if "velocity" in table else None
    if kt is None and velocity is None:
        kt = 1.0
    seed = _check(source, lambda: whole_number(table.get("seed", 0), f"{field}.seed", minimum=0), f"{field}.seed")
    spec = GasSpec(
        name,
        kind,
        half,  # type: ignore[arg-type]
        (low.as_tuple(), high.as_tuple()),
        count,
        mass,
        kt,
        velocity,
        _optional(source, table, field, "restitution"),
        seed,
    )
    return _check(source, lambda: place_gas(spec, field), field, {"gas": "gas"})


def _box_table(source: str, data: object) -> Box:
    """The ``[box]`` table: ``region`` (two opposite corners) and ``boundary``."""
    table = _table(source, data, "box", _BOX_KEYS)
    corners = _get(source, table, "box", "region")
    where = "box.region"
    if not isinstance(corners, list) or len(corners) != 2:
        raise ScenarioError(source, where, "must be two opposite corners [[x0, y0, z0], [x1, y1, z1]]")
    low, high = (_check(source, functools.partial(as_vector, c, where), where) for c in corners)
    boundary = table.get("boundary", "walls")
    return _check(source, lambda: Box(low, high, boundary), "box", {"box": "box"})


def parse_scenario(data: Mapping[str, Any], source: str = "<scenario>", title: str | None = None) -> Scenario:
    """A :class:`Scenario` from parsed TOML data (a dict as ``tomllib`` gives)."""
    _table(source, data, "scenario", {"simulation", "body", "static", "gas", "box"})
    sim = _table(source, data.get("simulation", {}), "simulation", _SIMULATION_KEYS)
    given = {key: value for key, value in sim.items() if key not in ("title", "allow_initial_overlap")}
    allow_overlap = sim.get("allow_initial_overlap", False)
    if not isinstance(allow_overlap, bool):
        raise ScenarioError(source, "simulation.allow_initial_overlap", "must be true or false", got=allow_overlap)
    names = {key: f"simulation.{key}" for key in _SIMULATION_KEYS}
    settings = _check(source, lambda: Settings(**given), "simulation", names)
    bodies_data = data.get("body", [])
    statics_data = data.get("static", [])
    gases_data = data.get("gas", [])
    for key, value in (("body", bodies_data), ("static", statics_data), ("gas", gases_data)):
        if not isinstance(value, list):
            raise ScenarioError(source, key, f"must be an array of tables, written [[{key}]]")
    bodies = [_body(source, b, i) for i, b in enumerate(bodies_data)]
    blocks = [_gas(source, table, index) for index, table in enumerate(gases_data)]
    statics = [_static(source, s, i) for i, s in enumerate(statics_data)]
    box = _box_table(source, data["box"]) if "box" in data else None
    fields = [f"body[{i}]" for i in range(len(bodies))] + [f"static[{i}]" for i in range(len(statics))]
    seen: set[str] = set()
    things: list[Body | Obstacle] = [*bodies, *statics]
    for thing, where in zip(things, fields, strict=True):
        if thing.name in seen:
            raise ScenarioError(source, f"{where}.name", "must be unique among bodies and obstacles", got=thing.name)
        seen.add(thing.name)
    name = sim.get("title", title or Path(source).stem)
    if not isinstance(name, str):
        raise ScenarioError(source, "simulation.title", "must be a string", got=name)
    # The scenario's own checks name a body (a pair that cannot collide), ``gravity``, a field
    # of the file (``gas[0].name``, ``box.region``) or ``body``.
    names = {b.name: f"body[{i}].shape" for i, b in enumerate(bodies)}
    for index, block in enumerate(blocks):
        names.update({body.name: f"gas[{index}].shape" for body in block[:2]})
    names.update({key: key for key in ("gravity", "body", "static", "simulation", "box", "gas")})
    names["gravity"] = "simulation.gravity"
    scenario = _check(
        source,
        lambda: Scenario(settings, (*bodies, *blocks), tuple(statics), name, allow_overlap, box),
        "scenario",
        names,
    )
    # Here rather than in the world: before any kernel is compiled, and under the file's name.
    _check(source, lambda: _refuse_overlaps(scenario, blocks), "body", {"gas": "gas"})
    return scenario


def _refuse_overlaps(scenario: Scenario, blocks: list[BodyBlock]) -> None:
    """:func:`refuse_overlaps`, saying so when the two bodies come from two ``[[gas]]`` tables:
    each table is placed on a lattice of its own, blind to the others, so two tables whose
    regions meet may put bodies on each other (the field is then the later table's region)."""
    try:
        refuse_overlaps(scenario)
    except InitialOverlapError as error:
        tables = [next((i for i, block in enumerate(blocks) if block.names_clash(name)), -1) for name in error.pair]
        first, second = sorted(tables)
        if first < 0 or first == second:
            raise
        a, b = error.pair
        raise InvalidInputError(
            f"gas[{second}].region",
            f"'{a}' and '{b}' overlap at the start: each [[gas]] table is placed on its own, blind to the others; "
            f"give gas[{first}] and gas[{second}] regions that do not meet",
        ) from None


def read_toml(path: str | Path, invalid: Callable[[str, str, str], InvalidInputError], kind: str) -> dict[str, Any]:
    """The data of the TOML file at ``path``, read as every input file of collisionlab is (a
    scenario, a sweep): at most ``MAX_SCENARIO_BYTES`` (never more is read: ``/dev/zero`` is
    endless), UTF-8, not nested too deeply. Bad data raises ``invalid(source, "file", problem)``;
    a missing or unreadable file, the ``OSError`` (the caller says what it was reading)."""
    source = str(path)
    with open(path, "rb") as file:
        raw = file.read(MAX_SCENARIO_BYTES + 1)
    if len(raw) > MAX_SCENARIO_BYTES:
        raise invalid(source, "file", f"is larger than {MAX_SCENARIO_BYTES:,} bytes; a {kind} file is small")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as error:
        byte = raw[error.start]
        raise invalid(source, "file", f"is not UTF-8 text (byte 0x{byte:02x} at offset {error.start})") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise invalid(source, "file", f"is not valid TOML: {error}") from None
    except RecursionError:
        raise invalid(source, "file", "is nested too deeply (arrays or tables within each other)") from None


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a scenario file (at most ``MAX_SCENARIO_BYTES``; UTF-8 TOML)."""
    source = str(path)
    try:
        data = read_toml(path, ScenarioError, "scenario")
    except OSError as error:
        # Not bad data but a missing or unreadable file: an "other failure" (exit status 1).
        raise CollisionLabError(f"{escape_controls(source)}: cannot be read: {error.strerror or error}") from None
    return parse_scenario(data, source)
