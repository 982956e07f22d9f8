"""The Maxwell-Boltzmann speed distribution a hard-sphere gas relaxes to.

With ``s2 = kT / m`` (the variance of one velocity component), the speed density is the
Rayleigh law in 2D and the Maxwell law in 3D (Reif, *Fundamentals of Statistical and Thermal
Physics*, 7.10):

* 2D: ``f(v) = v / s2 * exp(-v^2 / (2 s2))``
* 3D: ``f(v) = sqrt(2 / pi) v^2 / s2^(3/2) * exp(-v^2 / (2 s2))``
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidInputError
from ..validate import positive

__all__ = ["component_variance", "speed_pdf"]


def speed_pdf(speed: ArrayLike, dim: int, variance: float) -> NDArray[np.float64]:
    """Probability density of the speed at ``speed`` for ``kT/m = variance``.

    >>> float(speed_pdf(1.0, 2, 1.0))              # 1 * exp(-1/2)
    0.6065306597126334
    >>> round(float(speed_pdf(math.sqrt(2), 3, 1.0)), 6)   # peak: sqrt(2/pi) * 2 * exp(-1)
    0.587051
    """
    s2 = positive(variance, "variance")
    v = np.asarray(speed, dtype=np.float64)
    gauss = np.exp(-(v**2) / (2.0 * s2))
    if dim == 2:
        return np.asarray(v / s2 * gauss, np.float64)
    if dim == 3:
        return np.asarray(math.sqrt(2.0 / math.pi) * v**2 / s2**1.5 * gauss, np.float64)
    raise InvalidInputError("dim", "must be 2 or 3", got=dim)


def component_variance(velocities: ArrayLike) -> float:
    """``kT/m`` of equal-mass bodies from equipartition: ``<|v|^2> / dim`` (rows are bodies).

    >>> component_variance([[1.0, 1.0], [-1.0, 1.0]])
    1.0
    """
    v = np.asarray(velocities, dtype=np.float64)
    return float(np.mean(np.sum(v**2, axis=1)) / v.shape[1])
