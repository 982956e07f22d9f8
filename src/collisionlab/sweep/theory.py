"""Hard-sphere (hard-disc) equations of state, and the pressure of a gas from its collision rate.

The compressibility factor ``Z = P V / (N k T)`` of a gas of equal hard balls of diameter
``sigma`` at packing fraction ``phi`` (the fraction of the volume, or area, the balls fill).
"""

from __future__ import annotations

import math

__all__ = ["carnahan_starling", "compressibility_from_collisions", "hard_ball_compressibility", "henderson"]


def carnahan_starling(phi: float) -> float:
    """Hard spheres (3D): ``Z = (1 + phi + phi^2 - phi^3) / (1 - phi)^3`` (Carnahan and
    Starling, J. Chem. Phys. 51, 635 (1969), eq. 10).

    >>> carnahan_starling(0.0)
    1.0
    >>> round(carnahan_starling(0.3), 4)     # (1 + 0.3 + 0.09 - 0.027) / 0.7^3 = 1.363 / 0.343
    3.9738
    """
    return (1.0 + phi + phi**2 - phi**3) / (1.0 - phi) ** 3


def henderson(phi: float) -> float:
    """Hard discs (2D): ``Z = (1 + phi^2 / 8) / (1 - phi)^2`` (Henderson, Mol. Phys. 30, 971
    (1975)), the two-dimensional counterpart of Carnahan-Starling.

    >>> round(henderson(0.5), 4)             # (1 + 0.25 / 8) / 0.25 = 1.03125 * 4
    4.125
    """
    return (1.0 + phi**2 / 8.0) / (1.0 - phi) ** 2


def hard_ball_compressibility(phi: float, dim: int) -> float:
    """:func:`henderson` in 2D, :func:`carnahan_starling` in 3D."""
    return henderson(phi) if dim == 2 else carnahan_starling(phi)


def compressibility_from_collisions(
    collisions: int, n: int, dim: int, diameter: float, duration: float, kinetic_energy: float, mass: float = 1.0
) -> float:
    """``Z`` of an elastic hard-ball gas in equilibrium, from how often its balls collide (the
    virial theorem with impulsive forces; Allen and Tildesley, *Computer Simulation of Liquids*,
    2nd ed., 2.4 and 3.7):

    ``P V = N k T + (1 / (d t)) * sum over collisions of sigma * |dp|``, where each collision
    moves momentum ``|dp| = m v_n`` along the line of centres. Over the collisions of a Maxwellian
    gas the normal approach speed averages ``<v_n> = sqrt(pi k T / m)``, so with the collision
    rate per ball ``omega = 2 C / (N t)`` and ``k T = 2 E / (d N)``:

    ``Z = 1 + omega * sigma * sqrt(pi m / (k T)) / (2 d)``.

    Check against the second virial coefficient: a dilute 3D gas collides ``omega = 4 n sigma^2
    sqrt(pi k T / m)`` times per ball, giving ``Z = 1 + (2 pi / 3) n sigma^3 = 1 + 4 phi``, the
    first term of :func:`carnahan_starling`. With ``sigma = 2``, ``kT = m = 1``, ``N = 1000``,
    ``phi = 0.01`` (``n = phi / (pi / 6 sigma^3)``) for ``t = 1``:

    >>> n_density = 0.01 / (math.pi / 6 * 8)
    >>> omega = 4 * n_density * 4 * math.sqrt(math.pi)
    >>> collisions = omega * 1000 / 2
    >>> round(compressibility_from_collisions(collisions, 1000, 3, 2.0, 1.0, 1.5 * 1000), 12)
    1.04
    """
    if n <= 0 or duration <= 0.0 or kinetic_energy <= 0.0:
        return math.nan
    kt = 2.0 * kinetic_energy / (dim * n)
    omega = 2.0 * collisions / (n * duration)
    return 1.0 + omega * diameter * math.sqrt(math.pi * mass / kt) / (2.0 * dim)
