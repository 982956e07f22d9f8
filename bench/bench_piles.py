"""Piles: circles poured into a box, collisionlab's contact solver against pymunk, side by side.

The scene of issue "Piles, pours and stacks": ``N`` circles (r 0.5 m, m 1 kg) laid 1.2 diameters
apart from y = 2 m, poured into a box of three lines ``WIDTH`` m wide (floor, two sides), e 0.5,
g 9.81, dt 0.01, ``STEPS`` steps. Both engines get the same bodies, the same steps and the same
restitution (pymunk multiplies two shapes' elasticities, so each shape gets sqrt(0.5));
pymunk's circles are frictionless and do not turn, as ours, with its default solver (10
iterations).

Printed, each as the median of ``--runs`` runs with min-max:
* ``collisionlab run`` the whole command (start-up and compiled kernels loaded from the cache
  included; JSON written to a file), against pymunk's stepping alone;
* the hard phase apart: the pile once it has formed (the last half of the steps), stepped in
  process by both, body-steps/s;
* what each leaves: kinetic energy per ball at the end, bodies outside the box, the deepest
  overlap of two circles or a circle and a line (as a fraction of the radius).

    python3 tasks.py bench-piles                 # N 2000, 1000 steps, 3 runs
    python3 bench/bench_piles.py --n 400 --steps 600 --runs 3
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

RADIUS = 0.5
DT = 0.01
E = 0.5
G = 9.81


def layout(n: int, width: float) -> np.ndarray:
    """The circles' centres: rows 1.2 diameters apart from y = 2 m, as many per row as fit."""
    spacing = 2.4 * RADIUS
    per_row = int((width - 2 * RADIUS) // spacing)
    k = np.arange(n)
    x = -width / 2 + RADIUS + spacing * (k % per_row) + 0.5 * (width - 2 * RADIUS - spacing * (per_row - 1))
    # a small sideways offset per row, so the columns do not land on top of each other exactly
    x += 0.05 * RADIUS * np.sin(1.7 * k)
    y = 2.0 + spacing * (k // per_row)
    return np.c_[x, y]


def scenario_toml(n: int, width: float, steps: int) -> str:
    lines = [
        "[simulation]",
        f'title = "{n} circles poured into a box"',
        f"dt = {DT}",
        f"steps = {steps}",
        f"restitution = {E}",
        f"gravity = [0, {-G}, 0]",
        'mode = "exact"',
        'contacts = "solve"',
        "",
    ]
    for name, point, direction in (
        ("floor", (0, 0), (1, 0)),
        ("left", (-width / 2, 0), (0, 1)),
        ("right", (width / 2, 0), (0, 1)),
    ):
        lines += [
            "[[static]]",
            f'name = "{name}"',
            'shape = "line"',
            f"point = {list(point)}",
            f"direction = {list(direction)}",
            "",
        ]
    for i, (x, y) in enumerate(layout(n, width)):
        lines += [
            "[[body]]",
            f'name = "c{i}"',
            'shape = "circle"',
            f"position = [{float(x)!r}, {float(y)!r}]",
            f"radius = {RADIUS}",
            "",
        ]
    return "\n".join(lines)


def pair_overlap(pos: np.ndarray, radius: float) -> float:
    """The deepest overlap of two balls of ``radius`` at ``pos`` (0 if none), in metres."""
    n = len(pos)
    d = np.sqrt(((pos[:, None, :] - pos[None, :, :]) ** 2).sum(axis=2)) + np.eye(n) * 1e9
    return max(0.0, float((2 * radius - d).max()))


def outcome(pos: np.ndarray, vel: np.ndarray, width: float) -> dict[str, float]:
    """Kinetic energy per ball, bodies outside the box, deepest overlap / radius."""
    n = len(pos)
    overlap = pair_overlap(pos, RADIUS)
    walls = np.r_[RADIUS - pos[:, 1], RADIUS - (pos[:, 0] + width / 2), RADIUS - (width / 2 - pos[:, 0])]
    overlap = max(overlap, float(walls.max()))
    outside = int(np.sum((pos[:, 1] < 0) | (np.abs(pos[:, 0]) > width / 2)))
    return {"ke_per_ball": 0.5 * float((vel**2).sum()) / n, "outside": outside, "overlap_r": overlap / RADIUS}


# --- collisionlab ---------------------------------------------------------------------------------
def ours_command(path: Path, out: Path) -> float:
    """Seconds of the whole ``collisionlab run`` command."""
    script = Path(sys.executable).with_name("collisionlab")
    start = time.perf_counter()
    subprocess.run([str(script), "run", str(path), "--format", "json", "--every", "100000", "--output", str(out)],
                   check=True, stdout=subprocess.DEVNULL)  # fmt: skip
    return time.perf_counter() - start


def ours_phases(path: Path, steps: int, width: float) -> dict[str, float]:
    from collisionlab.engine.world import World
    from collisionlab.scenario_file import load_scenario

    world = World(load_scenario(path))
    world.step(1)  # loads the compiled kernels
    world.step(steps // 2 - 1)
    start = time.perf_counter()
    world.step(steps - steps // 2)
    took = time.perf_counter() - start
    n = len(world.position_array)
    return {
        "formed_rate": n * (steps - steps // 2) / took,
        **outcome(world.position_array[:, :2], world.velocity_array[:, :2], width),
    }


# --- pymunk ---------------------------------------------------------------------------------------
def pymunk_run(n: int, width: float, steps: int) -> dict[str, float]:
    import pymunk

    space = pymunk.Space()
    space.gravity = (0.0, -G)
    elasticity = math.sqrt(E)
    bodies = []
    for x, y in layout(n, width):
        body = pymunk.Body(1.0, math.inf)
        body.position = (float(x), float(y))
        shape = pymunk.Circle(body, RADIUS)
        shape.elasticity, shape.friction = elasticity, 0.0
        space.add(body, shape)
        bodies.append(body)
    for a, b in (
        ((-width / 2, 0), (width / 2, 0)),
        ((-width / 2, 0), (-width / 2, 1e4)),
        ((width / 2, 0), (width / 2, 1e4)),
    ):
        wall = pymunk.Segment(space.static_body, a, b, 0.0)
        wall.elasticity, wall.friction = elasticity, 0.0
        space.add(wall)
    start = time.perf_counter()
    for _ in range(steps // 2):
        space.step(DT)
    half = time.perf_counter()
    for _ in range(steps - steps // 2):
        space.step(DT)
    end = time.perf_counter()
    pos = np.array([tuple(b.position) for b in bodies])
    vel = np.array([tuple(b.velocity) for b in bodies])
    return {"seconds": end - start, "formed_rate": n * (steps - steps // 2) / (end - half), **outcome(pos, vel, width)}


def spread(values: list[float], unit: str = "") -> str:
    return f"{statistics.median(values):.3g}{unit} ({min(values):.3g}-{max(values):.3g})"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=2000)
    parser.add_argument("--width", type=float, default=50.0)
    parser.add_argument("--steps", type=int, default=1000)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    n, width, steps = args.n, args.width, args.steps
    print(f"{n} circles into a {width:g} m box, {steps} steps of {DT} s; medians of {args.runs} runs (min-max)")
    print(f"machine: {os.cpu_count()} cores, Python {sys.version.split()[0]}")
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "pour.toml"
        path.write_text(scenario_toml(n, width, steps), encoding="utf-8")
        out = Path(folder) / "pour.json"
        ours_command(path, out)  # warm-up: compiles the kernels once if the cache lacks them
        ours = [ours_command(path, out) for _ in range(args.runs)]
        last = json.loads(out.read_text(encoding="utf-8"))["frames"][-1]["bodies"]
        pos = np.array([[b["position"][0], b["position"][1]] for b in last])
        vel = np.array([[b["velocity"][0], b["velocity"][1]] for b in last])
        ours_end = outcome(pos, vel, width)
        phases = [ours_phases(path, steps, width) for _ in range(args.runs)]
    theirs = [pymunk_run(n, width, steps) for _ in range(args.runs)]
    body_steps = n * steps
    ratio = statistics.median([r["seconds"] for r in theirs]) / statistics.median(ours)
    print(f"whole run   collisionlab run (command) {spread([body_steps / s / 1e6 for s in ours], 'M')} body-steps/s"
          f"   pymunk stepping {spread([body_steps / r['seconds'] / 1e6 for r in theirs], 'M')} body-steps/s"
          f"   collisionlab / pymunk (medians) {ratio:.2f}x")  # fmt: skip
    formed = spread([p["formed_rate"] / 1e6 for p in phases], "M")
    print(f"pile formed (steps {steps // 2}-{steps})  collisionlab {formed}"
          f"   pymunk {spread([r['formed_rate'] / 1e6 for r in theirs], 'M')} body-steps/s")  # fmt: skip
    for label, end in (("collisionlab", ours_end), ("pymunk", theirs[-1])):
        print(f"{label:>12} at {steps * DT:g} s: kinetic energy {end['ke_per_ball']:.3g} J per ball, "
              f"{end['outside']} outside the box, deepest overlap {end['overlap_r']:.3g} of a radius")  # fmt: skip


if __name__ == "__main__":
    main()
