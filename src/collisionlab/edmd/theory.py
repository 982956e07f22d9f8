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

Mixtures (species ``a`` with number fractions ``x_a``, diameters ``sigma_a``, masses ``m_a``;
``sigma_ab = (sigma_a + sigma_b) / 2``; moments ``<sigma^k> = sum_a x_a sigma_a^k``; ``eta`` the
total packing fraction, ``rho`` the total number density):

* 3D, Boublik, J. Chem. Phys. 53, 471 (1970) and Mansoori, Carnahan, Starling and Leland,
  J. Chem. Phys. 54, 1523 (1971) (BMCSL), with ``xi_k = (pi/6) rho <sigma^k>``:
  ``Z = 6/(pi rho) [xi_0/(1 - xi_3) + 3 xi_1 xi_2/(1 - xi_3)^2 + (3 - xi_3) xi_2^3/(1 - xi_3)^3]``;
  its contact values (Boublik 1970; Grundke and Henderson, Mol. Phys. 24, 269 (1972); Lee and
  Levesque, Mol. Phys. 26, 1351 (1973)), with ``z_ab = sigma_a sigma_b / (sigma_a + sigma_b)``:
  ``g_ab = 1/(1 - xi_3) + 3 xi_2 z_ab/(1 - xi_3)^2 + 2 xi_2^2 z_ab^2/(1 - xi_3)^3``,
  which give BMCSL back through the virial route
  ``Z = 1 + (2 pi/3) rho sum_ab x_a x_b sigma_ab^3 g_ab``.
* 2D, Santos, Yuste and Lopez de Haro, Mol. Phys. 96, 1 (1999), their recipe for d = 2 with
  Henderson's ``Z_s`` for one kind of disc:
  ``Z = 1/(1 - eta) + [Z_s(eta) - 1/(1 - eta)] <sigma>^2/<sigma^2>``; the contact values of the
  same authors, J. Chem. Phys. 117, 5785 (2002), d = 2:
  ``g_ab = 1/(1 - eta) + [g_s(eta) - 1/(1 - eta)] (sigma_a sigma_b / sigma_ab) <sigma>/<sigma^2>``,
  which give that ``Z`` back through ``Z = 1 + (pi/2) rho sum_ab x_a x_b sigma_ab^2 g_ab``
  (and the exact second virial coefficient, ``Z = 1 + eta (1 + <sigma>^2/<sigma^2>) + ...``).
* Enskog's collision frequency of one ball of ``a`` with the balls of ``b`` (Chapman and
  Cowling, ch. 16; Hansen and McDonald): ``rho_b g_ab`` times the cross-section and the mean
  relative speed, with the reduced mass ``mu_ab = m_a m_b / (m_a + m_b)``:
  3D ``rho_b g_ab pi sigma_ab^2 sqrt(8 kT/(pi mu_ab))``, 2D ``rho_b g_ab 2 sigma_ab
  sqrt(pi kT/(2 mu_ab))`` (one kind: ``mu = m/2``, the formulas above).

>>> round(carnahan_starling(0.4), 6), round(henderson(0.3), 6)
(6.925926, 2.063776)
>>> round(enskog_collision_rate(0.0, 3, 1.0, 1.0, 1.0), 6)   # no neighbours, no collisions
0.0
>>> round(mixture_compressibility([1.0], [2.0], 0.4, 3), 6)   # one kind: Carnahan-Starling
6.925926
"""

from __future__ import annotations

import math
from collections.abc import Sequence

__all__ = [
    "bmcsl",
    "bmcsl_contact_values",
    "carnahan_starling",
    "contact_value",
    "disc_mixture",
    "disc_mixture_contact_values",
    "enskog_collision_rate",
    "enskog_pair_rates",
    "henderson",
    "ideal_compressibility",
    "mixture_compressibility",
    "mixture_contact_values",
    "number_density",
]

Numbers = Sequence[float]


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


def _moment(fractions: Numbers, diameters: Numbers, k: int) -> float:
    """``<sigma^k> = sum_a x_a sigma_a^k``."""
    return sum(x * s**k for x, s in zip(fractions, diameters, strict=True))


def number_density(fractions: Numbers, diameters: Numbers, eta: float, dim: int) -> float:
    """The total number density ``rho`` of a mixture at packing fraction ``eta``: ``eta`` over
    the mean ball's area ``(pi/4) <sigma^2>`` (2D) or volume ``(pi/6) <sigma^3>`` (3D)."""
    if dim == 2:
        return eta / (math.pi / 4.0 * _moment(fractions, diameters, 2))
    return eta / (math.pi / 6.0 * _moment(fractions, diameters, 3))


def bmcsl(fractions: Numbers, diameters: Numbers, eta: float) -> float:
    """``Z`` of a hard-sphere mixture (3D), Boublik-Mansoori-Carnahan-Starling-Leland (see the
    module's docstring); ``fractions`` by number, summing to 1."""
    rho = number_density(fractions, diameters, eta, 3)
    xi = [math.pi / 6.0 * rho * _moment(fractions, diameters, k) for k in range(4)]
    empty = 1.0 - xi[3]
    bracket = xi[0] / empty + 3.0 * xi[1] * xi[2] / empty**2 + (3.0 - xi[3]) * xi[2] ** 3 / empty**3
    return 6.0 / (math.pi * rho) * bracket


def bmcsl_contact_values(fractions: Numbers, diameters: Numbers, eta: float) -> list[list[float]]:
    """``g_ab(sigma_ab)`` of a hard-sphere mixture consistent with :func:`bmcsl` (BGHLL)."""
    rho = number_density(fractions, diameters, eta, 3)
    xi2 = math.pi / 6.0 * rho * _moment(fractions, diameters, 2)
    empty = 1.0 - eta
    values = []
    for sa in diameters:
        row = []
        for sb in diameters:
            z = sa * sb / (sa + sb)
            row.append(1.0 / empty + 3.0 * xi2 * z / empty**2 + 2.0 * (xi2 * z) ** 2 / empty**3)
        values.append(row)
    return values


def disc_mixture(fractions: Numbers, diameters: Numbers, eta: float) -> float:
    """``Z`` of a hard-disc mixture (2D): Santos, Yuste and Lopez de Haro's recipe on Henderson's
    equation (see the module's docstring)."""
    ratio = _moment(fractions, diameters, 1) ** 2 / _moment(fractions, diameters, 2)
    free = 1.0 / (1.0 - eta)
    return free + (henderson(eta) - free) * ratio


def disc_mixture_contact_values(fractions: Numbers, diameters: Numbers, eta: float) -> list[list[float]]:
    """``g_ab(sigma_ab)`` of a hard-disc mixture consistent with :func:`disc_mixture`."""
    scale = _moment(fractions, diameters, 1) / _moment(fractions, diameters, 2)
    free = 1.0 / (1.0 - eta)
    excess = contact_value(eta, 2) - free
    return [[free + excess * (2.0 * sa * sb / (sa + sb)) * scale for sb in diameters] for sa in diameters]


def mixture_compressibility(fractions: Numbers, diameters: Numbers, eta: float, dim: int) -> float:
    """``Z`` of a mixture: :func:`disc_mixture` in 2D, :func:`bmcsl` in 3D."""
    return disc_mixture(fractions, diameters, eta) if dim == 2 else bmcsl(fractions, diameters, eta)


def mixture_contact_values(fractions: Numbers, diameters: Numbers, eta: float, dim: int) -> list[list[float]]:
    """``g_ab(sigma_ab)`` of a mixture, consistent with :func:`mixture_compressibility`."""
    if dim == 2:
        return disc_mixture_contact_values(fractions, diameters, eta)
    return bmcsl_contact_values(fractions, diameters, eta)


def enskog_pair_rates(
    fractions: Numbers, diameters: Numbers, masses: Numbers, eta: float, dim: int, kt: float
) -> list[list[float]]:
    """``[a][b]``: collisions per unit time of one ball of species ``a`` with balls of ``b``, in
    Enskog's theory with :func:`mixture_contact_values` (see the module's docstring). Summed
    over ``b``, one ball's collision rate; ``x_a rates[a][b] = x_b rates[b][a]``."""
    rho = number_density(fractions, diameters, eta, dim)
    g = mixture_contact_values(fractions, diameters, eta, dim)
    rates = []
    for a, (sa, ma) in enumerate(zip(diameters, masses, strict=True)):
        row = []
        for b, (xb, sb, mb) in enumerate(zip(fractions, diameters, masses, strict=True)):
            sigma = 0.5 * (sa + sb)
            mu = ma * mb / (ma + mb)
            if dim == 2:
                row.append(rho * xb * g[a][b] * 2.0 * sigma * math.sqrt(math.pi * kt / (2.0 * mu)))
            else:
                row.append(rho * xb * g[a][b] * math.pi * sigma**2 * math.sqrt(8.0 * kt / (math.pi * mu)))
        rates.append(row)
    return rates
