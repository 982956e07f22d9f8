"""The fuzz harness: every input surface of collisionlab, and what each input may end in.

Five surfaces, each a hypothesis strategy and a probe that feeds one input and classifies what
came out:

* ``scenario-data``: parsed-TOML data (tables of any keys and values, and plausible scenarios
  whose numbers span the whole float range) through ``parse_scenario``, a short run and every
  output format;
* ``file-bytes``: raw bytes (example files mutated byte by byte, and random bytes) run as a file;
* ``command-line``: words of the command line's vocabulary (long values and paths among them),
  random text, and the exact gas's flags at and beyond their range;
* ``menu-answers``: a case and answers, good and bad, typed into the menu;
* ``public-api``: the library's functions and constructors with any values.

Outcome classes (the only ones allowed): ``ok`` (success with finite, valid output: strict JSON,
no ``inf``/``nan`` in any number) and ``error <status>`` (one documented error line with its
documented status: 1, 2 or 65 on the command line; one of the library's own exceptions with a
one-line message in the API). Anything else is a ``FAILURE`` and is printed with its input.

``tests/test_fuzz_*.py`` run these probes with hypothesis (seeded and bounded);
``python3 tasks.py fuzz`` (``python -m tests.fuzz_harness --inputs N``) runs them at N inputs in
all and prints the counts by outcome.
"""

from __future__ import annotations

import argparse
import concurrent.futures
import json
import math
import sys
import tempfile
import time
import warnings
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from collisionlab import (
    AABB,
    Circle,
    CollisionLabError,
    Line,
    Plane,
    Sphere,
    Vector3D,
    contact,
    distance,
    intersects,
    reflect_velocity,
    resolve_collision,
    separate,
    separation,
    time_of_impact,
)
from collisionlab.cli.render import render_csv, render_json, render_table
from collisionlab.errors import OutOfRangeError
from collisionlab.scenario_file import ScenarioError, parse_scenario
from collisionlab.world import InitialOverlapError, simulate
from tests.cli_helpers import EXAMPLES, HEAVY_EXAMPLES, Result, run_cli, typed

__all__ = ["FUZZ_SETTINGS", "SURFACES", "Outcome", "classify_api", "classify_cli", "main"]

#: Steps of a fuzzed run (enough to meet, bounded so that 100,000 inputs take minutes).
FUZZ_STEPS = 20


def FUZZ_SETTINGS(count: int) -> settings:
    """Seeded, bounded settings for the fuzz tests: ``count`` examples, derandomized (the same
    inputs on every run), no example database, no deadline."""
    return settings(
        max_examples=count,
        derandomize=True,
        database=None,
        deadline=None,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much, HealthCheck.data_too_large],
    )


@dataclass(frozen=True)
class Outcome:
    """``kind`` is ``ok``, ``error <status>`` or ``FAILURE``; ``detail`` says why (for failures)."""

    kind: str
    detail: str = ""

    @property
    def failed(self) -> bool:
        return self.kind == "FAILURE"


OK = Outcome("ok")


# --- numbers and values ------------------------------------------------------------------------
#: Floats over the whole range, with the edges of the documented range and the special values.
EDGES = [0.0, -0.0, 1.0, -1.0, 0.5, 1e-9, 1e-6, 1e9, -1e9, 1e12, 1e154, 1e200, 1e308, -1e308, 1.7e308,
         5e-324, -5e-324, 2.2e-308, math.inf, -math.inf, math.nan]  # fmt: skip
FLOATS = st.one_of(
    st.sampled_from(EDGES),
    st.floats(-10, 10),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(-3, 3).map(float),
)
NUMBERS = st.one_of(FLOATS, st.integers(-5, 5), st.integers(min_value=-(10**400), max_value=10**400))
LEAVES = st.one_of(
    st.none(),
    st.booleans(),
    NUMBERS,
    st.text(max_size=8),
    st.sampled_from(["circle", "sphere", "aabb", "line", "plane", "euler", "exact", "ba\x1bll", "a\nb", ""]),
)
VALUES = st.recursive(LEAVES, lambda inner: st.lists(inner, max_size=4), max_leaves=10)


def _vector(dims: tuple[int, ...] = (2, 3)) -> st.SearchStrategy[Any]:
    return st.one_of(
        st.sampled_from(dims).flatmap(lambda n: st.lists(NUMBERS, min_size=n, max_size=n)),
        st.lists(NUMBERS, max_size=5),
        VALUES,
    )


def _weighted(good: st.SearchStrategy[Any], bad: st.SearchStrategy[Any], odds: int) -> st.SearchStrategy[Any]:
    """``good`` about ``odds`` times out of ``odds + 1``, else ``bad`` (one_of would draw them
    evenly). The bad branch sits mid-range: hypothesis draws the ends of a range more often."""
    return st.integers(0, odds).flatmap(lambda k: bad if k == odds // 2 else good)


def _sometimes(strategy: st.SearchStrategy[Any]) -> st.SearchStrategy[Any]:
    """``strategy`` mostly, any value now and then (a wrong type where a number belongs)."""
    return _weighted(strategy, VALUES, 60)


SMALL = st.floats(-5, 5, allow_nan=False)
PLAUSIBLE_VECTOR = st.one_of(st.lists(SMALL, min_size=3, max_size=3), st.lists(SMALL, min_size=2, max_size=2))
#: Two or three numbers of any size (finite or not): the right shape, any magnitude.
EXTREME_VECTOR = st.integers(2, 3).flatmap(lambda n: st.lists(FLOATS, min_size=n, max_size=n))
#: Mostly well-formed vectors (so that inputs get past the first check), any value now and then.
VECTORS = _weighted(PLAUSIBLE_VECTOR, st.one_of(EXTREME_VECTOR, _vector()), 4)


def _dims_vector(dims: int) -> st.SearchStrategy[list[float]]:
    return st.lists(SMALL, min_size=dims, max_size=dims)


#: A number mostly in a plausible range, of any size now and then.
def _mostly(low: float, high: float) -> st.SearchStrategy[Any]:
    return _weighted(st.floats(low, high), FLOATS, 30)


@st.composite
def plausible_body(draw: st.DrawFn) -> dict[str, Any]:
    kind = draw(st.sampled_from(["circle", "sphere", "aabb"]))
    dims = 2 if kind == "circle" else 3 if kind == "sphere" else draw(st.sampled_from([2, 3]))
    vector = _weighted(_dims_vector(dims), st.one_of(EXTREME_VECTOR, _vector()), 30)
    name = _weighted(st.sampled_from(["ball", "b", "ball A"]), st.sampled_from(["", "x\ty", "a\x1b[2J"]), 30)
    body: dict[str, Any] = {"name": draw(name), "shape": kind}
    body["position"] = draw(_sometimes(vector))
    if kind == "aabb":
        body["size"] = draw(_sometimes(st.lists(_mostly(0.01, 3), min_size=dims, max_size=dims)))
    else:
        body["radius"] = draw(_sometimes(_mostly(0.01, 3)))
    if draw(st.booleans()):
        body["velocity"] = draw(_sometimes(vector))
    if draw(st.booleans()):
        body["mass"] = draw(_sometimes(_mostly(0.1, 10)))
    if draw(st.booleans()):
        body["restitution"] = draw(_sometimes(_mostly(0, 2)))
    return body


@st.composite
def plausible_static(draw: st.DrawFn) -> dict[str, Any]:
    kind = draw(st.sampled_from(["line", "plane", "aabb"]))
    static: dict[str, Any] = {"name": draw(st.sampled_from(["floor", "wall", "s"])), "shape": kind}
    dims = 2 if kind == "line" else 3 if kind == "plane" else draw(st.sampled_from([2, 3]))
    vector = _weighted(_dims_vector(dims), st.one_of(EXTREME_VECTOR, _vector()), 30)
    if kind == "line":
        static["point"] = draw(_sometimes(vector))
        static["direction"] = draw(_sometimes(vector))
    elif kind == "plane" and draw(st.booleans()):
        static["points"] = draw(_sometimes(st.lists(vector, min_size=3, max_size=3)))
    elif kind == "plane":
        static["point"] = draw(_sometimes(vector))
        static["normal"] = draw(_sometimes(vector))
    else:
        static["position"] = draw(_sometimes(vector))
        static["size"] = draw(_sometimes(st.lists(_mostly(0.01, 3), min_size=dims, max_size=dims)))
    if draw(st.booleans()):
        static["restitution"] = draw(_sometimes(_mostly(0, 2)))
    return static


@st.composite
def plausible_scenario(draw: st.DrawFn) -> dict[str, Any]:
    simulation: dict[str, Any] = {}
    for key, strategy in (
        ("dt", _mostly(1e-3, 0.5)),
        ("steps", _weighted(st.integers(1, FUZZ_STEPS), NUMBERS, 30)),
        ("restitution", _mostly(0, 1.5)),
        ("gravity", st.one_of(st.just([0, -9.81, 0]), st.just([0, -9.81]), VECTORS)),
        ("mode", _weighted(st.sampled_from(["euler", "exact"]), st.just("fast"), 30)),
        ("title", _weighted(st.text(max_size=8), VALUES, 8)),
    ):
        if draw(st.booleans()):
            simulation[key] = draw(_sometimes(strategy))
    bodies = draw(st.lists(plausible_body(), min_size=1, max_size=3))
    statics = draw(st.lists(plausible_static(), max_size=2))
    for index, thing in enumerate([*bodies, *statics]):
        if draw(st.integers(0, 9)):  # names unique, mostly: a clash is one refusal among many
            thing["name"] = f"{thing['name']}{index}"
    return {"simulation": simulation, "body": bodies, "static": statics}


_KEYS = st.sampled_from(
    ["name", "shape", "position", "radius", "size", "velocity", "mass", "restitution", "point", "normal",
     "points", "direction", "dt", "steps", "gravity", "mode", "title", "bogus"]
)  # fmt: skip
_TABLES = st.dictionaries(_KEYS, VALUES, max_size=6)
ANY_DATA = st.fixed_dictionaries(
    {
        "simulation": _TABLES,
        "body": st.one_of(st.lists(_TABLES, max_size=3), VALUES),
        "static": st.one_of(st.lists(_TABLES, max_size=3), VALUES),
    }
)
SCENARIO_DATA = _weighted(plausible_scenario(), ANY_DATA, 3)


# --- outputs -----------------------------------------------------------------------------------
def _strict_json(text: str) -> Any:
    def refuse(word: str) -> None:
        raise ValueError(f"{word} in JSON output")

    return json.loads(text, parse_constant=refuse)


def _one_line(message: str) -> bool:
    return bool(message) and "\n" not in message.strip()


def probe_scenario_data(data: dict[str, Any]) -> Outcome:
    """Parse, run a few steps, render every format: a record, or one ScenarioError/OutOfRangeError."""
    try:
        scenario = parse_scenario(data, "fuzz.toml")
    except ScenarioError as error:
        if not str(error).startswith("fuzz.toml: ") or not _one_line(str(error)):
            return Outcome("FAILURE", f"message not one line naming the file: {error!r}")
        return Outcome("error 65")
    try:
        steps = min(scenario.settings.steps, FUZZ_STEPS)
        record = simulate(scenario.with_settings(steps=steps))
    except (OutOfRangeError, InitialOverlapError) as error:  # both documented: exit 65
        return Outcome("error 65") if _one_line(str(error)) else Outcome("FAILURE", f"{error!r}")
    _strict_json(render_json(record))
    for text in (render_table(record, explain=True), render_csv(record)):
        for word in ("nan", "inf"):
            if any(cell == word or cell.endswith(f"{word})") for cell in text.replace(",", " ").split()):
                return Outcome("FAILURE", f"{word} in the output")
    return OK


def classify_cli(result: Result, fmt: str | None = None) -> Outcome:
    """A run of the command line: 0 with valid output, or 1/2/65 with one error line."""
    err_lines = [line for line in result.err.splitlines() if line.strip()]
    if "Traceback" in result.err or "unexpected error" in result.err:
        return Outcome("FAILURE", result.err[-300:])
    if result.status == 0:
        if fmt == "json" and result.out:
            _strict_json(result.out)
        noise = [line for line in err_lines if not line.startswith(("warning: ", "wrote ", "collisionlab gas"))]
        return Outcome("FAILURE", f"status 0 with stderr {noise!r}") if noise else OK
    if result.status not in (1, 2, 65):
        return Outcome("FAILURE", f"status {result.status}: {result.err[-300:]}")
    errors = [line for line in err_lines if not line.startswith("warning: ")]
    if result.status == 2:  # usage errors also show the usage, then the one error line
        errors = [line for line in errors if not line.startswith(("usage:", " "))]
    if len(errors) != 1 or not errors[0].startswith("collisionlab"):
        return Outcome("FAILURE", f"status {result.status} with stderr {result.err[-300:]!r}")
    if len(errors[0]) > 400:
        return Outcome("FAILURE", f"an error line of {len(errors[0])} characters")
    return Outcome(f"error {result.status}")


# --- raw file bytes -----------------------------------------------------------------------------
#: The shipped examples but the heavy ones (HEAVY_EXAMPLES: minutes a run, even edited).
_LIGHT_EXAMPLES = sorted(p for p in EXAMPLES.glob("*.toml") if p.stem not in HEAVY_EXAMPLES)
_EXAMPLE_BYTES = [path.read_bytes() for path in _LIGHT_EXAMPLES]


@st.composite
def file_bytes(draw: st.DrawFn) -> bytes:
    """An example file with a few byte edits (insert, delete, replace), or random bytes."""
    if draw(st.integers(0, 4)) == 0:
        return draw(st.binary(max_size=300))
    data = bytearray(draw(st.sampled_from(_EXAMPLE_BYTES)))
    for _ in range(draw(st.integers(1, 6))):
        where = draw(st.integers(0, len(data)))
        edit = draw(st.sampled_from(["insert", "delete", "replace", "digits"]))
        piece = draw(st.one_of(st.binary(min_size=1, max_size=4), st.sampled_from([b"e308", b"-", b"[", b'"', b"\n"])))
        if edit == "insert":
            data[where:where] = piece
        elif edit == "delete":
            del data[where : where + len(piece)]
        elif edit == "replace":
            data[where : where + len(piece)] = piece
        else:
            data[where:where] = str(draw(st.integers(-(10**30), 10**30))).encode()
    return bytes(data)


_FOLDER = Path(tempfile.mkdtemp(prefix="collisionlab-fuzz-"))


def probe_file_bytes(data: bytes) -> Outcome:
    path = _FOLDER / "fuzz.toml"
    path.write_bytes(data)
    fmt = "json" if len(data) % 2 else "table"
    return classify_cli(run_cli(["run", str(path), "--steps", str(FUZZ_STEPS), "--format", fmt]), fmt)


# --- command lines ------------------------------------------------------------------------------
_WORDS = ["run", "demo", "menu", "gas", "spheres", "head-on", "stack", "nope", "--steps", "--dt", "--every",
          "--mode", "--format", "--restitution", "--quiet", "--explain", "--list", "euler", "exact", "json", "csv",
          "table", "3", "0", "-1", "0.01", "1e308", "1e-300", "nan", "inf", "x", "", "--help", "--bogus",
          "--output", str(_FOLDER / "out.txt"), str(_FOLDER), str(_FOLDER / "missing" / "o.txt"), "--n",
          "--dim", "--seed", "--gravity", "--speeds", "equal", "--backend", "numpy", "99999999999999999999",
          "--kernels", "python", "compiled", "compile",
          str(EXAMPLES / "bouncing-ball.toml"), str(EXAMPLES / "none.toml"), "/dev/zero", "-", "--time",
          "--fraction", "--tc", "--boundary", "periodic", "--events", str(_FOLDER / "ev.csv"), "--mode", "exact",
          "5e-324", "9" * 400, "x" * 400, str(_FOLDER / ("p" * 300))]  # fmt: skip
_OPTIONS = st.sampled_from(
    [["--steps", "5"], ["--dt", "0.05"], ["--dt", "1e-9"], ["--dt", "1e6"], ["--mode", "exact"], ["--mode", "euler"],
     ["--restitution", "0.5"], ["--restitution", "10"], ["--restitution", "1e308"], ["--every", "2"],
     ["--kernels", "python"], ["--kernels", "compiled"], ["--kernels", "fast"],
     ["--format", "json"], ["--format", "csv"], ["--quiet"], ["--explain"], ["--output", str(_FOLDER / "o.txt")],
     ["--output", ""], ["--steps", "2000001"], ["--steps", "1e23"], ["--steps", "9" * 400],
     ["--output", str(_FOLDER / ("p" * 300) / "o.txt")], ["--output", str(_FOLDER / "missing" / ("o" * 400))]]
)  # fmt: skip
#: The exact gas (``gas --mode exact --n 60 --time 1``): its own flags, at and beyond their range.
_EXACT_GAS_OPTIONS = st.sampled_from(
    [["--time", "5e-324"], ["--time", "1e308"], ["--time", "0.5"], ["--fraction", "1e-20"], ["--fraction", "0.5"],
     ["--fraction", "0.8"], ["--tc", "1e308"], ["--tc", "0"], ["--restitution", "10"], ["--restitution", "0.5"],
     ["--gravity", "10"], ["--gravity", "1e300"], ["--boundary", "periodic"], ["--dim", "3"], ["--n", "0"],
     ["--n", "99999999999999999999"], ["--seed", "-1"], ["--seed", "7"], ["--format", "json"], ["--quiet"],
     ["--events", str(_FOLDER / "ev.csv")], ["--events", str(_FOLDER / "ev.jsonl")], ["--events", "ev.txt"],
     ["--events", str(_FOLDER / "missing" / "e.csv")], ["--plot", str(_FOLDER / "g.png")],
     ["--trajectory", str(_FOLDER / "t.gsd")], ["--trajectory", str(_FOLDER / "t.xyz")], ["--trajectory", "t.dcd"],
     ["--frames", "0"], ["--frames", "3"], ["--frames", "99999999999999999999"]]
)  # fmt: skip
_STRUCTURED = st.tuples(
    st.one_of(
        st.sampled_from(["stack", "spheres", "bouncing-ball", "newtons-cradle", "circle-box", "head-on"]).map(
            lambda name: ["demo", name]
        ),
        st.sampled_from([p.name for p in _LIGHT_EXAMPLES]).map(lambda f: ["run", str(EXAMPLES / f)]),
        st.just(["gas", "--dim", "3"]),
    ),
    st.lists(_OPTIONS, max_size=4),
).map(lambda parts: [*parts[0], *[word for option in parts[1] for word in option]])
_EXACT_GAS = st.lists(_EXACT_GAS_OPTIONS, max_size=4).map(
    lambda options: ["gas", "--mode", "exact", *[word for option in options for word in option]]
)
COMMAND_LINES = _weighted(
    _weighted(_STRUCTURED, _EXACT_GAS, 2),  # the exact gas a third of the time
    st.lists(_weighted(st.sampled_from(_WORDS), st.text(max_size=5), 3), max_size=7),
    2,
)


def probe_command_line(argv: list[str]) -> Outcome:
    argv = list(argv)
    if argv[:1] == ["gas"]:  # a small, short gas, unless the words say otherwise (the last one counts)
        argv[1:1] = ["--n", "60", "--steps", "5", "--time", "1"]
    elif "gas" in argv:
        argv += ["--n", "60", "--steps", "5"]
    elif "--steps" not in argv:
        argv += ["--steps", "3"]
    formats = [argv[i + 1] for i, word in enumerate(argv[:-1]) if word == "--format"]
    fmt = formats[-1] if formats else None  # argparse keeps the last
    return classify_cli(run_cli(argv, stdin=""), fmt)


# --- menu answers -------------------------------------------------------------------------------
_ANSWERS = st.one_of(
    st.just(""),
    st.just(""),
    st.sampled_from(
        [
            "0",
            "1",
            "-1",
            "0.5",
            "2",
            "1 0",
            "1 0 0",
            "0 0 0",
            "1 1 1",
            "nan",
            "inf",
            "1e308",
            "1e200 0 0",
            "5e-324",
            "a",
            "exact",
            "euler",
            "y",
            "n",
            "1 2 3 4",
            "1,2,3",
            "\x1b[2J",
            "99999999999",
            "0 0 1",
            "2 0 0",
        ]
    ),
    st.text(max_size=6),
    st.lists(FLOATS, min_size=1, max_size=3).map(lambda xs: " ".join(repr(x) for x in xs)),
)
MENU_SESSIONS = st.tuples(
    st.one_of(st.integers(1, 8).map(str), st.sampled_from(["", "0", "9", "x"])),
    st.lists(_ANSWERS, max_size=16),
)


def probe_menu(session: tuple[str, list[str]]) -> Outcome:
    case, answers = session
    cleaned = [answer.replace("\n", " ").replace("\r", " ") for answer in answers]
    # Never "y" to saving (it would write files where the tests run): the dialogue asks again.
    cleaned = [answer for answer in cleaned if answer.strip().lower() not in ("y", "yes")]
    # Then Enter until the end (each question's default; "no" to saving), so most sessions run.
    return classify_cli(run_cli(["menu"], typed(case.replace("\n", " "), *cleaned, *[""] * 40)))


# --- the public API -----------------------------------------------------------------------------
_ANY = st.one_of(NUMBERS, _vector(), st.none(), st.text(max_size=3))


def _shape() -> st.SearchStrategy[Any]:
    vec = st.one_of(PLAUSIBLE_VECTOR, _vector())
    size = st.one_of(st.floats(0.01, 3), FLOATS, NUMBERS)
    return st.one_of(
        st.builds(Circle, vec, size),
        st.builds(Sphere, vec, size),
        st.builds(AABB, vec, vec),
        st.builds(AABB.from_center_size, vec, vec),
        st.builds(Line, vec, vec),
        st.builds(Plane, vec, vec),
        st.builds(Plane.from_points, vec, vec, vec),
    )


@st.composite
def api_calls(draw: st.DrawFn) -> tuple[str, Callable[[], Any]]:
    """A name (for the report) and a call of one public function with drawn arguments; shapes are
    built inside the call, so their refusals are outcomes too."""
    vec = VECTORS
    which = draw(st.sampled_from(["vector", "shape", "query", "toi", "reflect", "resolve", "separate"]))
    if which == "vector":
        xyz = draw(st.lists(NUMBERS, min_size=2, max_size=3))  # Vector3D(x, y[, z]): any numbers
        b, c = draw(vec), draw(vec)
        # + and - take vectors (2 or 3 numbers); a float operand is Python's TypeError by design
        # (the operator returns NotImplemented), as Vector3D * Vector3D is: not a probe of ours.
        p, q = draw(st.one_of(PLAUSIBLE_VECTOR, EXTREME_VECTOR)), draw(st.one_of(PLAUSIBLE_VECTOR, EXTREME_VECTOR))
        op = draw(st.sampled_from(["normalized", "length", "cross", "dot", "parallel", "perpendicular", "line", "plane",
                                   "add", "scale"]))  # fmt: skip
        scalar = draw(FLOATS)
        calls: dict[str, Callable[[], Any]] = {
            "normalized": lambda: Vector3D(*xyz).normalized(),
            "length": lambda: Vector3D(*xyz).length(),
            "cross": lambda: Vector3D(*xyz).cross(b),
            "dot": lambda: Vector3D(*xyz).dot(b),
            "parallel": lambda: Vector3D(*xyz).parallel_projection(b),
            "perpendicular": lambda: Vector3D(*xyz).perpendicular_projection(b),
            "line": lambda: Vector3D.closest_point_on_line(xyz, b, c),
            "plane": lambda: Vector3D.closest_point_on_plane(xyz, b, c),
            "add": lambda: Vector3D(*xyz) + p - q,
            "scale": lambda: Vector3D(*xyz) * scalar / (scalar or 1.0),
        }
        return f"Vector3D {op}({xyz!r}, {b!r}, {c!r}, {scalar!r})", calls[op]
    if which in ("shape", "query", "toi"):
        size = _weighted(st.floats(0.01, 3), NUMBERS, 3)
        spec = st.tuples(st.sampled_from(range(7)), vec, vec, vec, size)
        shapes = draw(st.lists(spec, min_size=2, max_size=2))

        def build(spec: tuple[int, Any, Any, Any, Any]) -> Any:
            kind, p, q, r, size = spec
            makers: list[Callable[[], Any]] = [
                lambda: Circle(p, size),
                lambda: Sphere(p, size),
                lambda: AABB(p, q),
                lambda: AABB.from_center_size(p, q),
                lambda: Line(p, q),
                lambda: Plane(p, q),
                lambda: Plane.from_points(p, q, r),
            ]
            return makers[kind]()

        if which == "shape":
            return f"shape {shapes[0]!r}", lambda: build(shapes[0])
        if which == "query":
            query = draw(st.sampled_from([contact, distance, intersects, separation]))
            return f"{query.__name__}{tuple(shapes)!r}", lambda: query(build(shapes[0]), build(shapes[1]))
        motion = [draw(vec), draw(vec), draw(_weighted(st.floats(0, 10), FLOATS, 3)), draw(vec), draw(vec)]
        return (
            f"time_of_impact({shapes!r}, {motion!r})",
            lambda: time_of_impact(build(shapes[0]), build(shapes[1]), *motion),
        )
    scalars = [draw(_weighted(st.floats(0.1, 10), NUMBERS, 3)) for _ in range(4)]
    a, b, c = draw(vec), draw(vec), draw(vec)
    if which == "reflect":
        return f"reflect_velocity({a!r}, {b!r}, {scalars[0]!r})", lambda: reflect_velocity(a, b, scalars[0])
    if which == "resolve":
        return (
            f"resolve_collision({a!r}, {b!r}, {scalars[:3]!r}, {c!r})",
            lambda: resolve_collision(a, b, scalars[0], scalars[1], c, scalars[2]),
        )
    return (
        f"separate({a!r}, {b!r}, {scalars!r}, {c!r})",
        lambda: separate(a, b, scalars[0], scalars[1], c, scalars[2]),
    )


def _numbers_in(value: Any) -> list[float]:
    if isinstance(value, bool) or value is None:
        return []
    if isinstance(value, (int, float)):
        return [float(value)]
    if isinstance(value, Vector3D):
        return list(value)
    if isinstance(value, (tuple, list)):
        return [x for item in value for x in _numbers_in(item)]
    if hasattr(value, "__dataclass_fields__"):
        return [x for name in value.__dataclass_fields__ for x in _numbers_in(getattr(value, name))]
    return []


def classify_api(call: Callable[[], Any]) -> Outcome:
    """A library call: a finite result, or one of the library's errors with a one-line message."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # a leaked warning is a failure too
            result = call()
    except CollisionLabError as error:
        if not _one_line(str(error)) or len(str(error)) > 400:
            return Outcome("FAILURE", f"{type(error).__name__} message: {str(error)[:300]!r}")
        return Outcome(f"error {type(error).__name__}")
    except Exception as error:  # anything else escaping the library
        return Outcome("FAILURE", f"{type(error).__name__}: {error}")
    if not all(math.isfinite(x) for x in _numbers_in(result)):
        return Outcome("FAILURE", f"non-finite result {result!r}")
    return OK


def probe_api(call: tuple[str, Callable[[], Any]]) -> Outcome:
    return classify_api(call[1])


# --- the surfaces, and running them ---------------------------------------------------------------
SURFACES: dict[str, tuple[st.SearchStrategy[Any], Callable[[Any], Outcome], float]] = {
    # name: (strategy, probe, share of the inputs)
    "scenario-data": (SCENARIO_DATA, probe_scenario_data, 0.25),
    "file-bytes": (file_bytes(), probe_file_bytes, 0.15),
    "command-line": (COMMAND_LINES, probe_command_line, 0.10),
    "menu-answers": (MENU_SESSIONS, probe_menu, 0.05),  # each session runs 150-200 steps: the dearest
    "public-api": (api_calls(), probe_api, 0.45),
}


def guarded(probe: Callable[[Any], Outcome], value: Any) -> Outcome:
    """``probe(value)``, with anything it raises (a bug in collisionlab) as a FAILURE."""
    try:
        return probe(value)
    except Exception as error:
        return Outcome("FAILURE", f"{type(error).__name__}: {str(error)[:300]}")


def explore(name: str, count: int) -> tuple[Counter[str], list[str]]:
    """``count`` inputs of surface ``name`` (hypothesis, derandomized: the same inputs on every
    run): the counts by outcome and the failures, each with its input (the reproducer)."""
    strategy, probe, _ = SURFACES[name]
    counts: Counter[str] = Counter()
    failures: list[str] = []

    @settings(
        max_examples=count,
        derandomize=True,
        database=None,
        deadline=None,
        phases=[Phase.generate],
        suppress_health_check=list(HealthCheck),
    )
    @given(strategy)
    def feed(value: Any) -> None:
        outcome = guarded(probe, value)
        counts[outcome.kind] += 1
        if outcome.failed and len(failures) < 50:
            failures.append(f"FAILURE {outcome.detail}\n    input: {value!r}"[:2000])

    feed()
    return counts, failures


def _explore_timed(name: str, count: int) -> tuple[str, Counter[str], list[str], float]:
    start = time.monotonic()
    counts, failures = explore(name, count)
    return name, counts, failures, time.monotonic() - start


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tests.fuzz_harness", description=__doc__.split("\n\n")[0])
    parser.add_argument("--inputs", type=int, default=100_000, help="inputs in all (default 100000)")
    parser.add_argument("--surface", choices=sorted(SURFACES), action="append", help="only these surfaces")
    parser.add_argument("--jobs", type=int, default=1, help="surfaces explored in parallel processes")
    args = parser.parse_args(argv)
    names = args.surface or list(SURFACES)
    share = sum(SURFACES[n][2] for n in names)
    counts_of = {name: max(1, round(args.inputs * SURFACES[name][2] / share)) for name in names}
    total: Counter[str] = Counter()
    began = time.monotonic()
    with concurrent.futures.ProcessPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        jobs = [pool.submit(_explore_timed, name, counts_of[name]) for name in names]
        for job in concurrent.futures.as_completed(jobs):
            name, counts, failures, took = job.result()
            total.update(counts)
            summary = ", ".join(f"{kind} {n:,}" for kind, n in sorted(counts.items()))
            print(f"{name:<14} {sum(counts.values()):>7,} inputs in {took:6.1f} s: {summary}", flush=True)
            for failure in failures:
                print(f"  {failure}", flush=True)
    summary = ", ".join(f"{kind} {n:,}" for kind, n in sorted(total.items()))
    print(f"{'all':<14} {sum(total.values()):>7,} inputs in {time.monotonic() - began:6.1f} s: {summary}")
    return 1 if total["FAILURE"] else 0


if __name__ == "__main__":
    sys.exit(main())
