"""Many-body gas: collisionlab's ParticleWorld against pymunk, pybullet and the naive O(N^2) loop.

One invocation runs the same workload everywhere and prints body-steps per second side by side
with the ratios. The scenario (``collisionlab.particles.gas_scenario``): N equal discs of radius 1
on a lattice, area fraction 0.2 of a square box, seeded Gaussian velocities, dt such that the rms
speed covers 0.1 radius per step, e = 1, no gravity, four static walls.

The workload is the same for every engine: the lattice is first relaxed by ``SETTLE_STEPS``
steps (collisionlab, untimed), and every engine starts from those very positions and velocities,
takes ``WARMUP_STEPS`` untimed steps (buffers, caches), then ``STEPS[n]`` timed steps: the same
number for every engine at a given N, and the same for 10k and 1M, so the scaling figure compares
the same phase of the gas. Each figure is the median of ``repeats`` runs (at least 3), each from a
fresh copy of the start, with the lowest and highest run as the spread.

    python3 tasks.py bench                    # installs pymunk and pybullet, then runs this
    python bench/bench_gas.py --quick         # 1k and 10k only

Not a test: it asserts nothing and prints numbers (recorded in bench/README.md).
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib.util
import math
import platform
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np

from collisionlab.particles import gas_scenario, warm_up
from collisionlab.particles.scenarios import GasScenario
from collisionlab.tolerances import CONTACT_SLOP

SEED = 0
#: Steps that relax the lattice into a gas before anything is timed (about four collisions per body).
SETTLE_STEPS = 200
#: Untimed steps every engine takes from the common start (allocations, caches).
WARMUP_STEPS = 2
#: Timed steps at each N, the same for every engine; 10k and 1M alike so the scaling compares one phase.
STEPS = {1000: 100, 10_000: 20, 100_000: 20, 1_000_000: 20}


def timed(function: Callable[[], Any]) -> tuple[float, Any]:
    start = time.perf_counter()
    result = function()
    return time.perf_counter() - start, result


@dataclasses.dataclass
class Figure:
    """Body-steps per second over several runs: the median and the spread (lowest, highest)."""

    rates: list[float]
    drift: float
    extra: dict[str, float]

    @property
    def median(self) -> float:
        return statistics.median(self.rates)

    def text(self, scale: float, unit: str) -> str:
        return f"{self.median / scale:.3g} {unit} ({min(self.rates) / scale:.3g}-{max(self.rates) / scale:.3g})"


def measure(run: Callable[[], dict[str, float]], repeats: int) -> Figure:
    results = [run() for _ in range(repeats)]
    rates = [r.pop("rate") for r in results]
    drift = results[-1].pop("drift")
    return Figure(rates, drift, results[-1])


def settled(gas: GasScenario) -> GasScenario:
    """The same gas after ``SETTLE_STEPS`` steps: off the lattice, collisions under way."""
    world = gas.world()
    world.step(gas.dt, SETTLE_STEPS)
    return dataclasses.replace(gas, positions=world.positions.copy(), velocities=world.velocities.copy())


# --- collisionlab ---------------------------------------------------------------------------------------
def run_collisionlab(gas: GasScenario, steps: int) -> dict[str, float]:
    world = gas.world()
    world.step(gas.dt, WARMUP_STEPS)  # grid buffers allocated; compile already done by warm_up()
    energy = world.kinetic_energy()
    seconds, report = timed(lambda: world.step(gas.dt, steps))
    return {
        "rate": gas.n * steps / seconds,
        "drift": world.kinetic_energy() / energy - 1.0,
        "collisions_per_body_step": report.body_collisions / (gas.n * steps),
        "bytes": world.nbytes / gas.n,
    }


def _status_kib(key: str) -> int:
    with open("/proc/self/status", encoding="ascii") as status:
        for line in status:
            if line.startswith(key + ":"):
                return int(line.split()[1])
    raise KeyError(key)


def memory_probe(n: int) -> None:
    """Child process: growth of peak resident memory per body while a world of n bodies is made
    and stepped (Linux: the peak is reset first, so the scenario's own temporaries do not count)."""
    gas = gas_scenario(n, 2, SEED)
    warm_up()
    before = _status_kib("VmRSS")
    with open("/proc/self/clear_refs", "w", encoding="ascii") as clear:
        clear.write("5")  # resets VmHWM to the current RSS
    world = gas.world()
    world.step(gas.dt, 20)
    after = _status_kib("VmHWM")
    print(f"{(after - before) * 1024 / n:.1f} {world.nbytes / n:.1f}")


# --- pymunk ------------------------------------------------------------------------------------------
def run_pymunk(gas: GasScenario, steps: int, spatial_hash: bool) -> dict[str, float]:
    import pymunk

    space = pymunk.Space()
    space.gravity = (0.0, 0.0)
    if spatial_hash:
        # As pymunk's docs advise: cells the size of a shape (a disc's diameter), and about ten
        # times as many cells as objects.
        space.use_spatial_hash(2.0 * gas.radius, 10 * gas.n)
    bodies = []
    for (x, y), (vx, vy) in zip(gas.positions.tolist(), gas.velocities.tolist(), strict=True):
        body = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0.0, gas.radius))
        body.position = (x, y)
        body.velocity = (vx, vy)
        shape = pymunk.Circle(body, gas.radius)
        shape.elasticity = 1.0
        shape.friction = 0.0
        space.add(body, shape)
        bodies.append(body)
    side = gas.side
    corners = [(0.0, 0.0), (side, 0.0), (side, side), (0.0, side)]
    for k in range(4):
        wall = pymunk.Segment(space.static_body, corners[k], corners[(k + 1) % 4], 0.0)
        wall.elasticity = 1.0
        wall.friction = 0.0
        space.add(wall)

    def energy() -> float:
        return sum(0.5 * (b.velocity.x**2 + b.velocity.y**2) for b in bodies)

    for _ in range(WARMUP_STEPS):
        space.step(gas.dt)
    start = energy()

    def go() -> None:
        for _ in range(steps):
            space.step(gas.dt)

    seconds, _ = timed(go)
    return {"rate": gas.n * steps / seconds, "drift": energy() / start - 1.0}


# --- pybullet (3D) ----------------------------------------------------------------------------------------
def run_pybullet(gas: GasScenario, steps: int) -> dict[str, float]:
    import pybullet as pb

    client = pb.connect(pb.DIRECT)
    pb.setGravity(0, 0, 0, physicsClientId=client)
    pb.setTimeStep(gas.dt, physicsClientId=client)
    # Configured for an elastic gas, so that its energy stays sane: no Baumgarte push-out
    # (erp = contactERP = 0: by default it turns penetration into velocity, and the gas heats up),
    # and below, contactProcessingThreshold = 0 (no speculative contacts, which close a gap
    # inelastically and cool the gas). With its defaults the energy grows by tens of percent.
    pb.setPhysicsEngineParameter(restitutionVelocityThreshold=0.0, erp=0.0, contactERP=0.0, physicsClientId=client)
    sphere = pb.createCollisionShape(pb.GEOM_SPHERE, radius=gas.radius, physicsClientId=client)
    ids = []
    for position in gas.positions.tolist():
        body = pb.createMultiBody(1.0, sphere, basePosition=position, physicsClientId=client)
        ids.append(body)
    for body, velocity in zip(ids, gas.velocities.tolist(), strict=True):
        pb.resetBaseVelocity(body, velocity, physicsClientId=client)
        pb.changeDynamics(
            body,
            -1,
            restitution=1.0,
            lateralFriction=0.0,
            linearDamping=0.0,
            angularDamping=0.0,
            contactProcessingThreshold=0.0,
            physicsClientId=client,
        )
    half = gas.side / 2.0
    for axis in range(3):
        for sign in (-1.0, 1.0):  # six thick static boxes as walls
            extents = [half + 1.0] * 3
            extents[axis] = 0.5
            centre = [half] * 3
            centre[axis] = half + sign * (half + 0.5)
            shape = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=extents, physicsClientId=client)
            wall = pb.createMultiBody(0.0, shape, basePosition=centre, physicsClientId=client)
            pb.changeDynamics(
                wall, -1, restitution=1.0, lateralFriction=0.0, contactProcessingThreshold=0.0, physicsClientId=client
            )

    def energy() -> float:
        return sum(0.5 * sum(c * c for c in pb.getBaseVelocity(b, physicsClientId=client)[0]) for b in ids)

    for _ in range(WARMUP_STEPS):
        pb.stepSimulation(physicsClientId=client)
    start = energy()

    def go() -> None:
        for _ in range(steps):
            pb.stepSimulation(physicsClientId=client)

    seconds, _ = timed(go)
    drift = energy() / start - 1.0
    pb.disconnect(physicsClientId=client)
    return {"rate": gas.n * steps / seconds, "drift": drift}


# --- the naive pure-Python O(N^2) loop ----------------------------------------------------------------------
def run_naive(gas: GasScenario, steps: int) -> dict[str, float]:
    """What every student writes: lists of floats, all pairs, the same impulse law and walls."""
    px, py = gas.positions[:, 0].tolist(), gas.positions[:, 1].tolist()
    vx, vy = gas.velocities[:, 0].tolist(), gas.velocities[:, 1].tolist()
    n, r, side, dt = gas.n, gas.radius, gas.side, gas.dt
    reach2 = (2 * r) ** 2

    def go() -> None:
        for _ in range(steps):
            for i in range(n):
                px[i] += vx[i] * dt
                py[i] += vy[i] * dt
            for i in range(n):
                for j in range(i + 1, n):
                    dx = px[j] - px[i]
                    dy = py[j] - py[i]
                    d2 = dx * dx + dy * dy
                    if d2 <= reach2:
                        d = math.sqrt(d2) or 1.0
                        nx, ny = dx / d, dy / d
                        vn = (vx[j] - vx[i]) * nx + (vy[j] - vy[i]) * ny
                        if vn < 0.0:
                            jm = -vn  # -(1 + e) vn / (1/m + 1/m) with e = 1, m = 1
                            vx[i] -= jm * nx
                            vy[i] -= jm * ny
                            vx[j] += jm * nx
                            vy[j] += jm * ny
                        push = (2 * r - d + CONTACT_SLOP) / 2
                        px[i] -= nx * push
                        py[i] -= ny * push
                        px[j] += nx * push
                        py[j] += ny * push
            for i in range(n):
                if px[i] < r:
                    px[i], vx[i] = r + CONTACT_SLOP, abs(vx[i])
                elif px[i] > side - r:
                    px[i], vx[i] = side - r - CONTACT_SLOP, -abs(vx[i])
                if py[i] < r:
                    py[i], vy[i] = r + CONTACT_SLOP, abs(vy[i])
                elif py[i] > side - r:
                    py[i], vy[i] = side - r - CONTACT_SLOP, -abs(vy[i])

    def warm() -> None:
        nonlocal steps
        timed_steps, steps = steps, WARMUP_STEPS
        go()
        steps = timed_steps

    warm()
    start = sum(a * a + b * b for a, b in zip(vx, vy, strict=True))
    seconds, _ = timed(go)
    end = sum(a * a + b * b for a, b in zip(vx, vy, strict=True))
    return {"rate": n * steps / seconds, "drift": end / start - 1.0}


# --- design measurements: Jacobi impulses, sort-and-sweep ------------------------------------------------------
def jacobi_drift(gas: GasScenario, steps: int) -> tuple[float, float]:
    """Energy drift of the same gas when every impulse of a step is computed from the velocities
    before the step and summed (Jacobi), against the world's sequential pass. Plain numpy on the
    public broad phase (``grid_pairs``); walls reflect the velocity component (energy-exact)."""
    from collisionlab.particles import grid_pairs

    pos, vel = gas.positions.copy(), gas.velocities.copy()
    r, side = gas.radius, gas.side
    start = float(np.sum(vel**2))
    for _ in range(steps):
        pos += vel * gas.dt
        pairs = grid_pairs(pos, r)
        a, b = pairs[:, 0], pairs[:, 1]
        delta = pos[b] - pos[a]
        dist = np.sqrt(np.sum(delta**2, axis=1))
        n = delta / np.where(dist > 0.0, dist, 1.0)[:, None]
        vn = np.sum((vel[b] - vel[a]) * n, axis=1)
        j = np.where(vn < 0.0, -vn, 0.0)  # e = 1, unit masses: -(1 + e) vn / 2
        dv = np.zeros_like(vel)
        np.add.at(dv, a, -n * j[:, None])
        np.add.at(dv, b, n * j[:, None])
        vel += dv
        push = (2.0 * r - dist + CONTACT_SLOP) / 2.0
        np.add.at(pos, a, -n * push[:, None])
        np.add.at(pos, b, n * push[:, None])
        low, high = pos < r, pos > side - r
        vel[low], vel[high] = np.abs(vel[low]), -np.abs(vel[high])
        np.clip(pos, r + CONTACT_SLOP, side - r - CONTACT_SLOP, out=pos)
    world = gas.world()
    world.step(gas.dt, steps)
    return float(np.sum(vel**2)) / start - 1.0, world.kinetic_energy() * 2.0 / start - 1.0


def sweep_vs_grid(n: int) -> tuple[float, float]:
    """Seconds to find all pairs once: sort-and-sweep along x (numba) against the grid."""
    import numba

    @numba.njit(cache=False)
    def sweep(pos: Any, radius: float) -> int:
        order = np.argsort(pos[:, 0])
        found = 0
        for u in range(order.shape[0]):
            i = order[u]
            for w in range(u + 1, order.shape[0]):
                j = order[w]
                if pos[j, 0] - pos[i, 0] > 2.0 * radius:
                    break
                dx = pos[j, 0] - pos[i, 0]
                dy = pos[j, 1] - pos[i, 1]
                if math.sqrt(dx * dx + dy * dy) <= 2.0 * radius:
                    found += 1
        return found

    from collisionlab.particles import grid_pairs

    gas = gas_scenario(n, 2, SEED)
    world = gas.world()
    world.step(gas.dt, 200)  # off the lattice
    pos = world.positions
    sweep(pos, 1.0)
    grid_pairs(pos, 1.0)
    reps = max(3, 200_000 // n)
    t_sweep, _ = timed(lambda: [sweep(pos, 1.0) for _ in range(reps)])
    t_grid, _ = timed(lambda: [grid_pairs(pos, 1.0) for _ in range(reps)])
    return t_sweep / reps, t_grid / reps


# --- scaling: cost per body-step at 1M against 10k ----------------------------------------------------------
def scaling(pairs: int = 5) -> list[float]:
    """Cost per body-step at 1M over that at 10k, measured in interleaved pairs (10k, then 1M), so a
    change in the machine's load between the two sizes does not bias the ratio: one ratio per pair.
    Both sizes start from their settled gas and time the same steps (the same phase)."""
    small, large = settled(gas_scenario(10_000, 2, SEED)), settled(gas_scenario(1_000_000, 2, SEED))
    ratios = []
    for _ in range(pairs):
        at_10k = run_collisionlab(small, STEPS[10_000])["rate"]
        at_1m = run_collisionlab(large, STEPS[1_000_000])["rate"]
        ratios.append(at_10k / at_1m)
    return ratios


# --- main ------------------------------------------------------------------------------------------------
def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="1k and 10k only, no 1M, no design figures")
    parser.add_argument("--sizes", help="comma-separated N to run (e.g. 10000,100000), no design figures")
    parser.add_argument("--scaling-only", action="store_true", help="only the 1M-against-10k cost ratio")
    parser.add_argument("--memory-probe", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.memory_probe:
        memory_probe(args.memory_probe)
        return
    have_pymunk = importlib.util.find_spec("pymunk") is not None
    have_pybullet = importlib.util.find_spec("pybullet") is not None
    versions = [f"numpy {np.__version__}"]
    for name in ("numba", "pymunk", "pybullet"):
        if importlib.util.find_spec(name) is not None:
            versions.append(f"{name} {_version(name)}")
    print(
        f"# {time.strftime('%Y-%m-%d %H:%M')}, {platform.processor() or platform.machine()}, "
        f"{platform.python_implementation()} {platform.python_version()}, {', '.join(versions)}"
    )
    seconds, compiled = timed(warm_up)
    how = "compiled or loaded from cache" if compiled else "numpy only"
    print(f"# numba kernels ready in {seconds:.2f} s ({how})")
    print(
        f"# every engine: start after {SETTLE_STEPS} settling steps, {WARMUP_STEPS} untimed steps, then the timed steps"
    )
    print("# body-steps/s: median of the runs (lowest-highest)")
    if args.scaling_only:
        _print_scaling()
        return
    sizes = [1000, 10_000] if args.quick else [1000, 10_000, 100_000, 1_000_000]
    if args.sizes:
        sizes = [int(n) for n in args.sizes.split(",")]
    ours_by_n: dict[int, Figure] = {}
    for n in sizes:
        gas = settled(gas_scenario(n, 2, SEED))
        steps = STEPS[n]
        repeats = 5 if n <= 10_000 else 3
        ours = measure(partial(run_collisionlab, gas, steps), repeats)
        ours_by_n[n] = ours
        line = [f"N = {n:,} (2D), {steps} steps, {repeats} runs", f"  collisionlab  {ours.text(1e6, 'M')}"]
        per_body_step = ours.extra["collisions_per_body_step"]
        line.append(f"                drift {ours.drift:.1e}, collisions per body-step {per_body_step:.4f}")
        best = 0.0
        if have_pymunk and n <= 100_000:
            for label, spatial_hash in (("pymunk hash", True), ("pymunk tree", False)):
                theirs = measure(partial(run_pymunk, gas, steps, spatial_hash), 3)
                best = max(best, theirs.median)
                line.append(f"  {label:<13} {theirs.text(1e6, 'M')}  drift {theirs.drift:.1e}")
            line.append(f"  collisionlab / best pymunk (medians): {ours.median / best:.1f}x")
        if n == 1000:
            naive = measure(partial(run_naive, gas, steps), 3)
            line.append(f"  naive         {naive.text(1e3, 'k')}  drift {naive.drift:.1e}")
            line.append(f"  collisionlab / naive (medians): {ours.median / naive.median:.0f}x")
        print("\n".join(line), flush=True)
    if 1_000_000 in ours_by_n:
        _print_scaling()
        probe = subprocess.run(
            [sys.executable, __file__, "--memory-probe", "1000000"], capture_output=True, text=True, check=True
        )
        rss, held = probe.stdout.split()
        print(f"# memory at 1M bodies: {rss} bytes/body peak RSS growth, {held} bytes/body of arrays held")
    if have_pybullet:
        for n in [1000, 10_000]:
            gas = settled(gas_scenario(n, 3, SEED))
            steps = STEPS[n]
            ours = measure(partial(run_collisionlab, gas, steps), 3)
            bullet = measure(partial(run_pybullet, gas, steps), 3)
            print(
                f"N = {n:,} (3D), {steps} steps, 3 runs\n"
                f"  collisionlab  {ours.text(1e6, 'M')}  drift {ours.drift:.1e}\n"
                f"  pybullet      {bullet.text(1e6, 'M')}  drift {bullet.drift:.1e}\n"
                f"  collisionlab / pybullet (medians): {ours.median / bullet.median:.1f}x",
                flush=True,
            )
    else:
        print("# pybullet not installed: no 3D comparison")
    if not (args.quick or args.sizes):
        jacobi, sequential = jacobi_drift(gas_scenario(10_000, 2, SEED), 1000)
        print(f"# energy drift, 10k discs, 1000 steps: sequential (the world) {sequential:.1e}, Jacobi {jacobi:.1e}")
        for n in (10_000, 100_000):
            t_sweep, t_grid = sweep_vs_grid(n)
            print(f"# all pairs once at N = {n:,}: sort-and-sweep {t_sweep * 1e3:.2f} ms, grid {t_grid * 1e3:.2f} ms")


def _print_scaling() -> None:
    ratios = scaling()
    print(
        f"# cost per body-step at 1M / at 10k, {len(ratios)} interleaved pairs, {STEPS[1_000_000]} steps each from the "
        f"settled gas: median {statistics.median(ratios):.2f} ({min(ratios):.2f}-{max(ratios):.2f})",
        flush=True,
    )


def _version(name: str) -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(name)
    except PackageNotFoundError:
        return "?"


if __name__ == "__main__":
    main()
