"""The compiled text layout (text_kernels.py): its FIXED3 numbers against Python's own ``%.3f``
(the oracle), in its Python form (hypothesis) and compiled (a million doubles of every size)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from numpy.typing import NDArray

from collisionlab import text_kernels
from collisionlab.text_kernels import FIXED3, FIXED3_LIMIT


def fixed3(values: NDArray[np.float64], compiled: bool) -> list[str]:
    """Each of ``values`` written by a one-row program (one event a value)."""
    n = len(values)
    program = np.array([[FIXED3, 0, 0, 0]], np.int64)
    out = np.zeros(n * 24, np.uint8)
    starts = np.zeros(n + 1, np.int64)
    nothing = np.frombuffer(b"", np.uint8)  # read-only, as the callers' (one compiled copy)
    lay_out = text_kernels.compiled() if compiled else text_kernels.lay_out
    lay_out(
        nothing, np.zeros(n, np.int64), np.zeros(n, np.int64), np.zeros(n, np.int64), np.zeros((n, 1), bool),
        nothing, np.zeros(1, np.int64), program, nothing, np.zeros(1, np.int64), out,
        values.reshape(n, 1), starts,
    )  # fmt: skip
    return [out[starts[k] : starts[k + 1]].tobytes().decode() for k in range(n)]


@given(st.floats().filter(lambda x: not abs(x) >= FIXED3_LIMIT or not math.isfinite(x)))
def test_fixed3_writes_what_percent_does(x: float) -> None:
    assert fixed3(np.array([x]), compiled=False) == ["%.3f" % x]  # noqa: UP031  (% is the oracle)


def test_fixed3_compiled_writes_what_percent_does_at_every_size_and_on_every_tie() -> None:
    rng = np.random.default_rng(7)
    # Doubles from 1e-20 to the limit, both signs, and values on and next to a half-thousandth
    # (ties exist only when exact: 0.0625 is 62.5 thousandths, written 0.062, half to even).
    wide = rng.choice([-1.0, 1.0], 500_000) * 10.0 ** rng.uniform(-20, 15.9, 500_000)
    halves = (rng.integers(-(10**9), 10**9, 250_000) + 0.5) / 1000
    ties = np.array([k / 16 for k in range(-64, 65)] + [2.0**-s for s in range(1, 80)])
    near = np.concatenate((np.nextafter(halves, np.inf), np.nextafter(halves, -np.inf), halves))
    specials = np.array([0.0, -0.0, 5e-4, -5e-4, 4.999e-4, math.inf, -math.inf, math.nan, FIXED3_LIMIT / 2, 5e-324])
    values = np.concatenate((wide, near, ties, specials))
    written = fixed3(values, compiled=True)
    wrong = [(x, w) for x, w in zip(values.tolist(), written, strict=True) if w != "%.3f" % x]  # noqa: UP031
    assert not wrong, wrong[:5]
