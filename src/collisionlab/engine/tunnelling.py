"""Forward Euler's tunnelling check: does a body move farther in one step than it takes to pass
through something? (Euler then misses the collision; exact mode does not.) The world warns once.

Lines, planes and walls are not such things: a body that crosses one is put back on its side
(euler_clamps' ``_uncross``), a body past a wall back inside; fixed boxes and other bodies are.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from . import pair_separation

__all__ = ["thickness", "tunnelling"]

#: Bodies up to this many are checked pair by pair (relative speeds); more, against the fastest.
_PAIRWISE_UP_TO = 400


def thickness(kind: np.ndarray[Any, np.dtype[np.int64]], ext: np.ndarray[Any, np.dtype[np.float64]], dims: int) -> Any:
    """How far something must travel to pass through each body: a ball's diameter, a box's
    shortest edge.

    >>> kind = np.array([pair_separation.BALL_3D, pair_separation.BALL_3D + 1])
    >>> thickness(kind, np.array([[0.5, 0.5, 0.5], [1.0, 0.2, 3.0]]), 3).tolist()   # 2 r; 2 x the least half-size
    [1.0, 0.4]
    """
    return np.where(kind <= pair_separation.BALL_3D, 2.0 * ext[:, 0], 2.0 * ext[:, :dims].min(axis=1))


def tunnelling(
    vel: np.ndarray[Any, np.dtype[np.float64]],
    thick: np.ndarray[Any, np.dtype[np.float64]],
    thinnest: float,
    dt: float,
    fixed_boxes: bool,
) -> tuple[int, int, float, float] | None:
    """The first pair found that can pass through each other in a step ``dt``: ``(a, i, moved,
    limit)``, ``a`` -1 for a fixed box, ``moved`` the distance one step moves ``i`` relative to
    ``a``, ``limit`` what it takes to pass through; or None. ``vel`` and ``thick`` are the moving
    bodies' velocities and thicknesses, ``thinnest`` the least thickness of all.

    >>> v = np.array([[0.0, -100.0, 0.0], [0.0, 0.0, 0.0]])
    >>> tunnelling(v, np.array([1.0, 1.0]), 1.0, 0.01, False)   # 100 m/s x 0.01 s = 1 m: not more than 1 m
    >>> tunnelling(v, np.array([1.0, 1.0]), 1.0, 0.02, False)   # 2 m relative to the other, against 1 + 1
    >>> tunnelling(v, np.array([1.0, 1.0]), 1.0, 0.03, False)
    (0, 1, 3.0, 2.0)
    """
    n = vel.shape[0]
    speeds = np.sqrt(np.einsum("ij,ij->i", vel, vel))
    # Nothing moves farther than the thinnest body in a step: no pair can tunnel (a pair's
    # relative speed is at most twice the fastest, its limit at least twice the thinnest).
    if n == 0 or float(speeds.max()) * dt <= thinnest:
        return None
    if fixed_boxes:
        over = speeds * dt > thick
        if np.any(over):
            i = int(np.argmax(over))
            return (-1, i, float(speeds[i] * dt), float(thick[i]))
    if n > 1:
        if n <= _PAIRWISE_UP_TO:
            relative = np.sqrt(((vel[:, None, :] - vel[None, :, :]) ** 2).sum(axis=2)) * dt
            limit = thick[:, None] + thick[None, :]
            pairs = np.triu(relative > limit, 1)
            if np.any(pairs):
                i, j = (int(x) for x in np.argwhere(pairs)[0])
                return (i, j, float(relative[i, j]), float(limit[i, j]))
        elif 2.0 * float(speeds.max()) * dt > 2.0 * float(thick.min()):
            i = int(np.argmax(speeds))
            return (i, i, 2.0 * float(speeds.max()) * dt, 2.0 * float(thick.min()))
    return None
