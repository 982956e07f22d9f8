"""Where a sweep's parameter points in its base's data: a dotted path (``body.ball.velocity.y``,
``gas.fraction``, ``gas.species.NAME.KEY``) checked against the base and turned into the keys
that lead to the field (:func:`target`), and a copy of the base with a point's values set there
(:func:`apply_point`). Also the sweep's :class:`SweepError` and :class:`Parameter`, which
:mod:`.spec` (the file's reading) re-exports.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from ..errors import InvalidInputError
from ..scenario_file import SCENARIO_FIELDS
from .points import EXACT_GAS_KEYS, GAS_DEFAULTS, SPECIES_KEYS

__all__ = ["Parameter", "SweepError", "Value", "apply_point", "target"]

#: A parameter's value as TOML gives it: a number, a string, a boolean, or a list (a vector).
Value = float | int | str | bool | list[Any]

_COMPONENTS = {"x": 0, "y": 1, "z": 2}


class SweepError(InvalidInputError):
    """A sweep file that cannot be used; the message starts with the file."""

    def __init__(self, source: str, field: str, problem: str, got: object = None) -> None:
        super().__init__(field, problem, got)
        self.source = source
        self.args = (f"{source}: {self.args[0]}",)


@dataclass(frozen=True)
class Parameter:
    """One varied field: its dotted ``path``, its values in order, and where it is in the base's
    data: the ``keys`` leading to it (a body by its index) and the vector ``component`` (or None)."""

    path: str
    values: tuple[Value, ...]
    keys: tuple[str | int, ...] = ()
    component: int | None = None


def _find_table(source: str, data: Mapping[str, Any], section: str, name: str, field: str) -> int:
    """The index of the body (or static) named ``name`` (or numbered ``name``) in the base."""
    tables = data.get(section, [])
    names = [t.get("name", f"{section}{i + 1}") if isinstance(t, Mapping) else None for i, t in enumerate(tables)]
    if name in names:
        return names.index(name)
    if name.isdigit() and int(name) < len(tables):
        return int(name)
    have = ", ".join(str(n) for n in names) or "none"
    raise SweepError(source, field, f"the base has no {section} named {name!r} (it has: {have})")


def target(
    source: str, kind: str, data: Mapping[str, Any], path: str, field: str
) -> tuple[tuple[str | int, ...], int | None]:
    """The keys leading to the field in the base's data, and the vector component (or None)."""
    parts = path.split(".")
    component = None
    if len(parts) > 2 and parts[-1] in _COMPONENTS:
        component = _COMPONENTS[parts.pop()]
    if kind == "gas":
        exact = data.get("mode") == "exact"
        if exact and parts[:2] == ["gas", "species"] and component is None:
            return species_target(source, data, parts, field)
        allowed_keys = [k for k in (EXACT_GAS_KEYS if exact else GAS_DEFAULTS) if k not in ("mode", "species")]
        if exact:
            allowed_keys.append("species.NAME.KEY")
        if parts[0] != "gas" or len(parts) != 2 or parts[1] not in allowed_keys or component is not None:
            which = 'the exact gas (mode = "exact")' if exact else "the gas"
            hint = " (the mode is set in [sweep.gas], not varied)" if path == "gas.mode" else ""
            raise SweepError(
                source, field, f"the base is {which}: expected gas.KEY, KEY one of {', '.join(allowed_keys)}{hint}"
            )
        return (parts[1],), None
    forms = "simulation.KEY, body.NAME.KEY, static.NAME.KEY or gas.NAME.KEY (with .x, .y or .z for one component)"
    keys: list[str | int]
    if parts[0] == "simulation" and len(parts) == 2:
        keys, allowed = list(parts), SCENARIO_FIELDS["simulation"] - {"title"}
    elif parts[0] in ("body", "static", "gas") and len(parts) == 3:
        keys = [parts[0], _find_table(source, data, parts[0], parts[1], field), parts[2]]
        allowed = SCENARIO_FIELDS[parts[0]] - {"name"}
    else:
        raise SweepError(source, field, f"the base is a scenario: expected {forms}")
    if parts[-1] not in allowed:
        raise SweepError(source, field, f"unknown field {parts[-1]!r}; expected one of {', '.join(sorted(allowed))}")
    if component is not None and not isinstance(_get(data, keys), list):
        raise SweepError(source, field, f"needs {'.'.join(parts)} given as a vector in the base to vary one component")
    return tuple(keys), component


def species_target(
    source: str, data: Mapping[str, Any], parts: list[str], field: str
) -> tuple[tuple[str | int, ...], None]:
    """The keys of ``gas.species.NAME.KEY`` in the exact gas's base: its species ``NAME``'s
    ``KEY`` (``fraction``, ``radius`` or ``mass``)."""
    varied = [key for key in SPECIES_KEYS if key != "name"]
    form = f"gas.species.NAME.KEY, KEY one of {', '.join(varied)}"
    if len(parts) != 4 or parts[3] not in varied:
        raise SweepError(source, field, f"expected {form}")
    species = data.get("species") or []
    names = [table.get("name") for table in species if isinstance(table, Mapping)]
    if parts[2] not in names:
        have = ", ".join(str(n) for n in names) or "none: add [[sweep.gas.species]] tables"
        raise SweepError(source, field, f"the base has no species named {parts[2]!r} (it has: {have})")
    return ("species", names.index(parts[2]), parts[3]), None


def _get(data: Any, keys: Sequence[str | int]) -> Any:
    for key in keys:
        if isinstance(key, int):
            data = data[key] if isinstance(data, list) and key < len(data) else None
        else:
            data = data.get(key) if isinstance(data, Mapping) else None
    return data


def apply_point(
    base: Mapping[str, Any], parameters: Sequence[Parameter], values: Mapping[str, Value]
) -> dict[str, Any]:
    """A copy of the base's data with the point's values set where its parameters point.

    >>> fraction = Parameter("gas.fraction", (0.3,), ("fraction",))
    >>> apply_point({"n": 10, "fraction": 0.2}, [fraction], {"gas.fraction": 0.3})
    {'n': 10, 'fraction': 0.3}
    >>> speed = Parameter("body.ball.velocity.y", (-4,), ("body", 0, "velocity"), component=1)
    >>> apply_point({"body": [{"velocity": [1, -2, 0]}]}, [speed], {"body.ball.velocity.y": -4})
    {'body': [{'velocity': [1, -4, 0]}]}
    """
    data = copy.deepcopy(dict(base))
    for parameter in parameters:
        *leading, last = parameter.keys
        target: Any = data
        for key in leading:  # a base with no [simulation] table gets one
            target = target[key] if isinstance(key, int) else target.setdefault(key, {})
        value = copy.deepcopy(values[parameter.path])
        if parameter.component is not None:
            vector = list(target[last])
            vector[parameter.component] = value
            value = vector
        target[last] = value
    return data
