"""A checkpoint's state arrays checked before any world is made from them (:mod:`.checkpoint`
reads the file, its header and checksum): each array's dtype and shape, their agreement with
each other and with the header, and every index they hold inside its range, so that the compiled
loop never reads past an array. ``refuse`` turns a problem into the reader's one-line error.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import layout as L
from .exact_gas import ExactGas

__all__ = ["check_arrays"]

#: Each state array's dtype and the shape it must have, ``n`` the balls, ``s`` the species
#: counted (0 for one kind), ``None`` any length.
_DTYPES = {
    "F": np.float64,
    "IX": np.int32,
    "NB": np.int32,
    "CI": np.int32,
    "heap": np.int32,
    "lists": np.int32,
    "P": np.float64,
    "Q": np.int64,
    "G": np.float64,
    "K": np.int64,
    "S": np.int32,
    "KS": np.int64,
    "SE": np.float64,
    "order": np.int64,
}


def check_arrays(arrays: dict[str, NDArray[Any]], gas: ExactGas, info: dict[str, Any], refuse: Any) -> None:
    """Dtypes and shapes of the state arrays, and their agreement with the header, so that the
    compiled loop never reads past an array."""
    for name, dtype in _DTYPES.items():
        if arrays[name].dtype != np.dtype(dtype):
            raise refuse(f"array {name} is {arrays[name].dtype}, expected {np.dtype(dtype)}")
    checked = gas.checked()
    n, dim = checked.n, checked.dim
    if info.get("n") != n or info.get("dim") != dim:
        raise refuse("header's world and gas disagree on the number of balls or the dimension")
    # A mixture's P goes on with each body's radius (layout.P_RADII), which the loop reads when
    # P_MIXED says the radii differ: the flag, the length and the radii must agree with F.
    p, f = arrays["P"], arrays["F"]
    mixed = p.ndim == 1 and p.shape[0] > L.P_MIXED and p[L.P_MIXED] != 0.0
    shapes = {
        "F": (n, L.NF),
        "IX": (n, L.NI),
        "heap": (n,),
        "order": (n,),
        "P": (L.NP + (n if mixed else 0),),
        "Q": (L.NQ,),
        "G": (L.NG,),
        "K": (L.NK,),
    }
    for name, shape in shapes.items():
        if arrays[name].shape != shape:
            raise refuse(f"array {name} has shape {arrays[name].shape}, expected {shape}")
    radii = f[:, L.RADIUS]
    if mixed != bool(radii.min() != radii.max()) or (mixed and not np.array_equal(p[L.P_RADII :], radii)):
        raise refuse("array P's mixture flag or radii disagree with the balls' radii in F")
    nb, ci, ks, se, s = arrays["NB"], arrays["CI"], arrays["KS"], arrays["SE"], arrays["S"]
    counted = ks.shape[0]
    Q = arrays["Q"]
    if (
        nb.ndim != 2
        or nb.shape[0] != n
        or ci.ndim != 3
        or ci.shape[2] != 4
        or ci.shape[0] != int(np.prod(Q[L.Q_NC : L.Q_NC + 3]))
        or arrays["lists"].shape != (int(Q[L.Q_NB]) + 1,)
        or ks.shape != (counted, counted)
        or se.shape != (counted, 3)
        or s.shape != ((n,) if counted else (0,))
    ):
        raise refuse("the arrays' shapes disagree with each other")
    if int(Q[L.Q_DIM]) != dim or bool(Q[L.Q_PERIODIC]) != (checked.boundary == "periodic"):
        raise refuse("the arrays disagree with the header's dimension or boundary")
    if not np.array_equal(np.sort(arrays["order"]), np.arange(n)):
        raise refuse("array order is not a permutation of the balls")
    nnb = arrays["IX"][:, L.NNB]
    if np.any(nnb < 0) or np.any(nnb > nb.shape[1]):
        raise refuse("the neighbour counts exceed the lists")
    used = np.arange(nb.shape[1])[None, :] < nnb[:, None]
    if np.any(used & ((nb < 0) | (nb >= n))) or (counted and (np.any(s < 0) or np.any(s >= counted))):
        raise refuse("the neighbour lists or species name balls that do not exist")
    ix, queued = arrays["IX"], int(arrays["K"][L.K_HEAP])
    links = ix[:, [L.QNEXT, L.QPREV]]
    if (
        not 0 <= queued <= n
        or np.any(arrays["heap"][:queued] < 0)
        or np.any(arrays["heap"][:queued] >= n)
        or np.any(arrays["lists"] < -1)
        or np.any(arrays["lists"] >= n)
        or np.any(links < -1)
        or np.any(links >= n)
        or np.any(ix[:, L.CELL] < 0)
        or np.any(ix[:, L.CELL] >= ci.shape[0])
    ):
        raise refuse("the event calendar or cells name balls or cells that do not exist")
