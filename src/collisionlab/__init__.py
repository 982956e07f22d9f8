"""collisionlab: collision detection and resolution of simple shapes.

The stateless layer (vectors, shapes, queries, resolution, time of impact) is usable alone;
:mod:`collisionlab.world` steps a simulation on top of it and :mod:`collisionlab.cli` is the
command line.
"""

from __future__ import annotations

from .contact import Contact, Separation
from .errors import CollisionLabError, InvalidInputError, UnsupportedPairError
from .narrowphase import contact, distance, intersects, separation, supported_pairs
from .resolution import reflect_velocity, resolve_collision, separate
from .shapes import AABB, Circle, Line, Plane, Shape, Sphere
from .toi import Impact, time_of_impact
from .vector import Vector3D, VectorLike

__all__ = [
    "AABB",
    "Circle",
    "CollisionLabError",
    "Contact",
    "Impact",
    "InvalidInputError",
    "Line",
    "Plane",
    "Separation",
    "Shape",
    "Sphere",
    "UnsupportedPairError",
    "Vector3D",
    "VectorLike",
    "contact",
    "distance",
    "intersects",
    "reflect_velocity",
    "resolve_collision",
    "separate",
    "separation",
    "supported_pairs",
    "time_of_impact",
]

__version__ = "0.1.0"
