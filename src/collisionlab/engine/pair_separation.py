"""A pair's separation for the steppers' kernels: the body and static kinds (``BALL_2D`` ..
``STATIC_BOX``), a pair's restitution (:func:`_pair_e`), and the separation of two bodies or of a
static and a body from :mod:`.geometry_kernels` (one kernel per pair of features), each body pair
oriented as the scenario orders pairs (:func:`_pair_sep`, :func:`_static_sep`, and from the rows:
:func:`_body_separation`, :func:`_static_separation`, :func:`_contact_separation`).

It imports only :mod:`.geometry_kernels`; it must not import the broad phase, the order, the
impulses or any stepper's loop, which all call it.
"""

from __future__ import annotations

from typing import Any

if "_GEOMETRY" in globals():  # the compiled copy: the kernels it calls are compiled too
    gk: Any = globals()["_GEOMETRY"]
else:
    from . import geometry_kernels as gk

__all__ = ["BALL_2D", "BALL_3D", "BOX_2D", "BOX_3D", "STATIC_BOUNDARY", "STATIC_BOX", "STATIC_WALL"]

# Body kinds: circles and spheres, 2D and 3D boxes.
BALL_2D = 0
BALL_3D = 1
BOX_2D = 2
BOX_3D = 3
# Static kinds: a two-sided line or plane, a one-sided wall, a fixed box.
STATIC_BOUNDARY = 0
STATIC_WALL = 1
STATIC_BOX = 2

#: Helpers the compiled form inlines into their callers (:mod:`.compiled`): they take arrays, and a
#: call that passes several numba arrays (each a struct of seven fields) costs more than the work inside.
INLINE = ("_pair_e", "_pair_sep", "_body_separation", "_static_sep", "_static_separation", "_contact_separation")


def _pair_e(e_a: float, e_b: float, e_default: float) -> float:
    """A pair's restitution: the larger of the two overrides if any (NaN means none), else the
    scenario's default (Box2D mixes by max)."""
    if e_a != e_a and e_b != e_b:
        return e_default
    if e_a != e_a:
        return e_b
    if e_b != e_b:
        return e_a
    return max(e_a, e_b)


def _pair_sep(
    ka: int,
    ax: float,
    ay: float,
    az: float,
    ea0: float,
    ea1: float,
    ea2: float,
    kb: int,
    bx: float,
    by: float,
    bz: float,
    eb0: float,
    eb1: float,
    eb2: float,
) -> Any:
    """Separation of a body of kind ``ka`` at ``a`` (half sizes ``ea``) and one of kind ``kb`` at
    ``b``, normal from a to b: :func:`_body_separation` on numbers (the hot loops call this; a
    helper taking arrays costs more than the work inside)."""
    if ka <= BALL_3D and kb <= BALL_3D:
        return gk.separation_ball_ball(ax, ay, az, ea0, bx, by, bz, eb0)
    if ka <= BALL_3D:
        return gk.separation_ball_box(
            ax, ay, az, ea0, bx - eb0, by - eb1, bz - eb2, bx + eb0, by + eb1, bz + eb2, 2 if ka == BALL_2D else 3
        )
    if kb <= BALL_3D:
        s = gk.separation_ball_box(
            bx, by, bz, eb0, ax - ea0, ay - ea1, az - ea2, ax + ea0, ay + ea1, az + ea2, 2 if kb == BALL_2D else 3
        )
        return (s[0], -s[1], -s[2], -s[3], s[4], s[5], s[6])
    return gk.separation_box_box(
        ax - ea0,
        ay - ea1,
        az - ea2,
        ax + ea0,
        ay + ea1,
        az + ea2,
        bx - eb0,
        by - eb1,
        bz - eb2,
        bx + eb0,
        by + eb1,
        bz + eb2,
        2 if ka == BOX_2D else 3,
    )


def _body_separation(kind: Any, pos: Any, ext: Any, a: int, b: int) -> Any:
    """Separation of bodies ``a`` and ``b``, normal from a to b."""
    return _pair_sep(
        kind[a],
        pos[a, 0],
        pos[a, 1],
        pos[a, 2],
        ext[a, 0],
        ext[a, 1],
        ext[a, 2],
        kind[b],
        pos[b, 0],
        pos[b, 1],
        pos[b, 2],
        ext[b, 0],
        ext[b, 1],
        ext[b, 2],
    )


def _static_sep(
    sk: int,
    ox: float,
    oy: float,
    oz: float,
    ux: float,
    uy: float,
    uz: float,
    kb: int,
    bx: float,
    by: float,
    bz: float,
    e0: float,
    e1: float,
    e2: float,
) -> Any:
    """Separation of a static of kind ``sk`` (a point ``o`` and unit normal ``u``, or a fixed
    box's corners ``o``, ``u``) and a body of kind ``kb`` at ``b`` (half sizes ``e``), normal from
    the static to the body: :func:`_static_separation` on numbers."""
    ball = kb <= BALL_3D
    if sk == STATIC_BOX:
        if ball:
            r = gk.separation_ball_box(bx, by, bz, e0, ox, oy, oz, ux, uy, uz, 2 if kb == BALL_2D else 3)
            return (r[0], -r[1], -r[2], -r[3], r[4], r[5], r[6])
        return gk.separation_box_box(
            ox, oy, oz, ux, uy, uz, bx - e0, by - e1, bz - e2, bx + e0, by + e1, bz + e2, 2 if kb == BOX_2D else 3
        )
    if ball:
        if sk == STATIC_WALL:
            return gk.separation_wall_ball(ox, oy, oz, ux, uy, uz, bx, by, bz, e0)
        return gk.separation_boundary_ball(ox, oy, oz, ux, uy, uz, bx, by, bz, e0)
    if sk == STATIC_WALL:
        return gk.separation_wall_box(ox, oy, oz, ux, uy, uz, bx - e0, by - e1, bz - e2, bx + e0, by + e1, bz + e2)
    return gk.separation_boundary_box(ox, oy, oz, ux, uy, uz, bx - e0, by - e1, bz - e2, bx + e0, by + e1, bz + e2)


def _static_separation(s_kind: Any, s_a: Any, s_b: Any, s: int, kind: Any, pos: Any, ext: Any, b: int) -> Any:
    """Separation of static ``s`` and body ``b``, normal from the static to the body."""
    return _static_sep(
        s_kind[s],
        s_a[s, 0],
        s_a[s, 1],
        s_a[s, 2],
        s_b[s, 0],
        s_b[s, 1],
        s_b[s, 2],
        kind[b],
        pos[b, 0],
        pos[b, 1],
        pos[b, 2],
        ext[b, 0],
        ext[b, 1],
        ext[b, 2],
    )


def _contact_separation(kind: Any, pos: Any, ext: Any, s_kind: Any, s_a: Any, s_b: Any, a: int, b: int) -> Any:
    """Separation of a contact ``(a, b)``: ``a >= 0`` a body, ``a < 0`` the static ``-1 - a``."""
    if a >= 0:
        return _body_separation(kind, pos, ext, a, b)
    return _static_separation(s_kind, s_a, s_b, -1 - a, kind, pos, ext, b)
