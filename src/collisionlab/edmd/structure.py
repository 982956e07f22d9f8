"""Structure and transport of a periodic event-driven gas: the radial distribution function
``g(r)``, its contact value, and the mean-squared displacement with the self-diffusion
coefficient (``collisionlab gas --mode exact --observe rdf,msd``).

**g(r).** At each of ``K`` sample times the pairs closer than ``r_max`` (half the box's
smallest side: the nearest image is then the only one) are counted in bins of width
``BIN_WIDTH`` smallest contact distances, per unordered pair of species ``(a, b)``, and

    g_ab(r) = <count_ab(r)> / (P_ab V_shell(r) / V),   V_shell = (4 pi / 3) (r_hi^3 - r_lo^3)
    (3D) or pi (r_hi^2 - r_lo^2) (2D),

with ``P_ab = N_a N_b`` (``a != b``) or ``N_a (N_a - 1) / 2`` pairs, ``V`` the box's volume
(Allen and Tildesley, *Computer Simulation of Liquids*, 2nd ed., section 8.2). Walls are
refused: near a wall a ball has fewer neighbours, and the bulk normalisation above would not hold.

**Contact value.** ``g_ab(sigma_ab)`` is a quadratic fitted by least squares to the bins lying
wholly beyond contact within ``CONTACT_FIT_REACH`` diameters of it, evaluated at ``sigma_ab``.
The virial route (Hansen and McDonald, *Theory of Simple Liquids*, eq. 2.5.26 for hard spheres;
its mixture form in :mod:`.theory`) then gives the compressibility

    Z = 1 + (2 pi / 3) n sum_ab x_a x_b sigma_ab^3 g_ab(sigma_ab)   (3D; one kind: 1 + 4 eta g)
    Z = 1 + (pi / 2) n sum_ab x_a x_b sigma_ab^2 g_ab(sigma_ab)     (2D; one kind: 1 + 2 eta g),

to compare with the one the collisions measure (:mod:`.observables`).

**MSD.** Positions are unwrapped by adding up each ball's nearest-image displacement between
stops close enough in time that no ball can have moved half a box (at most ``1 / UNWRAP_SAFETY``
of the box's smallest side at the fastest ball's speed of the previous stop; the loop itself
puts a ball back in the box only at its neighbour-list rebuilds, so its stored positions cannot
be used). ``MSD(t) = <|x_i(t_0 + t) - x_i(t_0)|^2>`` from the observation's start t_0, and the self-diffusion
coefficient ``D`` is the least-squares slope of ``MSD = 2 d D t + c`` over the samples at
``t >= FIT_FROM T`` (Einstein's relation; Allen and Tildesley section 8.7). In free flight
``MSD = <v^2> t^2`` exactly. Enskog's ``D`` (:func:`enskog_self_diffusion`) is the comparison;
the real ``D`` of hard spheres is larger at moderate density (the velocity autocorrelation's
long-time tail: Alder, Gass and Wainwright, J. Chem. Phys. 53, 3813 (1970), their Table I: D/D_E
about 1.2 to 1.3 at V/V_0 = 3 to 2, eta = 0.25 to 0.37), and in a periodic box of side ``L`` the
measured ``D`` is lower by about ``2.837 kT / (6 pi eta_s L)`` (Yeh and Hummer, J. Phys. Chem. B
108, 15873 (2004)).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidInputError
from .compile import jit
from .theory import contact_value

__all__ = [
    "BIN_WIDTH",
    "CONTACT_FIT_REACH",
    "DEFAULT_SAMPLES",
    "FIT_FROM",
    "OBSERVABLES",
    "OBSERVER_ARRAYS",
    "OBSERVE_FROM",
    "RDF_MAX_BALLS",
    "UNWRAP_SAFETY",
    "contact_fit",
    "enskog_self_diffusion",
    "pair_histogram",
    "parse_observables",
    "rdf_from_counts",
]

#: ``--observe``: the observables a run may add to its report.
OBSERVABLES = ("rdf", "msd")
#: Width of g(r)'s bins, in the smallest contact distance (diameter).
BIN_WIDTH = 0.02
#: The contact value is fitted to the bins within this many diameters beyond contact.
CONTACT_FIT_REACH = 0.16
#: Degree of the polynomial fitted near contact.
CONTACT_FIT_DEGREE = 2
#: The observation starts after this part of the run (the lattice of the start relaxing: g(r)
#: at contact averaged from the start was 1% low at fraction 0.3, N = 4,000, time 20).
OBSERVE_FROM = 0.2
#: ``--samples``: samples of the run (g(r) averaged over them, MSD at each) by default.
DEFAULT_SAMPLES = 100
#: The diffusion coefficient is the slope of the MSD over the samples from this part of the run on.
FIT_FROM = 0.5
#: Between two stops of the unwrapping, the fastest ball (at the earlier stop) moves at most
#: ``1 / UNWRAP_SAFETY`` of the smallest side: collisions would have to speed it up more than
#: ``UNWRAP_SAFETY / 2`` times for a displacement to be taken to the wrong image.
UNWRAP_SAFETY = 16.0
#: g(r) counts every pair (O(N^2) per sample): refused above this many balls.
RDF_MAX_BALLS = 20_000
#: The arrays of an :class:`~.observer.Observer`'s state (:meth:`~.observer.Observer.saved`), as a checkpoint names
#: them, each with its dtype.
OBSERVER_ARRAYS = {
    "observer_counts": np.int64,
    "observer_msd": np.float64,
    "observer_unwrapped": np.float64,
    "observer_start": np.float64,
    "observer_ref": np.float64,
    "observer_kinds": np.int64,
}


def _is_int(value: object) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _is_finite(value: object) -> bool:
    return not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value)


def parse_observables(text: str) -> tuple[str, ...]:
    """``--observe``'s comma list, checked (:class:`InvalidInputError` naming the choices).

    >>> parse_observables("msd, rdf")
    ('msd', 'rdf')
    """
    names = tuple(part.strip() for part in text.split(","))
    for name in names:
        if name not in OBSERVABLES:
            raise InvalidInputError("observe", f"must be a comma list of {', '.join(OBSERVABLES)}", got=name)
    return tuple(dict.fromkeys(names))


def enskog_self_diffusion(eta: float, dim: int, radius: float, mass: float, kt: float) -> float:
    """Enskog's self-diffusion coefficient of hard spheres (3D) or discs (2D) of one kind:
    the dilute (Chapman-Enskog, first Sonine approximation) value divided by the contact value
    ``g(sigma)`` (:func:`.theory.contact_value`: Carnahan-Starling, Henderson):

        3D: D_E = 3 / (8 n sigma^2 g(sigma)) sqrt(kT / (pi m))
        2D: D_E = 1 / (2 n sigma g(sigma)) sqrt(kT / (pi m))

    (Chapman and Cowling, *The Mathematical Theory of Non-uniform Gases*, 3rd ed., sections
    10.51 and 16.5; Alder, Gass and Wainwright, J. Chem. Phys. 53, 3813 (1970), eq. 3; 2D:
    Gass, J. Chem. Phys. 54, 1898 (1971)), ``sigma = 2 radius``, ``n`` the number density.

    >>> round(enskog_self_diffusion(0.3, 3, 1.0, 1.0, 1.0), 6)
    0.298016
    """
    sigma = 2.0 * radius
    ball = math.pi * radius**2 if dim == 2 else 4.0 / 3.0 * math.pi * radius**3
    n = eta / ball
    speed = math.sqrt(kt / (math.pi * mass))
    g = contact_value(eta, dim)
    if dim == 2:
        return speed / (2.0 * n * sigma * g)
    return 3.0 * speed / (8.0 * n * sigma**2 * g)


@jit
def pair_histogram(pos: Any, kinds: Any, species: int, sides: Any, width: float, counts: Any) -> None:
    """Add every pair closer than ``counts.shape[1] * width`` (nearest image in the periodic
    box ``sides``) to ``counts[pair, bin]``, ``pair`` the index of the unordered pair of kinds
    ``(a <= b)``: ``a * species - a (a - 1) / 2 + b - a``."""
    n, dim = pos.shape
    bins = counts.shape[1]
    reach = bins * width
    reach2 = reach * reach
    for i in range(n - 1):
        ki = kinds[i]
        for j in range(i + 1, n):
            d2 = 0.0
            for k in range(dim):  # positions in [0, L): |d| < L, one image at most away
                d = pos[j, k] - pos[i, k]
                if d > 0.5 * sides[k]:
                    d -= sides[k]
                elif d < -0.5 * sides[k]:
                    d += sides[k]
                d2 += d * d
            if d2 < reach2:
                b = int(math.sqrt(d2) / width)
                if b < bins:
                    a, c = (ki, kinds[j]) if ki <= kinds[j] else (kinds[j], ki)
                    counts[a * species - (a * (a - 1)) // 2 + c - a, b] += 1


def rdf_from_counts(
    counts: NDArray[np.int64], samples: int, width: float, volume: float, dim: int, numbers: list[int]
) -> NDArray[np.float64]:
    """g(r) per unordered pair of kinds, from ``counts`` summed over ``samples`` (see the
    module's docstring); rows in :func:`pair_histogram`'s order."""
    edges = width * np.arange(counts.shape[1] + 1)
    shell = np.diff(edges**dim) * (math.pi if dim == 2 else 4.0 / 3.0 * math.pi)
    g = np.zeros(counts.shape)
    row = 0
    for a, na in enumerate(numbers):
        for b in range(a, len(numbers)):
            pairs = na * (na - 1) / 2.0 if a == b else float(na * numbers[b])
            if pairs > 0:
                g[row] = counts[row] / (samples * pairs * shell / volume)
            row += 1
    return g


def contact_fit(r: NDArray[np.float64], g: NDArray[np.float64], width: float, sigma: float) -> float:
    """g at contact ``sigma``: a quadratic fitted to the bins (centres ``r``, width ``width``)
    lying wholly within ``(sigma, sigma + CONTACT_FIT_REACH * sigma]``, evaluated at sigma.

    >>> r = 0.01 + 0.02 * np.arange(100)
    >>> round(contact_fit(r, np.where(r > 1, 3 - r, 0.0), 0.02, 1.0), 9)
    2.0
    """
    lower = r - 0.5 * width
    upper = r + 0.5 * width
    use = (lower >= sigma * (1.0 - 1e-12)) & (upper <= sigma * (1.0 + CONTACT_FIT_REACH) * (1.0 + 1e-12))
    if int(use.sum()) <= CONTACT_FIT_DEGREE:
        return math.nan
    coefficients = np.polyfit(r[use] - sigma, g[use], CONTACT_FIT_DEGREE)
    return float(coefficients[-1])
