"""Fuzz: public-api (tests/fuzz_harness.py).

The public API with any values: a finite result, or one of the library's own errors
(InvalidInputError, UnsupportedPairError, OutOfRangeError) in one line; never a raw exception,
a leaked warning, inf or NaN.

Seeded (derandomized) and bounded for CI; ``python3 tasks.py fuzz`` runs the same probe at many
more inputs. COLLISIONLAB_EXAMPLES overrides the count.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

from hypothesis import given

from tests.fuzz_harness import FUZZ_SETTINGS, api_calls, guarded, probe_api


@FUZZ_SETTINGS(int(os.environ.get("COLLISIONLAB_EXAMPLES", "800")))
@given(api_calls())
def test_api_ends_in_a_documented_outcome(call: tuple[str, Callable[[], Any]]) -> None:
    outcome = guarded(probe_api, call)
    assert not outcome.failed, outcome.detail
