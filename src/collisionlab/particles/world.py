"""``ParticleWorld``: many balls (discs in 2D, spheres in 3D) in a box of static walls, stepped fast.

The state is a structure of float64 arrays: positions and velocities ``(n, dim)``, radii and
inverse masses ``(n,)``. A step is, in this fixed order:

1. forward Euler: ``x += v dt``, then ``v += g dt`` (bodies of finite mass);
2. broad phase on a uniform grid (:mod:`collisionlab.particles.broadphase`), narrow phase: two
   balls touch when ``|x_b - x_a| <= r_a + r_b``, a ball touches a wall ``n . x >= c`` when
   ``n . x - c <= r`` (Ericson, *Real-Time Collision Detection*, 4.3.1 and 5.2.2); the impulse
   solver also gets pairs within ``SOLVER_MARGIN`` of touching (see tolerances.py: balls left
   ``CONTACT_SLOP`` apart by push-apart stay in contact, so a resting stack stays supported);
3. the contacts are put in one order that depends on geometry only: deepest first, ties broken by
   positions (lexicographically), body pairs before wall contacts, then the wall's number;
4. impulses in that order, each computed from the velocities left by the ones before, with the
   scalar core's law (:func:`collisionlab.resolution.resolve_collision`): ``n`` from a to b,
   ``v_n = (v_b - v_a) . n``, nothing if ``v_n >= 0``, else ``j = -(1 + e) v_n / (1/m_a + 1/m_b)``,
   ``v_a -= (j/m_a) n``, ``v_b += (j/m_b) n``; a wall: ``v -= (1 + e)(v . n) n`` if ``v . n < 0``
   (lab eq. 24). The sweep is repeated while it still applies an impulse, at most ``passes`` times;
5. push-apart in that order, from current positions: a pair still overlapping by ``d >= 0`` moves
   apart by ``d + CONTACT_SLOP`` shared in inverse proportion to mass
   (:func:`collisionlab.resolution.separate`), a ball touching a wall moves out to ``CONTACT_SLOP``
   from it; repeated like the impulses; finally every body touched is put back inside every wall.

A pair (or a ball and a wall) that is the only contact of its bodies gets exactly the scalar
core's single impulse and push-apart (a second sweep finds it separating), which the tests check
to 1e-12. Gravity does not act on static bodies (mass ``math.inf``).

Order independence: nothing in a step depends on the order in which bodies were given (step 3
uses positions, never indices), so permuting the bodies permutes the result exactly. A sequential
pass (Gauss-Seidel) was chosen over summing every impulse from the pre-step velocities (Jacobi):
each two-body impulse with ``e = 1`` conserves kinetic energy exactly up to rounding, while a
Jacobi sum over a ball touching two others at once does not: over 1000 steps of 10,000 discs the
world's kinetic energy moved by 0 (to rounding), a Jacobi variant's by -8% (``bench/README.md``).

Limitation: this is a collision (event) model, not a contact solver with accumulated impulses.
A tall heap under gravity with ``e`` well below 1 keeps visible overlaps (measured on 300 discs at
area fraction 0.45, g = 1, e = 0: mean overlap of touching pairs about 0.3 radius); dilute and
dense gases, and short stacks, are fine.

Coincident centres use ``FALLBACK_NORMAL`` from the body whose position comes first; two bodies
at exactly the same place are ordered by storage, the one case where order can matter.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidInputError
from ..tolerances import SOLVER_MARGIN
from ..validate import finite_number, non_negative, positive, whole_number
from . import numpy_kernels
from .backend import compiled_kernels, pick_backend
from .broadphase import grid_pairs, half_stencil, max_cells

__all__ = ["DEFAULT_PASSES", "ParticleWorld", "Progress", "StepReport"]

FloatArray = NDArray[np.float64]

#: ``progress(steps_done, steps_total)``, called by :meth:`ParticleWorld.step` between chunks.
Progress = Callable[[int, int], None]

#: Most sweeps over a step's contacts, for impulses and again for push-apart. A sweep that changes
#: nothing ends them early, so a dilute gas makes about two; a resting heap needs several so that
#: a ball pressed between a neighbour and the floor is pushed out within the step.
DEFAULT_PASSES = 8

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
    by its velocity only. ``backend`` is ``"auto"`` (numba if installed), ``"numba"`` or
    ``"numpy"``.

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
        self._passes = whole_number(passes, "passes")
        self._backend = pick_backend(backend)
        self._dim = int(dim)
        self._pos, self._vel, self._rad, self._ima = pos, vel, rad, ima
        self._ids = np.arange(n, dtype=np.int64)
        self._planes_n, self._planes_c = normals, offsets
        self._gravity = g
        self._e = e
        self._stencil = half_stencil(dim)
        self._min_cell = 2.0 * float(rad.max()) + SOLVER_MARGIN
        self._max_cells = max_cells(n)
        self._time = 0.0
        self._steps = 0
        self._scratch: tuple[NDArray[np.generic], ...] = ()
        self._contacts: tuple[NDArray[np.generic], ...] = ()

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

        >>> ParticleWorld([[0, 0], [3, 0]], [[1, 0], [-1, 0]], radii=1.0, box=((-5, -5), (8, 5)), backend="numpy")
        <ParticleWorld: 2 discs in 2D, 4 walls, e = 1, gravity off, t = 0 s after 0 steps, backend numpy>
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
        return out

    @property
    def n(self) -> int:
        return int(self._pos.shape[0])

    @property
    def dim(self) -> int:
        return self._dim

    @property
    def backend(self) -> str:
        """``"numba"`` or ``"numpy"``."""
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
        return self._unsorted(self._rad)

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
        arrays = (self._pos, self._vel, self._rad, self._ima, self._ids, *self._scratch, *self._contacts)
        return int(sum(a.nbytes for a in arrays))

    def kinetic_energy(self) -> float:
        """``sum(m |v|^2) / 2`` over bodies of finite mass."""
        finite = self._ima > 0.0
        speed2 = np.einsum("ij,ij->i", self._vel[finite], self._vel[finite])
        return float(0.5 * np.sum(speed2 / self._ima[finite]))

    def momentum(self) -> FloatArray:
        """``sum(m v)`` over bodies of finite mass."""
        finite = self._ima > 0.0
        return np.asarray(np.sum(self._vel[finite] / self._ima[finite, None], axis=0), np.float64)

    def overlapping_pairs(self) -> NDArray[np.int64]:
        """Pairs ``(i, j)``, ``i < j``, of bodies touching now (indices as given), rows sorted."""
        return grid_pairs(self.positions, self.radii, backend=self._backend)

    # --- stepping -----------------------------------------------------------------------------
    def step(self, dt: float, steps: int = 1, progress: Progress | None = None) -> StepReport:
        """Advance ``steps`` steps of ``dt`` each (one compiled call, or one per chunk of about
        1/100 of the run when ``progress`` is given, called as ``progress(done, steps)``)."""
        dt = positive(dt, "dt")
        steps = whole_number(steps, "steps", minimum=0)
        stats = np.zeros(2, np.int64)
        chunk = steps if progress is None else max(1, -(-steps // _PROGRESS_CHUNKS))
        done = 0
        while done < steps:
            count = min(chunk, steps - done)
            if self._backend == "numba":
                self._run_compiled(dt, count, stats)
            else:
                numpy_kernels.run_steps(
                    self._pos,
                    self._vel,
                    self._rad,
                    self._ima,
                    self._stencil,
                    self._planes_n,
                    self._planes_c,
                    self._gravity,
                    dt,
                    self._e,
                    self._min_cell,
                    self._max_cells,
                    count,
                    self._passes,
                    stats,
                )
            done += count
            self._steps += count
            self._time += dt * count
            if progress is not None:
                progress(done, steps)
        return StepReport(steps, int(stats[0]), int(stats[1]))

    def _run_compiled(self, dt: float, steps: int, stats: NDArray[np.int64]) -> None:
        kernels = compiled_kernels()
        assert kernels is not None
        n = self.n
        if not self._scratch:
            self._scratch = (
                np.empty_like(self._pos),
                np.empty_like(self._vel),
                np.empty_like(self._rad),
                np.empty_like(self._ima),
                np.empty_like(self._ids),
                np.zeros(self._max_cells + 2, np.int64),  # cell starts
                np.zeros(n, np.int64),  # destination slot of each body in the counting sort
                np.zeros(n, np.int64),  # step stamp of the last wall clamp of each slot
            )
            capacity = max(64, n // 8)
            self._contacts = (np.empty(capacity, np.int64), np.empty(capacity, np.int64), np.empty(capacity))
        pos2, vel2, rad2, ima2, ids2, cell_start, dest, mark = self._scratch
        ca, cb, cd = kernels.run_steps(
            self._pos,
            self._vel,
            self._rad,
            self._ima,
            self._ids,
            pos2,
            vel2,
            rad2,
            ima2,
            ids2,
            cell_start,
            dest,
            mark,
            self._stencil,
            self._planes_n,
            self._planes_c,
            self._gravity,
            dt,
            self._e,
            self._min_cell,
            steps,
            self._passes,
            self._steps + 1,
            *self._contacts,
            stats,
        )
        self._contacts = (ca, cb, cd)
