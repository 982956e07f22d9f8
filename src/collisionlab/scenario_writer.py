"""A :class:`~collisionlab.model.Scenario` written as a scenario file (TOML) that
:func:`~collisionlab.scenario_file.load_scenario` reads back to an equal scenario: every number
as ``repr`` writes it (the shortest text that reads back to the same double), a box by the
shortest centre and size that rebuild its corners exactly, a ``[[gas]]`` table as the table that
placed its bodies (which places them again, the same)."""

from __future__ import annotations

import math

from .gas_spec import GasSpec
from .model import Body, BodyBlock, Scenario
from .shapes import AABB, Circle, Line
from .vector import Vector3D

__all__ = ["scenario_to_toml"]


def _fmt(value: float) -> str:
    if math.isinf(value):
        return "inf"
    return repr(float(value))


def _vec(vector: Vector3D, dim: int = 3) -> str:
    return "[" + ", ".join(_fmt(c) for c in vector.as_tuple()[:dim]) + "]"


def _shortest(value: float) -> list[float]:
    """``value`` written with 1, 2, ... 17 significant digits (the last is ``value`` itself)."""
    return [float(f"{value:.{digits}g}") for digits in range(1, 18)]


def _centre_and_size(box: AABB) -> tuple[Vector3D, Vector3D]:
    """A centre and size that rebuild exactly the box's corners (as :meth:`AABB.from_center_size`
    computes them): the shortest decimals that do, else the plain centre and size. The plain
    ``(min + max) / 2`` can be an ulp off the number the file gave (0.19999999999999998)."""
    centre, size = list(box.center.as_tuple()), list((box.max_corner - box.min_corner).as_tuple())
    for axis, (low, high) in enumerate(zip(box.min_corner.as_tuple(), box.max_corner.as_tuple(), strict=True)):
        found = next(
            (
                (c, s)
                for s in _shortest(size[axis])
                for c in _shortest(centre[axis])
                if c - s * 0.5 == low and c + s * 0.5 == high
            ),
            None,
        )
        if found is not None:
            centre[axis], size[axis] = found
    return Vector3D(*centre), Vector3D(*size)


def _str(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def scenario_to_toml(scenario: Scenario) -> str:
    """The scenario as a TOML file that :func:`load_scenario` reads back to an equal scenario."""
    s = scenario.settings
    lines = [
        "[simulation]",
        f"title = {_str(scenario.title)}",
        f"dt = {_fmt(s.dt)}",
        f"steps = {s.steps}",
        f"restitution = {_fmt(s.restitution)}",
        f"gravity = {_vec(s.gravity)}",
        f"mode = {_str(s.mode)}",
    ]
    if scenario.allow_initial_overlap:
        lines.append("allow_initial_overlap = true")
    if s.tc is not None:
        lines.append(f"tc = {_fmt(s.tc)}")
    if s.contacts != "events":
        lines.append(f"contacts = {_str(s.contacts)}")
    tables: list[str] = []
    for part in scenario.bodies.parts:
        if isinstance(part, BodyBlock) and part.spec is not None:
            tables += _gas_lines(part.spec)  # the table that placed it places it again, the same
        else:
            for body in part:
                lines += _body_lines(body)
    lines += tables
    for obstacle in scenario.obstacles:
        shape_o = obstacle.shape
        lines += ["", "[[static]]", f"name = {_str(obstacle.name)}"]
        if isinstance(shape_o, AABB):
            dim = shape_o.dim
            centre, size = _centre_and_size(shape_o)
            lines += ['shape = "aabb"', f"position = {_vec(centre, dim)}", f"size = {_vec(size, dim)}"]
        elif isinstance(shape_o, Line):
            lines += ['shape = "line"', f"point = {_vec(shape_o.point, 2)}"]
            lines.append(f"direction = {_vec(shape_o.direction, 2)}")
        else:
            lines += ['shape = "plane"', f"point = {_vec(shape_o.point)}", f"normal = {_vec(shape_o.normal)}"]
        if obstacle.restitution is not None:
            lines.append(f"restitution = {_fmt(obstacle.restitution)}")
    if scenario.box is not None:
        box = scenario.box
        lines += ["", "[box]", f"region = [{_vec(box.low, box.dims)}, {_vec(box.high, box.dims)}]"]
        lines.append(f"boundary = {_str(box.boundary)}")
    return "\n".join(lines) + "\n"


def _body_lines(body: Body) -> list[str]:
    shape = body.shape
    lines = ["", "[[body]]", f"name = {_str(body.name)}"]
    if isinstance(shape, AABB):
        dim = shape.dim
        centre, size = _centre_and_size(shape)
        lines += ['shape = "aabb"', f"position = {_vec(centre, dim)}", f"size = {_vec(size, dim)}"]
    else:
        kind = "circle" if isinstance(shape, Circle) else "sphere"
        dim = 2 if kind == "circle" else 3
        lines += [f'shape = "{kind}"', f"position = {_vec(shape.center, dim)}", f"radius = {_fmt(shape.radius)}"]
    lines += [f"velocity = {_vec(body.velocity, dim)}", f"mass = {_fmt(body.mass)}"]
    if body.restitution is not None:
        lines.append(f"restitution = {_fmt(body.restitution)}")
    return lines


def _gas_lines(spec: GasSpec) -> list[str]:
    dims = spec.dims
    low, high = (Vector3D(*corner) for corner in spec.region)
    lines = ["", "[[gas]]", f"name = {_str(spec.name)}", f"shape = {_str(spec.shape)}"]
    if spec.shape == "aabb":
        lines.append(f"size = {_vec(Vector3D(*(2.0 * h for h in spec.half)), dims)}")
    else:
        lines.append(f"radius = {_fmt(spec.half[0])}")
    lines += [f"region = [{_vec(low, dims)}, {_vec(high, dims)}]", f"count = {spec.count}", f"mass = {_fmt(spec.mass)}"]
    if spec.kT is not None:
        lines.append(f"kT = {_fmt(spec.kT)}")
    else:
        lines.append(f"velocity = {_vec(Vector3D(*(spec.velocity or (0.0, 0.0, 0.0))), dims)}")
    if spec.restitution is not None:
        lines.append(f"restitution = {_fmt(spec.restitution)}")
    lines.append(f"seed = {spec.seed}")
    return lines
