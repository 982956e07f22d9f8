"""Kinetic theory of hard discs and spheres: the numbers a run is checked against.

Packing fraction ``eta``; ``sigma`` the diameter; ``n`` the number density.

* 3D, Carnahan and Starling, J. Chem. Phys. 51, 635 (1969):
  ``Z = (1 + eta + eta^2 - eta^3) / (1 - eta)^3``, and the contact value of the pair
  distribution from ``Z = 1 + 4 eta g(sigma)``: ``g = (1 - eta/2) / (1 - eta)^3``.
* 2D, Henderson, Mol. Phys. 30, 971 (1975): ``Z = (1 + eta^2/8) / (1 - eta)^2``, with
  ``Z = 1 + 2 eta g(sigma)``: ``g = (1 - 7 eta / 16) / (1 - eta)^2``.
* Enskog's collision frequency of one body (Chapman and Cowling, ch. 16; Hansen and McDonald):
  the Boltzmann rate times ``g(sigma)``: 3D ``4 sqrt(pi kT/m) n sigma^2 g``, 2D
  ``2 sqrt(pi kT/m) n sigma g`` (the cross-section ``pi sigma^2`` or ``2 sigma`` times the mean
  relative speed ``sqrt(16 kT/(pi m))`` or ``sqrt(pi kT/m)``).

>>> round(carnahan_starling(0.4), 6), round(henderson(0.3), 6)
(6.925926, 2.063776)
>>> round(enskog_collision_rate(0.0, 3, 1.0, 1.0, 1.0), 6)   # no neighbours, no collisions
0.0
"""

from __future__ import annotations

import math

__all__ = ["carnahan_starling", "contact_value", "enskog_collision_rate", "henderson", "ideal_compressibility"]


def carnahan_starling(eta: float) -> float:
    """Compressibility factor ``Z = PV/(N kT)`` of hard spheres (3D) at packing fraction ``eta``."""
    return (1.0 + eta + eta * eta - eta**3) / (1.0 - eta) ** 3


def henderson(eta: float) -> float:
    """Compressibility factor of hard discs (2D) at area fraction ``eta``."""
    return (1.0 + eta * eta / 8.0) / (1.0 - eta) ** 2


def ideal_compressibility(eta: float, dim: int) -> float:
    """``Z`` of the equation of state for ``dim`` (Henderson in 2D, Carnahan-Starling in 3D)."""
    return henderson(eta) if dim == 2 else carnahan_starling(eta)


def contact_value(eta: float, dim: int) -> float:
    """``g(sigma)``, the pair distribution at contact, from the equation of state."""
    if dim == 2:
        return (1.0 - 7.0 * eta / 16.0) / (1.0 - eta) ** 2
    return (1.0 - 0.5 * eta) / (1.0 - eta) ** 3


def enskog_collision_rate(eta: float, dim: int, radius: float, mass: float, kt: float) -> float:
    """Collisions per body per unit time in Enskog's theory (each collision counts for both bodies)."""
    sigma = 2.0 * radius
    volume = math.pi * radius**2 if dim == 2 else 4.0 / 3.0 * math.pi * radius**3
    density = eta / volume
    speed = math.sqrt(math.pi * kt / mass)
    g = contact_value(eta, dim)
    if dim == 2:
        return 2.0 * speed * density * sigma * g
    return 4.0 * speed * density * sigma * sigma * g
