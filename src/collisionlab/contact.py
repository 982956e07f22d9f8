"""Typed query results: :class:`Separation` (signed distance) and :class:`Contact`."""

from __future__ import annotations

from dataclasses import dataclass

from .vector import Vector3D

__all__ = ["Contact", "Separation"]


@dataclass(frozen=True, slots=True)
class Contact:
    """Two shapes in contact.

    ``normal`` is a unit vector pointing from shape A to shape B (the direction in which B must
    move to separate), ``depth >= 0`` is how far they overlap along it (0 when exactly
    touching), and ``point`` is the contact point: midway between the deepest points of the two
    shapes (Box2D's convention for a manifold point).

    >>> c = Contact(Vector3D(1, 0, 0), 0.5, Vector3D(2, 0, 0))
    >>> c.flipped()
    Contact(normal=Vector3D(x=-1.0, y=0.0, z=0.0), depth=0.5, point=Vector3D(x=2.0, y=0.0, z=0.0))
    """

    normal: Vector3D
    depth: float
    point: Vector3D

    def flipped(self) -> Contact:
        """The same contact seen from B: the normal reversed, depth and point unchanged."""
        return Contact(-self.normal, self.depth, self.point)


@dataclass(frozen=True, slots=True)
class Separation:
    """The signed distance between two shapes, with the direction and the place it is measured.

    ``distance`` is positive when the shapes are apart (the gap), zero when touching, negative
    when overlapping (minus the depth). ``normal`` is a unit vector from A to B and ``point``
    lies midway between the two closest (or deepest) points.
    """

    distance: float
    normal: Vector3D
    point: Vector3D

    def flipped(self) -> Separation:
        return Separation(self.distance, -self.normal, self.point)

    def contact(self) -> Contact | None:
        """The :class:`Contact`, or ``None`` when apart. Touching (distance exactly 0) is a
        contact: this is collisionlab's one touching policy, for every pair (lab eqs. 7, 9)."""
        if self.distance > 0.0:
            return None
        return Contact(self.normal, 0.0 - self.distance, self.point)
