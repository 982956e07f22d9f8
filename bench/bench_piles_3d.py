"""Piles in 3D: spheres poured into a walled box, collisionlab's contact solver against pybullet.

The 3D pour of issue "Piles, pours and stacks": ``N`` spheres (r 0.5 m, m 1 kg) laid on a
lattice 1.2 diameters apart from y = 2 m, poured into a ``WIDTH`` m square box (a floor plane
and four static AABB walls, 1 m thick and ``TOP`` m high), e 0.5, g 9.81 along -y, dt 0.01,
``STEPS`` steps; then twice ``--rest`` more steps of the pile once it has formed. Both engines
get the same bodies, the same steps and the same restitution (Bullet multiplies two objects'
restitutions, so each gets sqrt(0.5)). pybullet: no friction of any kind (lateral, rolling,
spinning 0), its default solver (50 iterations, no substeps, its default push-out and contact
threshold), bodies allowed to sleep (``ACTIVATION_STATE_ENABLE_SLEEPING``), as ours sleep.

Printed, each as the median of ``--runs`` runs with min-max:
* ``collisionlab run`` the whole command over ``STEPS`` steps (start-up and compiled kernels
  loaded from the cache included; JSON written to a file), against pybullet's stepping alone;
* the hard phases apart, stepped in process by both: the pile forming (the last half of the
  ``STEPS``), ``--rest`` more steps after them (the pile settling), and ``--rest`` more again
  (the settled pile: ours asleep by then at the full size), body-steps/s;
* what each leaves after each phase: kinetic energy per ball, bodies asleep (ours),
  bodies outside the box, the deepest overlap of two spheres or a sphere and a wall or the
  floor (as a fraction of the radius).

    python3 tasks.py bench-piles-3d                     # N 1000, 500 + 2000 + 2000 steps, 3 runs
    python3 bench/bench_piles_3d.py --n 200 --steps 100 --rest 100 --runs 3   # a quick check
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
from bench_piles import ours_command, pair_overlap, spread  # the 2D pour's, beside this file

RADIUS = 0.5
DT = 0.01
E = 0.5
G = 9.81
#: The walls' thickness and height (m): far above the highest ball's start.
THICK = 1.0
TOP = 40.0


def layout(n: int, width: float) -> np.ndarray:
    """The spheres' centres: square layers 1.2 diameters apart from y = 2 m, as many a row as fit
    across the box in x and z, each centre nudged by at most 0.025 m in x and z, so the columns
    do not land exactly on top of one another."""
    spacing = 2.4 * RADIUS
    per_row = int((width - 2 * RADIUS) // spacing) + 1
    k = np.arange(n)
    offset = -(per_row - 1) * spacing / 2
    x = offset + spacing * (k % per_row) + 0.05 * RADIUS * np.sin(1.7 * k)
    z = offset + spacing * ((k // per_row) % per_row) + 0.05 * RADIUS * np.cos(1.3 * k)
    y = 2.0 + spacing * (k // (per_row * per_row))
    return np.c_[x, y, z]


def walls(width: float) -> list[tuple[str, tuple[float, float, float], tuple[float, float, float]]]:
    """The four walls as (name, centre, size): their inner faces at x, z = +-width/2."""
    h, t = width / 2, THICK
    return [
        ("west", (-h - t / 2, TOP / 2, 0.0), (t, TOP, width + 2 * t)),
        ("east", (h + t / 2, TOP / 2, 0.0), (t, TOP, width + 2 * t)),
        ("south", (0.0, TOP / 2, -h - t / 2), (width, TOP, t)),
        ("north", (0.0, TOP / 2, h + t / 2), (width, TOP, t)),
    ]


def scenario_toml(n: int, width: float, steps: int) -> str:
    lines = [
        "[simulation]",
        f'title = "{n} spheres poured into a box"',
        f"dt = {DT}",
        f"steps = {steps}",
        f"restitution = {E}",
        f"gravity = [0, {-G}, 0]",
        'mode = "exact"',
        'contacts = "solve"',
        "",
        "[[static]]",
        'name = "floor"',
        'shape = "plane"',
        "point = [0, 0, 0]",
        "normal = [0, 1, 0]",
        "",
    ]
    for name, centre, size in walls(width):
        lines += [
            "[[static]]",
            f'name = "{name}"',
            'shape = "aabb"',
            f"position = {list(centre)}",
            f"size = {list(size)}",
            "",
        ]
    for i, (x, y, z) in enumerate(layout(n, width)):
        lines += [
            "[[body]]",
            f'name = "s{i}"',
            'shape = "sphere"',
            f"position = [{float(x)!r}, {float(y)!r}, {float(z)!r}]",
            f"radius = {RADIUS}",
            "",
        ]
    return "\n".join(lines)


def outcome(pos: np.ndarray, vel: np.ndarray, width: float) -> dict[str, float]:
    """Kinetic energy per ball, bodies outside the box, deepest overlap / radius."""
    n = len(pos)
    overlap = pair_overlap(pos, RADIUS)
    h = width / 2
    faces = np.r_[RADIUS - pos[:, 1], RADIUS - (pos[:, 0] + h), RADIUS - (h - pos[:, 0])]
    faces = np.r_[faces, RADIUS - (pos[:, 2] + h), RADIUS - (h - pos[:, 2])]
    overlap = max(overlap, float(faces.max()))
    outside = int(np.sum((pos[:, 1] < 0) | (np.abs(pos[:, 0]) > h) | (np.abs(pos[:, 2]) > h)))
    return {"ke_per_ball": 0.5 * float((vel**2).sum()) / n, "outside": outside, "overlap_r": overlap / RADIUS}


# --- collisionlab ---------------------------------------------------------------------------------
def ours_phases(path: Path, steps: int, rest: int, width: float) -> dict[str, Any]:
    from collisionlab.engine.contact_stepper import ContactStepper
    from collisionlab.engine.world import World
    from collisionlab.scenario_file import load_scenario

    world = World(load_scenario(path))
    stepper = world.stepper
    assert isinstance(stepper, ContactStepper)
    n = len(world.position_array)
    world.step(1)  # loads the compiled kernels
    world.step(steps // 2 - 1)
    start = time.perf_counter()
    world.step(steps - steps // 2)
    formed = time.perf_counter() - start
    end = {**outcome(world.position_array, world.velocity_array, width), "asleep": stepper.asleep}
    start = time.perf_counter()
    world.step(rest)
    rested = time.perf_counter() - start
    after = {**outcome(world.position_array, world.velocity_array, width), "asleep": stepper.asleep}
    start = time.perf_counter()
    world.step(rest)
    slept = time.perf_counter() - start
    last = {**outcome(world.position_array, world.velocity_array, width), "asleep": stepper.asleep}
    return {
        "formed_rate": n * (steps - steps // 2) / formed,
        "rest_rate": n * rest / rested,
        "asleep_rate": n * rest / slept,
        "end": end,
        "after": after,
        "last": last,
    }


# --- pybullet -------------------------------------------------------------------------------------
def pybullet_run(n: int, width: float, steps: int, rest: int) -> dict[str, Any]:
    import pybullet as pb

    client = pb.connect(pb.DIRECT)
    pb.setGravity(0, -G, 0, physicsClientId=client)
    pb.setTimeStep(DT, physicsClientId=client)
    restitution = math.sqrt(E)
    frictionless = {"lateralFriction": 0.0, "rollingFriction": 0.0, "spinningFriction": 0.0, "restitution": restitution}
    floor = pb.createCollisionShape(pb.GEOM_PLANE, planeNormal=[0, 1, 0], physicsClientId=client)
    statics = [pb.createMultiBody(0.0, floor, basePosition=[0, 0, 0], physicsClientId=client)]
    for _, centre, size in walls(width):
        box = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=[s / 2 for s in size], physicsClientId=client)
        statics.append(pb.createMultiBody(0.0, box, basePosition=list(centre), physicsClientId=client))
    for wall in statics:
        pb.changeDynamics(wall, -1, **frictionless, physicsClientId=client)
    sphere = pb.createCollisionShape(pb.GEOM_SPHERE, radius=RADIUS, physicsClientId=client)
    ids = []
    for position in layout(n, width).tolist():
        body = pb.createMultiBody(1.0, sphere, basePosition=position, physicsClientId=client)
        pb.changeDynamics(
            body,
            -1,
            **frictionless,
            linearDamping=0.0,
            angularDamping=0.0,
            activationState=pb.ACTIVATION_STATE_ENABLE_SLEEPING,
            physicsClientId=client,
        )
        ids.append(body)

    def state() -> dict[str, Any]:
        pos = np.array([pb.getBasePositionAndOrientation(b, physicsClientId=client)[0] for b in ids])
        vel = np.array([pb.getBaseVelocity(b, physicsClientId=client)[0] for b in ids])
        return outcome(pos, vel, width)

    def go(count: int) -> float:
        start = time.perf_counter()
        for _ in range(count):
            pb.stepSimulation(physicsClientId=client)
        return time.perf_counter() - start

    first = go(steps // 2)
    formed = go(steps - steps // 2)
    end = state()
    rested = go(rest)
    after = state()
    slept = go(rest)
    last = state()
    pb.disconnect(physicsClientId=client)
    return {
        "seconds": first + formed,
        "formed_rate": n * (steps - steps // 2) / formed,
        "rest_rate": n * rest / rested,
        "asleep_rate": n * rest / slept,
        "end": end,
        "after": after,
        "last": last,
    }


def leaves(label: str, seconds: float, end: dict[str, Any], n: int) -> str:
    asleep = f", {end['asleep']} of {n} asleep" if "asleep" in end else ""
    return (f"{label:>12} at {seconds:g} s: kinetic energy {end['ke_per_ball']:.3g} J per ball{asleep}, "
            f"{end['outside']} outside the box, deepest overlap {end['overlap_r']:.3g} of a radius")  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=1000)
    parser.add_argument("--width", type=float, default=10.0)
    parser.add_argument("--steps", type=int, default=500)
    parser.add_argument(
        "--rest", type=int, default=2000, help="steps after STEPS, timed apart, twice (settling, settled)"
    )
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    n, width, steps, rest = args.n, args.width, args.steps, args.rest
    print(f"{n} spheres into a {width:g} m square box, {steps} + {rest} + {rest} steps of {DT} s; "
          f"medians of {args.runs} runs (min-max)")  # fmt: skip
    print(f"machine: {os.cpu_count()} cores, Python {sys.version.split()[0]}")
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "pour.toml"
        path.write_text(scenario_toml(n, width, steps), encoding="utf-8")
        out = Path(folder) / "pour.json"
        ours_command(path, out)  # warm-up: compiles the kernels once if the cache lacks them
        ours = [ours_command(path, out) for _ in range(args.runs)]
        last = json.loads(out.read_text(encoding="utf-8"))["frames"][-1]["bodies"]
        ours_end = outcome(np.array([b["position"] for b in last]), np.array([b["velocity"] for b in last]), width)
        phases = [ours_phases(path, steps, rest, width) for _ in range(args.runs)]
    theirs = [pybullet_run(n, width, steps, rest) for _ in range(args.runs)]
    body_steps = n * steps
    ratio = statistics.median([r["seconds"] for r in theirs]) / statistics.median(ours)
    print(f"whole run (steps 0-{steps})  collisionlab run (command) {spread([body_steps / s / 1e6 for s in ours], 'M')}"
          f"   pybullet stepping {spread([body_steps / r['seconds'] / 1e6 for r in theirs], 'M')} body-steps/s"
          f"   collisionlab / pybullet (medians) {ratio:.2f}x")  # fmt: skip
    for key, label in (
        ("formed_rate", f"steps {steps // 2}-{steps}"),
        ("rest_rate", f"steps {steps}-{steps + rest}"),
        ("asleep_rate", f"steps {steps + rest}-{steps + 2 * rest}"),
    ):
        print(f"{label:>24}  collisionlab {spread([p[key] / 1e6 for p in phases], 'M')}"
              f"   pybullet {spread([r[key] / 1e6 for r in theirs], 'M')} body-steps/s")  # fmt: skip
    print(leaves("collisionlab", steps * DT, {**ours_end, "asleep": phases[-1]["end"]["asleep"]}, n) + " (the command)")
    print(leaves("pybullet", steps * DT, theirs[-1]["end"], n))
    print(leaves("collisionlab", (steps + rest) * DT, phases[-1]["after"], n))
    print(leaves("pybullet", (steps + rest) * DT, theirs[-1]["after"], n))
    print(leaves("collisionlab", (steps + 2 * rest) * DT, phases[-1]["last"], n))
    print(leaves("pybullet", (steps + 2 * rest) * DT, theirs[-1]["last"], n))


if __name__ == "__main__":
    main()
