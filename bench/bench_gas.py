"""Many-body gas: collisionlab's ParticleWorld against pymunk, pybullet and the naive O(N^2) loop.

One invocation runs the same scenario everywhere and prints body-steps per second side by side
with the ratios. The scenario (``collisionlab.particles.gas_scenario``): N equal discs of radius 1
on a lattice, area fraction 0.2 of a square box, seeded Gaussian velocities, dt such that the rms
speed covers 0.1 radius per step, e = 1, no gravity, four static walls.

    pip install -e '.[fast,bench]'   # numba, pymunk; pybullet optional: pip install pybullet
    python bench/bench_gas.py                 # everything (about 5 minutes on 2 cores)
    python bench/bench_gas.py --quick         # 1k and 10k only

Not a test: it asserts nothing and prints numbers (recorded in bench/README.md).
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import platform
import subprocess
import sys
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from collisionlab.particles import gas_scenario, warm_up
from collisionlab.particles import numpy_kernels as nk
from collisionlab.particles.broadphase import half_stencil, max_cells
from collisionlab.particles.scenarios import GasScenario
from collisionlab.tolerances import CONTACT_SLOP

SEED = 0


def timed(function: Callable[[], Any]) -> tuple[float, Any]:
    start = time.perf_counter()
    result = function()
    return time.perf_counter() - start, result


# --- collisionlab ---------------------------------------------------------------------------------------
def run_collisionlab(gas: GasScenario, steps: int) -> dict[str, float]:
    world = gas.world()
    world.step(gas.dt, 2)  # grid buffers allocated; compile already done by warm_up()
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
        space.use_spatial_hash(2.0 * gas.radius, max(1000, 4 * gas.n))
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
    pb.setPhysicsEngineParameter(restitutionVelocityThreshold=0.0, physicsClientId=client)
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
            pb.changeDynamics(wall, -1, restitution=1.0, lateralFriction=0.0, physicsClientId=client)

    def energy() -> float:
        return sum(0.5 * sum(c * c for c in pb.getBaseVelocity(b, physicsClientId=client)[0]) for b in ids)

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

    start = sum(a * a + b * b for a, b in zip(vx, vy, strict=True))
    seconds, _ = timed(go)
    end = sum(a * a + b * b for a, b in zip(vx, vy, strict=True))
    return {"rate": n * steps / seconds, "drift": end / start - 1.0}


# --- design measurements: Jacobi impulses, sort-and-sweep ------------------------------------------------------
def jacobi_drift(gas: GasScenario, steps: int) -> tuple[float, float]:
    """Energy drift of the same gas when every impulse of a step is computed from the velocities
    before the step and summed (Jacobi), against the world's sequential pass; numpy, plain."""
    pos, vel = gas.positions.copy(), gas.velocities.copy()
    rad = np.full(gas.n, gas.radius)
    world = gas.world()
    normals, offsets = world.walls
    stencil, cells = half_stencil(2), max_cells(gas.n)
    start = float(np.sum(vel**2))
    for _ in range(steps):
        pos += vel * gas.dt
        ca, cb, _ = nk.find_contacts(pos, rad, normals, offsets, 2.0 * gas.radius, cells, stencil)
        pair = cb >= 0
        a, b = ca[pair], cb[pair]
        delta = pos[b] - pos[a]
        dist = np.sqrt(np.sum(delta**2, axis=1))
        n = delta / dist[:, None]
        vn = np.sum((vel[b] - vel[a]) * n, axis=1)
        j = np.where(vn < 0.0, -vn, 0.0)  # e = 1, unit masses: -(1 + e) vn / 2
        dv = np.zeros_like(vel)
        np.add.at(dv, a, -n * j[:, None])
        np.add.at(dv, b, n * j[:, None])
        wall = ~pair
        wa, wn = ca[wall], normals[-1 - cb[wall]]
        wv = np.sum(vel[wa] * wn, axis=1)
        np.add.at(dv, wa, -wn * np.where(wv < 0.0, 2.0 * wv, 0.0)[:, None])
        vel += dv
        depth = 2.0 * gas.radius - dist + CONTACT_SLOP
        np.add.at(pos, a, -n * (depth / 2)[:, None])
        np.add.at(pos, b, n * (depth / 2)[:, None])
        np.clip(pos, gas.radius + CONTACT_SLOP, gas.side - gas.radius - CONTACT_SLOP, out=pos)
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


# --- main ------------------------------------------------------------------------------------------------
def steps_for(n: int, body_steps: float, lowest: int = 20) -> int:
    return max(lowest, int(body_steps / n))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="1k and 10k only, no 1M, no design figures")
    parser.add_argument("--memory-probe", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.memory_probe:
        memory_probe(args.memory_probe)
        return
    have_pymunk = importlib.util.find_spec("pymunk") is not None
    have_pybullet = importlib.util.find_spec("pybullet") is not None
    print(
        f"# {time.strftime('%Y-%m-%d')}, {platform.processor() or platform.machine()}, "
        f"{platform.python_implementation()} {platform.python_version()}, numpy {np.__version__}"
    )
    seconds, compiled = timed(warm_up)
    how = "compiled or loaded from cache" if compiled else "numpy only"
    print(f"# numba kernels ready in {seconds:.2f} s ({how})")
    sizes = [1000, 10_000] if args.quick else [1000, 10_000, 100_000, 1_000_000]
    rows = []
    print(
        f"{'N':>9} {'collisionlab':>14} {'pymunk hash':>13} {'pymunk tree':>13} {'naive':>10} "
        f"{'vs best pymunk':>15} {'vs naive':>9} {'drift cl':>10} {'drift pymunk':>13}"
    )
    for n in sizes:
        gas = gas_scenario(n, 2, SEED)
        ours = run_collisionlab(gas, steps_for(n, 3e7 if n < 1_000_000 else 6e7))
        hashed = tree = naive = None
        if have_pymunk and n <= 100_000:
            hashed = run_pymunk(gas, steps_for(n, 3e6, 10), spatial_hash=True)
            tree = run_pymunk(gas, steps_for(n, 3e6, 10), spatial_hash=False)
        if n == 1000:
            naive = run_naive(gas, 3)
        best = max((r["rate"] for r in (hashed, tree) if r), default=math.nan)
        drift_pymunk = hashed["drift"] if hashed else math.nan
        rows.append((n, ours, hashed, tree, naive))

        def fmt(result: dict[str, float] | None) -> str:
            return f"{result['rate'] / 1e6:10.3f} M" if result else f"{'-':>12}"

        naive_rate = f"{naive['rate'] / 1e3:7.2f} k" if naive else "-"
        versus_pymunk = f"{ours['rate'] / best:14.1f}x" if not math.isnan(best) else f"{'-':>15}"
        drift_text = f"{drift_pymunk:13.1e}" if not math.isnan(drift_pymunk) else f"{'-':>13}"
        versus_naive = f"{ours['rate'] / naive['rate']:8.0f}x" if naive else "-"
        print(
            f"{n:>9,} {fmt(ours):>14} {fmt(hashed):>13} {fmt(tree):>13} {naive_rate:>10} "
            f"{versus_pymunk} {versus_naive:>9} {ours['drift']:10.1e} {drift_text}",
            flush=True,
        )
    by_n = {row[0]: row[1] for row in rows}
    if 1_000_000 in by_n:
        ratio = by_n[10_000]["rate"] / by_n[1_000_000]["rate"]
        print(f"# cost per body-step at 1M / at 10k: {ratio:.2f}")
        probe = subprocess.run(
            [sys.executable, __file__, "--memory-probe", "1000000"], capture_output=True, text=True, check=True
        )
        rss, held = probe.stdout.split()
        print(f"# memory at 1M bodies: {rss} bytes/body peak RSS growth, {held} bytes/body of arrays held")
    print(f"# collisions per body-step at 100k: {by_n.get(100_000, by_n[10_000])['collisions_per_body_step']:.4f}")
    if have_pybullet:
        print(
            f"{'N (3D)':>9} {'collisionlab':>14} {'pybullet':>13} {'ratio':>9} {'drift cl':>10} {'drift pybullet':>15}"
        )
        for n in [1000, 10_000]:
            gas = gas_scenario(n, 3, SEED)
            ours = run_collisionlab(gas, steps_for(n, 3e7))
            bullet = run_pybullet(gas, steps_for(n, 1e6, 10))
            print(
                f"{n:>9,} {ours['rate'] / 1e6:12.3f} M {bullet['rate'] / 1e6:11.3f} M "
                f"{ours['rate'] / bullet['rate']:8.1f}x {ours['drift']:10.1e} {bullet['drift']:15.1e}",
                flush=True,
            )
    else:
        print("# pybullet not installed: no 3D comparison")
    if not args.quick:
        jacobi, sequential = jacobi_drift(gas_scenario(10_000, 2, SEED), 1000)
        print(f"# energy drift, 10k discs, 1000 steps: sequential (the world) {sequential:.1e}, Jacobi {jacobi:.1e}")
        for n in (10_000, 100_000):
            t_sweep, t_grid = sweep_vs_grid(n)
            print(f"# all pairs once at N = {n:,}: sort-and-sweep {t_sweep * 1e3:.2f} ms, grid {t_grid * 1e3:.2f} ms")


if __name__ == "__main__":
    main()
