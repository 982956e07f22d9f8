"""Fuzz: file-bytes (tests/fuzz_harness.py).

Raw file bytes (the examples mutated byte by byte, random bytes) run as a scenario file:
exit 0 with valid output, or one error line with status 65 (or 1).

Seeded (derandomized) and bounded for CI; ``python3 tasks.py fuzz`` runs the same probe at many
more inputs. COLLISIONLAB_EXAMPLES overrides the count.
"""

from __future__ import annotations

import os

from hypothesis import given

from tests.fuzz_harness import FUZZ_SETTINGS, file_bytes, guarded, probe_file_bytes


@FUZZ_SETTINGS(int(os.environ.get("COLLISIONLAB_EXAMPLES", "250")))
@given(file_bytes())
def test_file_bytes_ends_in_a_documented_outcome(data: bytes) -> None:
    outcome = guarded(probe_file_bytes, data)
    assert not outcome.failed, outcome.detail
