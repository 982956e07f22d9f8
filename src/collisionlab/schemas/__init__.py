"""JSON Schemas (draft 2020-12) shipped with collisionlab, for other programs that read its files.

* ``run.schema.json``: the output of ``collisionlab run/demo --format json``;
* ``gas.schema.json``: the output of ``collisionlab gas --format json`` (stepped or exact);
* ``scenario.schema.json``: a scenario file, as the data its TOML parses to.

>>> schema("run").get("title")
'collisionlab run output'
"""

from __future__ import annotations

import json
from importlib import resources
from typing import Any

from ..errors import InvalidInputError

__all__ = ["SCHEMAS", "schema"]

#: The names of the shipped schemas.
SCHEMAS: tuple[str, ...] = ("run", "gas", "scenario")


def schema(name: str) -> dict[str, Any]:
    """The JSON Schema ``name`` (one of :data:`SCHEMAS`) as a dict, ready for ``jsonschema``."""
    if name not in SCHEMAS:
        raise InvalidInputError("schema", f"must be one of {', '.join(SCHEMAS)}", got=name)
    text = (resources.files(__name__) / f"{name}.schema.json").read_text(encoding="utf-8")
    data: dict[str, Any] = json.loads(text)
    return data
