"""``ParticleWorld``: many balls (discs in 2D, spheres in 3D) in a box of static walls, stepped fast.

A thin front of the engine for gases: the balls become a structure of arrays and each step is
the engine's Forward Euler stepper (:mod:`collisionlab.engine.step_kernels`, compiled by numba),
the same kernels, contact law and order as every other world: integrate, grid broad phase,
contacts deepest first with ties broken by geometry, sequential impulses (``j = -(1 + e) v_n /
(1/m_a + 1/m_b)``, e = 0 below the rest speed), push-apart to a gap of ``CONTACT_SLOP``. The box
and ``planes`` are one-sided walls: the inside is ``n . x >= c`` and a ball past a wall is pushed
back in, never out. No events are recorded here (a gas has millions); :meth:`step` counts them.

Order independence: nothing in a step depends on the order in which bodies were given (contacts
are ordered by depth and positions, never by index), so permuting the bodies permutes the result
exactly. A sequential pass (Gauss-Seidel) was chosen over summing every impulse from the
pre-step velocities (Jacobi): each two-body impulse with ``e = 1`` conserves kinetic energy
exactly up to rounding, while a Jacobi sum over a ball touching two others at once does not.

Limitation: this is a collision (event) model, not a contact solver with accumulated impulses.
A tall heap under gravity with ``e`` well below 1 keeps visible overlaps (``bench/README.md``);
dilute and dense gases, and short stacks, are fine.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..engine import pair_separation, step_kernels
from ..engine.params import DEFAULT_PASSES, WorldParams
from ..engine.state import BodyArrays, StaticArrays
from ..engine.stepper import EulerStepper
from ..errors import InvalidInputError
from ..validate import finite_number, non_negative, positive, whole_number
from .backend import engine_kernels, pick_backend
from .broadphase import grid_pairs

__all__ = ["DEFAULT_PASSES", "ParticleWorld", "Progress", "StepReport", "warm_up"]

FloatArray = NDArray[np.float64]

#: ``progress(steps_done, steps_total)``, called by :meth:`ParticleWorld.step` between chunks.
Progress = Callable[[int, int], None]

#: Calls of ``progress`` per :meth:`ParticleWorld.step` at most (each call ends a compiled chunk).
_PROGRESS_CHUNKS = 100


@dataclass(frozen=True)
class StepReport:
    """What one call of :meth:`ParticleWorld.step` did."""

    steps: int
    #: Two-body impulses applied (pairs found approaching).
    body_collisions: int
    #: Wall impulses applied.
    wall_collisions: int


def _matrix(value: object, field: str, n: int | None = None) -> FloatArray:
    try:
        array = np.array(value, dtype=np.float64, order="C", ndmin=2)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(field, "must be an array of numbers") from exc
    if array.ndim != 2 or array.shape[1] not in (2, 3) or array.shape[0] == 0:
        raise InvalidInputError(field, "must have shape (n, 2) or (n, 3) with n >= 1", got=array.shape)
    if n is not None and array.shape[0] != n:
        raise InvalidInputError(field, f"must have one row per body ({n})", got=array.shape)
    if not np.all(np.isfinite(array)):
        raise InvalidInputError(field, "must be finite numbers")
    return array


def _per_body(value: object, field: str, n: int, allow_inf: bool = False) -> FloatArray:
    try:
        array = np.array(np.broadcast_to(np.asarray(value, dtype=np.float64), (n,)), order="C")
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(field, f"must be one number or one per body ({n})") from exc
    ok = (array > 0.0) & (np.isfinite(array) | (allow_inf & (array == math.inf)))
    if not np.all(ok):
        bad = array[~ok][0]
        raise InvalidInputError(field, "must be > 0" + (" (math.inf: static)" if allow_inf else ""), got=float(bad))
    return array


def _vector(value: object, field: str, dim: int) -> FloatArray:
    try:
        array = np.array(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(field, f"must be {dim} numbers") from exc
    if array.shape != (dim,) or not np.all(np.isfinite(array)):
        raise InvalidInputError(field, f"must be {dim} finite numbers", got=tuple(array.tolist()))
    return array


class ParticleWorld:
    """N balls of per-body radius, mass and velocity, with static walls, restitution ``e`` and
    optional gravity. See the module docstring for the step's order and its laws.

    ``box=(lo, hi)`` adds the ``2 * dim`` walls of an axis-aligned box; ``planes`` adds walls
    ``(normal, c)`` whose inside is ``normal . x >= c`` (the normal is normalised). ``radii`` and
    ``masses`` are one number or one per body; ``math.inf`` is a static (kinematic) body, moved
    by its velocity only. ``backend`` is ``"auto"`` (numba), ``"numba"`` or ``"python"`` (the
    same kernels run as Python: slow, for small worlds and tests).

    >>> world = ParticleWorld([[0, 0], [3, 0]], [[1, 0], [-1, 0]], radii=1.0, box=((-5, -5), (8, 5)))
    >>> world.step(0.5, steps=2)   # they meet after 0.5 and swap velocities (equal masses, e = 1)
    StepReport(steps=2, body_collisions=1, wall_collisions=0)
    >>> world.velocities.tolist()
    [[-1.0, 0.0], [1.0, 0.0]]
    """

    def __init__(
        self,
        positions: object,
        velocities: object,
        radii: object = 1.0,
        masses: object = 1.0,
        *,
        box: tuple[Sequence[float], Sequence[float]] | None = None,
        planes: Sequence[tuple[Sequence[float], float]] = (),
        restitution: float = 1.0,
        gravity: Sequence[float] | None = None,
        passes: int = DEFAULT_PASSES,
        backend: str = "auto",
        params: WorldParams | None = None,
    ) -> None:
        pos = _matrix(positions, "positions")
        n, dim = pos.shape
        vel = _matrix(velocities, "velocities", n)
        if vel.shape[1] != dim:
            raise InvalidInputError("velocities", f"must have {dim} columns like positions", got=vel.shape)
        rad = _per_body(radii, "radii", n)
        ima = 1.0 / _per_body(masses, "masses", n, allow_inf=True)
        e = non_negative(restitution, "restitution")  # > 1 is allowed: it adds energy (postlab Q4)
        g = np.zeros(dim) if gravity is None else _vector(gravity, "gravity", dim)
        normals, offsets = self._walls(box, planes, dim, float(rad.max()))
        self._params = params or WorldParams(passes=whole_number(passes, "passes"))
        self._backend = pick_backend(backend)
        self._dim = int(dim)
        pos3 = np.zeros((n, 3))
        pos3[:, :dim] = pos
        vel3 = np.zeros((n, 3))
        vel3[:, :dim] = vel
        kind = np.full(n, pair_separation.BALL_2D if dim == 2 else pair_separation.BALL_3D, np.int64)
        ext = np.repeat(rad[:, None], 3, axis=1)
        bodies = BodyArrays(kind, pos3, vel3, ext, ima, np.full(n, math.nan), np.arange(n, dtype=np.int64))
        walls = normals.shape[0]
        points = np.zeros((walls, 3))
        points[:, :dim] = normals * offsets[:, None]
        units = np.zeros((walls, 3))
        units[:, :dim] = normals
        statics = StaticArrays(
            np.full(walls, pair_separation.STATIC_WALL, np.int64), points, units, np.full(walls, math.nan)
        )
        gravity3 = np.zeros(3)
        gravity3[:dim] = g
        self._stepper = EulerStepper(bodies, statics, int(dim), gravity3, self._params, record_events=False)
        # Views of the stepper's arrays (the kernels change them in place).
        self._pos, self._vel, self._ext, self._ima, self._ids = (
            bodies.pos,
            bodies.vel,
            bodies.ext,
            bodies.ima,
            bodies.ids,
        )
        self._planes_n, self._planes_c = normals, offsets
        self._gravity = gravity3
        self._e = e
        self._time = 0.0
        self._steps = 0

    @staticmethod
    def _walls(
        box: tuple[Sequence[float], Sequence[float]] | None,
        planes: Sequence[tuple[Sequence[float], float]],
        dim: int,
        largest_radius: float,
    ) -> tuple[FloatArray, FloatArray]:
        normals: list[FloatArray] = []
        offsets: list[float] = []
        if box is not None:
            try:
                lo_raw, hi_raw = box
            except (TypeError, ValueError) as exc:
                raise InvalidInputError("box", "must be a pair (lo, hi) of corners") from exc
            lo = _vector(lo_raw, "box", dim)
            hi = _vector(hi_raw, "box", dim)
            if not np.all(hi - lo > 2.0 * largest_radius):
                raise InvalidInputError("box", "must be wider than the largest diameter on every axis")
            for k in range(dim):
                axis = np.zeros(dim)
                axis[k] = 1.0
                normals += [axis, -axis]
                offsets += [float(lo[k]), -float(hi[k])]
        for index, plane in enumerate(planes):
            field = f"planes[{index}]"
            try:
                normal_raw, offset_raw = plane
            except (TypeError, ValueError) as exc:
                raise InvalidInputError(field, "must be a pair (normal, offset)") from exc
            normal = _vector(normal_raw, field, dim)
            length = float(np.sqrt(np.sum(normal * normal)))
            if length == 0.0:
                raise InvalidInputError(field, "normal must not be zero")
            normals.append(normal / length)
            offsets.append(finite_number(offset_raw, field) / length)
        return (
            np.array(normals, dtype=np.float64, order="C").reshape(-1, dim),
            np.array(offsets, dtype=np.float64),
        )

    def __repr__(self) -> str:
        """Counts and settings, never the arrays.

        >>> ParticleWorld([[0, 0], [3, 0]], [[1, 0], [-1, 0]], radii=1.0, box=((-5, -5), (8, 5)), backend="python")
        <ParticleWorld: 2 discs in 2D, 4 walls, e = 1, gravity off, t = 0 s after 0 steps, backend python>
        """
        kind = ("disc" if self._dim == 2 else "sphere") + ("" if self.n == 1 else "s")
        walls = int(self._planes_n.shape[0])
        gravity = "on" if np.any(self._gravity != 0.0) else "off"
        return (
            f"<ParticleWorld: {self.n:,} {kind} in {self._dim}D, {walls} wall{'' if walls == 1 else 's'}, "
            f"e = {self._e:g}, gravity {gravity}, t = {self._time:g} s after {self._steps:,} steps, "
            f"backend {self._backend}>"
        )

    # --- read-only views, in the order the bodies were given ---------------------------------
    def _unsorted(self, stored: NDArray[np.float64]) -> NDArray[np.float64]:
        out = np.empty_like(stored)
        out[self._ids] = stored
        return out[:, : self._dim] if out.ndim == 2 else out

    @property
    def n(self) -> int:
        return int(self._pos.shape[0])

    @property
    def dim(self) -> int:
        return self._dim

    @property
    def backend(self) -> str:
        """``"numba"`` or ``"python"``."""
        return self._backend

    @property
    def positions(self) -> FloatArray:
        """A copy, shape ``(n, dim)``, in the order the bodies were given."""
        return self._unsorted(self._pos)

    @property
    def velocities(self) -> FloatArray:
        """A copy, shape ``(n, dim)``, in the order the bodies were given."""
        return self._unsorted(self._vel)

    @property
    def radii(self) -> FloatArray:
        return self._unsorted(self._ext[:, 0].copy())

    @property
    def masses(self) -> FloatArray:
        """``1 / (1 / m)`` of the given masses (``math.inf`` for static bodies)."""
        with np.errstate(divide="ignore"):
            return self._unsorted(1.0 / self._ima)

    @property
    def walls(self) -> tuple[FloatArray, FloatArray]:
        """``(normals, offsets)``: wall ``w`` keeps bodies where ``normals[w] . x >= offsets[w]``."""
        return self._planes_n.copy(), self._planes_c.copy()

    @property
    def restitution(self) -> float:
        return self._e

    @property
    def gravity(self) -> FloatArray:
        return self._gravity.copy()

    @property
    def time(self) -> float:
        """Simulated time so far: the sum of ``dt * steps`` over the calls of :meth:`step`."""
        return self._time

    @property
    def steps_taken(self) -> int:
        return self._steps

    @property
    def nbytes(self) -> int:
        """Bytes of every array the world holds (state, scratch, grid and contact buffers)."""
        return self._stepper.nbytes()

    def kinetic_energy(self) -> float:
        """``sum(m |v|^2) / 2`` over bodies of finite mass."""
        finite = self._ima > 0.0
        vel = self._vel[finite]
        speed2 = np.einsum("ij,ij->i", vel, vel)
        return float(0.5 * np.sum(speed2 / self._ima[finite]))

    def momentum(self) -> FloatArray:
        """``sum(m v)`` over bodies of finite mass."""
        finite = self._ima > 0.0
        total = np.sum(self._vel[finite] / self._ima[finite, None], axis=0)
        return np.asarray(total[: self._dim], np.float64)

    def overlapping_pairs(self) -> NDArray[np.int64]:
        """Pairs ``(i, j)``, ``i < j``, of bodies touching now (indices as given), rows sorted."""
        return grid_pairs(self.positions, self.radii, backend=self._backend)

    # --- stepping -----------------------------------------------------------------------------
    def step(self, dt: float, steps: int = 1, progress: Progress | None = None) -> StepReport:
        """Advance ``steps`` steps of ``dt`` each (one compiled call, or one per chunk of about
        1/100 of the run when ``progress`` is given, called as ``progress(done, steps)``)."""
        dt = positive(dt, "dt")
        steps = whole_number(steps, "steps", minimum=0)
        ledger = np.zeros(step_kernels.LEDGER_SIZE)
        chunk = steps if progress is None else max(1, -(-steps // _PROGRESS_CHUNKS))
        done = 0
        while done < steps:
            count = min(chunk, steps - done)
            self._run(dt, count, ledger)
            done += count
            self._steps += count
            self._time += dt * count
            if progress is not None:
                progress(done, steps)
        return StepReport(steps, int(ledger[5]), int(ledger[6]))

    def _run(self, dt: float, steps: int, ledger: NDArray[np.float64]) -> None:
        before = self._stepper.ledger.copy()  # the stepper keeps totals; this call's part
        self._stepper.advance(engine_kernels(self._backend), dt, self._e, self._steps, steps)
        ledger += self._stepper.ledger - before


def warm_up() -> bool:
    """Compile the numba kernels now (or load them from numba's on-disk cache, which takes well
    under a second), so that a timed run does not include the compile. Returns True."""
    world = ParticleWorld(
        np.array([[0.0, 0.0], [1.5, 0.0]]),
        np.array([[1.0, 0.0], [-1.0, 0.0]]),
        1.0,
        box=((-3.0, -3.0), (3.0, 3.0)),
        backend="numba",
    )
    world.step(0.1, steps=2)
    world.overlapping_pairs()
    return True
