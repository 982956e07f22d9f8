"""The lab's interactive menu (part VI.A-B): which case, then every parameter, each with a
default in brackets that Enter accepts and the expected form. A bad answer prints a one-line
reason and the question is asked again. The answers become a scenario through the same
validation as a scenario file, so the menu holds no physics. The questions and their parsers are
:mod:`.menu_questions`'s."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..atomic import write_text_atomically
from ..errors import InvalidInputError
from ..scenario_file import ScenarioError, parse_scenario, scenario_to_toml
from ..world import World
from .interrupts import ChunkWatch, interruptible, interrupts_for
from .menu_questions import (
    Answers,
    Question,
    _body,
    _common,
    _direction,
    _size,
    _suggest_third_point,
    _third_point,
    _two_bodies,
    _vector,
)
from .progress import ProgressBar
from .render import render_table
from .streams import Streams

__all__ = ["CASES", "run_menu"]


@dataclass(frozen=True)
class Case:
    title: str
    questions: list[Question]
    body_shape: str
    static_shape: str | None


CASES: list[Case] = [
    Case(
        "AABB in 3D",
        [
            *_two_bodies("box", "aabb", 3, ("0 0 0", "1 1 1", "1 0 0", "3.05 0.2 0.1", "1 1 1", "-1 0 0")),
            *_common("1", "0.01", "200", bodies=2),
        ],
        "aabb",
        None,
    ),
    Case(
        "sphere and sphere",
        [
            *_two_bodies("sphere", "sphere", 3, ("0 0 0", "0.5", "1 0 0", "3 0.3 0", "0.5", "-1 0 0")),
            *_common("1", "0.01", "200", bodies=2),
        ],
        "sphere",
        None,
    ),
    Case(
        "circle and line",
        [
            *_body("the circle", "a", 2, "circle", "0 2.01", "0.5", "1 -2"),
            Question("line.direction", "direction of the line", "dx dy, two numbers, not both 0", "1 0", _direction(2)),
            Question("line.point", "a point on the line", "x y, two numbers", "0 0", _vector(2, "point")),
            *_common("0.8", "0.01", "150"),
        ],
        "circle",
        "line",
    ),
    Case(
        "sphere and plane",
        [
            *_body("the sphere", "a", 3, "sphere", "0 3.01 0", "0.5", "1 -2 0.5"),
            Question("p1", "first point on the plane", "x y z, three numbers", "0 0 0", _vector(3, "point 1")),
            Question("p2", "second point on the plane", "x y z, three numbers", "0 0 1", _vector(3, "point 2")),
            Question(
                "p3",
                "third point on the plane",
                "x y z, not on the line through the first two",
                "1 0 0",
                _third_point,
                _suggest_third_point,
            ),
            *_common("0.8", "0.01", "200"),
        ],
        "sphere",
        "plane",
    ),
    Case(
        "circle and circle",
        [
            *_two_bodies("circle", "circle", 2, ("0 0", "0.5", "1 0", "3 0.4", "0.5", "-1 0")),
            *_common("1", "0.01", "200", bodies=2),
        ],
        "circle",
        None,
    ),
    Case(
        "AABB in 2D",
        [
            *_two_bodies("box", "aabb", 2, ("0 0", "1 1", "1 0", "3.05 0.3", "1 1", "-1 0")),
            *_common("1", "0.01", "200", bodies=2),
        ],
        "aabb",
        None,
    ),
    Case(
        "sphere and a fixed box",
        [
            *_body("the sphere", "a", 3, "sphere", "-3 0.5 0", "0.5", "2 0 0"),
            Question(
                "box.position", "centre of the fixed box", "x y z, three numbers", "0 0 0", _vector(3, "position")
            ),
            Question("box.size", "extent of the fixed box", "edge lengths along x y z, > 0", "2 2 2", _size(3)),
            *_common("0.9", "0.01", "200"),
        ],
        "sphere",
        "aabb",
    ),
    Case(
        "circle and a fixed box",
        [
            *_body("the circle", "a", 2, "circle", "-3 0.8", "0.5", "3 0"),
            Question("box.position", "centre of the fixed box", "x y, two numbers", "0 0", _vector(2, "position")),
            Question("box.size", "extent of the fixed box", "edge lengths along x y, > 0", "2 2", _size(2)),
            *_common("0.9", "0.01", "150"),
        ],
        "circle",
        "aabb",
    ),
]


def _scenario_data(case: Case, answers: Answers) -> dict[str, Any]:
    """The answers as the same data a scenario file gives (validated by the same code)."""

    def body(key: str, name: str) -> dict[str, Any]:
        data: dict[str, Any] = {"name": name, "shape": case.body_shape}
        for field in ("position", "radius", "size", "velocity", "mass"):
            if f"{key}.{field}" in answers:
                data[field] = answers[f"{key}.{field}"]
        return data

    two = case.static_shape is None
    noun = {"aabb": "box", "sphere": "sphere", "circle": "circle"}[case.body_shape]
    bodies = [body("a", f"{noun} A"), body("b", f"{noun} B")] if two else [body("a", noun)]
    statics: list[dict[str, Any]] = []
    if case.static_shape == "line":
        statics.append(
            {"name": "line", "shape": "line", "point": answers["line.point"], "direction": answers["line.direction"]}
        )
    elif case.static_shape == "plane":
        statics.append({"name": "plane", "shape": "plane", "points": [answers["p1"], answers["p2"], answers["p3"]]})
    elif case.static_shape == "aabb":
        statics.append(
            {"name": "box", "shape": "aabb", "position": answers["box.position"], "size": answers["box.size"]}
        )
    simulation = {k: answers[k] for k in ("dt", "steps", "restitution", "mode")}
    simulation["title"] = f"Menu: {case.title}"
    # Typed answers may place bodies overlapping: the run pushes them apart and its table says so.
    simulation["allow_initial_overlap"] = True
    return {"simulation": simulation, "body": bodies, "static": statics}


class _Dialogue:
    def __init__(self, streams: Streams) -> None:
        self.streams = streams

    def ask(self, prompt: str) -> str:
        self.streams.stdout.write(prompt)
        self.streams.stdout.flush()
        line = self.streams.stdin.readline()
        if not line:
            raise EOFError
        if not self.streams.interactive:
            self.streams.stdout.write(line if line.endswith("\n") else line + "\n")
        return line.strip()

    def question(self, q: Question, answers: Answers) -> Any:
        default = q.default_for(answers)
        while True:
            text = self.ask(f"{q.text} ({q.form}) [{default}]: ") or default
            try:
                value = q.parse(text, answers)
            except InvalidInputError as error:
                self.streams.out(f"  ! {error}; try again")
                continue
            if q.key == "restitution" and isinstance(value, float) and value > 1.0:
                self.streams.out("  warning: e > 1: kinetic energy will grow with every collision (postlab Q4)")
            return value

    def yes(self, prompt: str) -> bool:
        while True:
            answer = self.ask(f"{prompt} [y/N]: ").lower()
            if answer in ("", "n", "no"):
                return False
            if answer in ("y", "yes"):
                return True
            self.streams.out("  ! answer y or n")

    def save(self, what: str, default: str, write: Callable[[str], None]) -> str:
        """Ask for a file name and write it; a name that cannot be written (a missing folder, no
        permission, a wrong extension) prints the reason and is asked again: the run is kept."""
        while True:
            path = self.ask(f"{what} [{default}]: ") or default
            try:
                write(path)
            except OSError as error:
                self.streams.out(f"  ! cannot write {path}: {error.strerror or error}; try again")
                continue
            except InvalidInputError as error:
                self.streams.out(f"  ! {error.problem}; try again")
                continue
            self.streams.out(f"wrote {path}")
            return path

    def choose_case(self) -> Case:
        self.streams.out("Which case?")
        for number, case in enumerate(CASES, start=1):
            self.streams.out(f"  {number}  {case.title}")
        while True:
            text = self.ask(f"case (1-{len(CASES)}) [4]: ") or "4"
            if text.isdigit() and 1 <= int(text) <= len(CASES):
                return CASES[int(text) - 1]
            self.streams.out(f"  ! case: expected a number from 1 to {len(CASES)}; try again")


def run_menu(streams: Streams) -> int:
    """The whole dialogue: choose, answer, run and print; then offer a plot and a scenario file."""
    dialogue = _Dialogue(streams)
    streams.out("collisionlab: collision detection and resolution (the lab's part VI)")
    case = dialogue.choose_case()
    answers: Answers = {}
    for q in case.questions:
        answers[q.key] = dialogue.question(q, answers)
    while True:
        try:
            scenario = parse_scenario(_scenario_data(case, answers), "<menu>")
            break
        except ScenarioError as error:  # the answers together (exact mode too fast for dt): ask the step again
            streams.out(f"  ! {error.field}: {error.problem}; try again")
            for q in case.questions:
                if q.key in ("dt", "steps", "mode"):
                    answers[q.key] = dialogue.question(q, answers)
    world = World(scenario)
    interruptible(world.load_kernels)  # before the bar's clock starts: compiling is not running
    bar = ProgressBar(streams, scenario.title)
    try:
        with interrupts_for(world.compiled) as pending:  # compiled: looked for between chunks
            watch = ChunkWatch(pending, bar)  # a chunk runs in a thread of its own: a signal stops it
            record = world.run(progress=watch.between, calling=watch.call)
    finally:
        bar.close()
    streams.stdout.write(render_table(record))
    if dialogue.yes("save a plot?"):
        from .. import plotting  # matplotlib loads only when a picture is asked for

        dialogue.save("plot file", "collision.png", lambda path: plotting.save_plot(record, scenario, path))
    if dialogue.yes("save these answers as a scenario file?"):
        path = dialogue.save(
            "scenario file",
            "scenario.toml",
            lambda path: write_text_atomically(path, lambda: scenario_to_toml(scenario)),
        )
        streams.out(f"run it again with: collisionlab run {path}")
    return 0
