"""Built-in scenarios: the example files shipped inside the package (``examples/`` in the repo).

The lab's four cases come first, numbered as in the lab's part VI.A.
"""

from __future__ import annotations

import tomllib
from importlib import resources
from pathlib import Path

from .errors import InvalidInputError, did_you_mean
from .model import Scenario
from .scenario_file import parse_scenario

__all__ = [
    "LAB_DEMOS",
    "SWEEP_PREFIX",
    "builtin_scenario_path",
    "builtin_sweep_path",
    "copy_examples",
    "demo_names",
    "demo_text",
    "load_demo",
    "sweep_names",
]

#: The lab's four cases, in the lab's order: 1 AABB in 3D, 2 sphere and sphere,
#: 3 circle and line, 4 sphere and plane.
LAB_DEMOS: tuple[str, ...] = ("aabb3d", "spheres", "circle-line", "sphere-plane")
#: ``examples/sweep-*.toml`` are sweep files (``collisionlab sweep``), not scenarios: not demos.
SWEEP_PREFIX = "sweep-"


def _folder() -> resources.abc.Traversable:
    return resources.files("collisionlab") / "examples"


def demo_names() -> list[str]:
    """Every built-in scenario: the lab's four first, then the rest alphabetically."""
    others = sorted(
        entry.name.removesuffix(".toml")
        for entry in _folder().iterdir()
        if entry.name.endswith(".toml")
        and entry.name.removesuffix(".toml") not in LAB_DEMOS
        and not entry.name.startswith(SWEEP_PREFIX)
    )
    return [*LAB_DEMOS, *others]


def demo_text(name: str) -> str:
    """The TOML text of a built-in scenario."""
    if name not in demo_names():
        hint = did_you_mean(name, demo_names())
        raise InvalidInputError("demo", f"unknown demo; {hint}expected one of {', '.join(demo_names())}", got=name)
    return (_folder() / f"{name}.toml").read_text(encoding="utf-8")


def load_demo(name: str) -> Scenario:
    """A built-in scenario by name.

    >>> load_demo("sphere-plane").obstacles[0].shape.unit_normal
    Vector3D(x=0.0, y=1.0, z=0.0)
    """
    return parse_scenario(tomllib.loads(demo_text(name)), f"examples/{name}.toml")


def builtin_scenario_path(text: str) -> Path | None:
    """The shipped file of a built-in scenario named by ``text``: its name (``head-on``), its
    file name (``head-on.toml``) or its path in the repository (``examples/head-on.toml``);
    ``None`` when ``text`` names no built-in scenario. The caller prefers a real file.

    >>> builtin_scenario_path("examples/head-on.toml").name, builtin_scenario_path("nothing")
    ('head-on.toml', None)
    """
    return _shipped(text, demo_names())


def sweep_names() -> list[str]:
    """Every shipped sweep file (``examples/sweep-*.toml``), alphabetically."""
    return sorted(
        entry.name.removesuffix(".toml")
        for entry in _folder().iterdir()
        if entry.name.endswith(".toml") and entry.name.startswith(SWEEP_PREFIX)
    )


def builtin_sweep_path(text: str) -> Path | None:
    """The shipped sweep file named by ``text``, as :func:`builtin_scenario_path` finds a
    scenario.

    >>> builtin_sweep_path("sweep-dt").name, builtin_sweep_path("head-on")
    ('sweep-dt.toml', None)
    """
    return _shipped(text, sweep_names())


def _shipped(text: str, names: list[str]) -> Path | None:
    path = Path(text)
    if path.parent not in (Path(), Path("examples")) or path.suffix not in ("", ".toml"):
        return None
    name = path.name.removesuffix(".toml")
    if name not in names:
        return None
    return Path(str(_folder() / f"{name}.toml"))


def copy_examples(folder: str | Path) -> list[Path]:
    """Write every built-in scenario file into ``folder`` (created if missing), to read and
    edit; an existing file is never overwritten (``InvalidInputError`` naming it, nothing
    written). Each file is written whole or not at all. Returns the paths written."""
    from .atomic import write_text_atomically

    target = Path(folder)
    if target.exists() and not target.is_dir():
        raise InvalidInputError("--copy", "must be a folder", got=str(target))
    paths = [target / f"{name}.toml" for name in demo_names()]
    clashes = [str(p) for p in paths if p.exists()]
    if clashes:
        more = f" (and {len(clashes) - 1} more)" if len(clashes) > 1 else ""
        raise InvalidInputError("--copy", f"would overwrite {clashes[0]}{more}; choose an empty or new folder")
    target.mkdir(parents=True, exist_ok=True)
    for name, path in zip(demo_names(), paths, strict=True):
        write_text_atomically(path, lambda name=name: demo_text(name))  # type: ignore[misc]
    return paths
