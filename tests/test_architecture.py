"""The package's import graph (issue 30): no import circles, and a collision layer at the bottom.

Every module under ``src/collisionlab`` is read with ``ast``, never imported, and every import in
it counts: at module level, under ``if TYPE_CHECKING:`` and inside functions (a lazy import is
still a circle: the two files still need each other), relative and absolute, and
``importlib.import_module("collisionlab...")`` with a literal name. Importing
``collisionlab.a.b`` also runs ``collisionlab/a/__init__.py``, so it counts as importing the
subpackage ``collisionlab.a`` too; not the top package ``collisionlab``, whose ``__init__``
Python runs before any of its modules (what it reaches is checked below).

docs/architecture.md draws the layers these tests hold.
"""

from __future__ import annotations

import ast
from collections.abc import Iterable
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parent.parent / "src"
PACKAGE = "collisionlab"

#: Import circles that are known and not yet removed. Each entry is one circle: the set of modules
#: that import each other (a strongly connected component of the graph). None is left: the last,
#: engine.world -> engine.ahead -> edmd.observables -> engine.world (and trajectory), went when a
#: world came to load its own stepper's kernels (engine.world.load_stepper_kernels). Remove an
#: entry with its circle (the test fails on an entry that is no longer a circle).
ALLOWED_CIRCLES: frozenset[frozenset[str]] = frozenset()

#: The collision layer (issue 30): vectors, shapes, contacts, the pair queries, the contact law and
#: their scalar kernels, with the errors, tolerances and checks they use. It imports nothing from
#: the model, the limits, the engine's world, records, pictures, the CLI or sweeps. toi.py (time of
#: impact) joined it when the exact stepper's kernels stopped importing limits (MAX_RUN_SPEED is
#: with the tolerances) and a shape's row moved from engine/state.py (which reads a Scenario) to
#: engine/shape_rows.py.
COLLISION_LAYER = (
    "collisionlab.vector",
    "collisionlab.shapes",
    "collisionlab.contact",
    "collisionlab.narrowphase",
    "collisionlab.resolution",
    "collisionlab.errors",
    "collisionlab.tolerances",
    "collisionlab.validate",
    "collisionlab.textformat",  # how Vector3D writes its numbers
    "collisionlab.sums",  # exactly rounded sums (the ledger's energies, any machine alike)
    "collisionlab.engine.geometry_kernels",  # the narrow phase as scalar kernels
    "collisionlab.engine.contact_law",  # the contact law as scalar kernels
    "collisionlab.toi",  # times of impact, through the exact stepper's kernels
    "collisionlab.toi_search",  # toi.py's search (the exact stepper's time of impact, scaled)
    "collisionlab.engine.shape_rows",  # a shape as a row of the kernels' arrays
    "collisionlab.engine.exact_kernels",  # the exact stepper's loop, and the files of its phases:
    "collisionlab.engine.exact_flight",
    "collisionlab.engine.pair_time_of_impact",
    "collisionlab.engine.exact_impulses",
    "collisionlab.engine.exact_rest",
    "collisionlab.engine.exact_sweeps",
    "collisionlab.engine.exact_settle",
    "collisionlab.engine.exact_impacts",
    "collisionlab.engine.exact_step_end",
    "collisionlab.engine.contact_kernels",  # the contact stepper's loop, and the files of its phases:
    "collisionlab.engine.contact_flight",
    "collisionlab.engine.contact_time_of_impact",
    "collisionlab.engine.contact_candidates",
    "collisionlab.engine.contact_impacts",
    "collisionlab.engine.contact_memory",
    "collisionlab.engine.contact_qp",
    "collisionlab.engine.contact_solver",
    "collisionlab.engine.contact_push_apart",
    "collisionlab.engine.contact_islands",
    "collisionlab.engine.step_kernels",  # the Forward Euler loop, and the files of its phases:
    "collisionlab.engine.non_literal",
    "collisionlab.engine.pair_separation",
    "collisionlab.engine.broad_phase_grid",
    "collisionlab.engine.broad_phase_pairs",
    "collisionlab.engine.contact_order",
    "collisionlab.engine.touching_memory",
    "collisionlab.engine.event_rows",
    "collisionlab.engine.euler_impulses",
    "collisionlab.engine.euler_push_apart",
    "collisionlab.engine.euler_clamps",
    "collisionlab.engine.euler_integrate",
    "collisionlab.engine.event_heap",
)

#: What the collision layer must not reach, directly or through another module (a package stands
#: for every module in it).
ABOVE_THE_COLLISION_LAYER = (
    "collisionlab.model",
    "collisionlab.limits",
    "collisionlab.record",
    "collisionlab.collision_events",
    "collisionlab.plotting",
    "collisionlab.engine.world",
    "collisionlab.cli",
    "collisionlab.sweep",
)

#: The top: the command line, sweeps and pictures. Nothing below imports them, but for these
#: edges, each the least bad way to keep a documented method (docs/architecture.md):
TOP = ("collisionlab.cli", "collisionlab.sweep", "collisionlab.plotting", "collisionlab.__main__")
ALLOWED_UPWARD = {
    # RunRecord.plot (and Jupyter's picture of a record) draws the record: one function-level
    # import, so matplotlib loads only when a record is drawn. Not a circle: the pictures read a
    # run through their own protocol (plotting/_run.py), never record.py.
    ("collisionlab.record", "collisionlab.plotting.static"),
}


def _modules() -> dict[str, tuple[Path, bool]]:
    """Every module of the package by dotted name: its file, and whether it is a package."""
    found = {}
    for path in sorted((SRC / PACKAGE).rglob("*.py")):
        parts = list(path.relative_to(SRC).with_suffix("").parts)
        package = parts[-1] == "__init__"
        if package:
            parts.pop()
        found[".".join(parts)] = (path, package)
    return found


MODULES = _modules()


def _known(name: str) -> str:
    """The module ``name`` lives in: itself, or its closest enclosing module (``a.b.C`` -> ``a.b``)."""
    while name not in MODULES:
        name = name.rpartition(".")[0]
    return name


def _targets(module: str, path: Path, package: bool) -> set[str]:
    """The package's modules that ``module`` imports by name, anywhere in the file."""
    here = module if package else module.rpartition(".")[0]
    targets: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            targets |= {_known(a.name) for a in node.names if a.name.split(".")[0] == PACKAGE}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = here.split(".")[: len(here.split(".")) - (node.level - 1)]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module or ""
            if source.split(".")[0] != PACKAGE:
                continue
            # `from a import b` imports the module a.b when there is one, else a name of a.
            targets |= {_known(f"{source}.{a.name}") for a in node.names}
        elif isinstance(node, ast.Call) and node.args and isinstance(node.args[0], ast.Constant):
            name = getattr(node.func, "attr", getattr(node.func, "id", ""))
            first = node.args[0].value
            if name in ("import_module", "__import__") and isinstance(first, str) and first.startswith(PACKAGE):
                targets.add(_known(first))
    targets.discard(module)
    return targets


def _with_packages(module: str, targets: Iterable[str]) -> set[str]:
    """``targets`` and the subpackages Python runs on the way to each (not the top package, nor a
    package holding ``module`` itself: those have started before ``module`` runs)."""
    out = set(targets)
    for target in targets:
        parts = target.split(".")
        for k in range(2, len(parts)):
            enclosing = ".".join(parts[:k])
            if enclosing in MODULES and not module.startswith(enclosing + "."):
                out.add(enclosing)
    out.discard(module)
    return out


DIRECT = {m: _targets(m, path, package) for m, (path, package) in MODULES.items()}
GRAPH = {m: _with_packages(m, targets) for m, targets in DIRECT.items()}


def circles(graph: dict[str, set[str]]) -> set[frozenset[str]]:
    """The graph's circles: its strongly connected components of more than one module (Tarjan's
    algorithm, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: set[frozenset[str]] = set()
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = set()
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.add(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.add(frozenset(component))
    return found


def _describe(circle: frozenset[str]) -> str:
    edges = [f"{a} -> {b}" for a in sorted(circle) for b in sorted(GRAPH[a] & circle)]
    return "{" + ", ".join(sorted(circle)) + "}: " + "; ".join(edges)


def _path(start: str, goal: Iterable[str]) -> list[str] | None:
    """The shortest chain of imports from ``start`` to a module in ``goal``, or None."""
    goal = set(goal)
    came: dict[str, str] = {start: start}
    queue = [start]
    for node in queue:
        if node in goal:
            chain = [node]
            while chain[-1] != start:
                chain.append(came[chain[-1]])
            return chain[::-1]
        for child in sorted(GRAPH[node]):
            if child not in came:
                came[child] = node
                queue.append(child)
    return None


def _inside(module: str, packages: Iterable[str]) -> bool:
    return any(module == p or module.startswith(p + ".") for p in packages)


def test_the_graph_is_read_from_the_source() -> None:
    # Guards the reader itself: a relative import, a function-level one and a subpackage's
    # __init__ are all seen (so a circle hidden in any of them cannot pass unnoticed).
    assert "collisionlab.vector" in DIRECT["collisionlab.shapes"]  # from .vector import ...
    assert "collisionlab.plotting.static" in DIRECT["collisionlab.record"]  # inside RunRecord.plot
    assert "collisionlab.plotting" in GRAPH["collisionlab.record"]  # plotting/__init__ runs first
    assert "collisionlab.engine.geometry_kernels" in DIRECT["collisionlab.narrowphase"]  # from .engine import gk
    assert circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == {frozenset("abc")}


def test_there_are_no_import_circles() -> None:
    found = circles(GRAPH)
    new = found - ALLOWED_CIRCLES
    assert not new, "import circles: " + " | ".join(_describe(c) for c in sorted(new, key=sorted))
    gone = ALLOWED_CIRCLES - found
    assert not gone, "no longer a circle, remove it from ALLOWED_CIRCLES: " + str([sorted(c) for c in gone])


@pytest.mark.parametrize("module", COLLISION_LAYER)
def test_the_collision_layer_imports_nothing_above_it(module: str) -> None:
    above = [m for m in MODULES if _inside(m, ABOVE_THE_COLLISION_LAYER)]
    chain = _path(module, above)
    assert chain is None, " -> ".join(chain)


def test_the_top_package_reaches_no_world_record_or_pictures() -> None:
    # `import collisionlab` (the scalar API) is what every submodule's import runs first.
    above = [m for m in MODULES if _inside(m, ("collisionlab.engine.world", *TOP[:3], "collisionlab.record"))]
    chain = _path(PACKAGE, above)
    assert chain is None, " -> ".join(chain)


def test_only_the_top_imports_the_command_line_sweeps_and_pictures() -> None:
    upward = {
        (a, b)
        for a, targets in DIRECT.items()
        if not _inside(a, TOP)
        for b in targets
        if _inside(b, TOP) and (a, b) not in ALLOWED_UPWARD
    }
    assert not upward, sorted(upward)
    for edge in ALLOWED_UPWARD:
        assert edge[1] in DIRECT[edge[0]], f"{edge} is gone: remove it from ALLOWED_UPWARD"
