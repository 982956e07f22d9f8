"""Validate what collisionlab writes against the JSON Schemas it ships (collisionlab.schemas)."""

from __future__ import annotations

import functools
import tomllib
from typing import Any

import jsonschema

from collisionlab.schemas import schema


@functools.cache
def _validator(name: str) -> jsonschema.protocols.Validator:
    document = schema(name)
    cls = jsonschema.validators.validator_for(document)
    cls.check_schema(document)
    return cls(document)


def check(name: str, data: Any) -> Any:
    """``data`` unchanged if it follows schema ``name``; else ``jsonschema.ValidationError``."""
    _validator(name).validate(data)
    return data


def check_scenario_text(text: str) -> str:
    """A scenario file's TOML text, checked against the scenario schema."""
    check("scenario", tomllib.loads(text))
    return text
