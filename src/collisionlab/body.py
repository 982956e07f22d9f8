"""A moving body: a shape placed at its starting position, a velocity and a mass.

Its own module so that :mod:`collisionlab.body_block` (many bodies as arrays) and
:mod:`collisionlab.model` (the scenario) can both build on it.
"""

from __future__ import annotations

from dataclasses import dataclass

from .errors import InvalidInputError
from .shapes import AABB, Circle, Sphere
from .validate import non_negative, positive_or_inf
from .vector import Vector3D, as_vector, as_vector_3d

__all__ = ["Body", "BodyShape", "planar"]

BodyShape = Circle | Sphere | AABB


def planar(shape: object) -> bool:
    """A circle or a 2D box: it lives in the x-y plane and must not move out of it."""
    return isinstance(shape, Circle) or (isinstance(shape, AABB) and shape.dim == 2)


@dataclass(frozen=True)
class Body:
    """A moving body: a shape placed at its starting position, a velocity and a mass.
    ``math.inf`` is a kinematic body: it moves at its own velocity, pushes others and is never
    pushed (gravity does not act on it).

    ``restitution`` overrides the scenario's default for collisions of this body. ``velocity``
    has as many numbers as the shape's vectors: three for a sphere or a 3D box (``(0, -1)`` is
    refused, never padded), ``(x, y)`` or ``(x, y, 0)`` for a circle or a 2D box; a ``Vector3D``
    is taken as it is.
    """

    name: str
    shape: BodyShape
    velocity: Vector3D
    mass: float = 1.0
    restitution: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.shape, (Circle, Sphere, AABB)):
            raise InvalidInputError("shape", "a moving body must be a circle, a sphere or an AABB")
        if planar(self.shape):  # (x, y) or (x, y, 0), as the shape's own vectors
            velocity = as_vector(self.velocity, "velocity")
        else:  # a sphere or a 3D box: (x, y, z), never padded
            owner = "a sphere" if isinstance(self.shape, Sphere) else "a 3D box"
            velocity = as_vector_3d(self.velocity, "velocity", owner)
        object.__setattr__(self, "velocity", velocity)
        object.__setattr__(self, "mass", positive_or_inf(self.mass, "mass"))
        if self.restitution is not None:
            object.__setattr__(self, "restitution", non_negative(self.restitution, "restitution"))
        if planar(self.shape) and self.velocity.z != 0.0:  # else it would leave its plane
            raise InvalidInputError("velocity", "a circle or a 2D box moves in the x-y plane: z must be 0")

    @property
    def position(self) -> Vector3D:
        return self.shape.center
