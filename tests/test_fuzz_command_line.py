"""Fuzz: command-line (tests/fuzz_harness.py).

Command lines from the vocabulary (well-formed with options, and random words): a documented
status (0, 1, 2, 65) with valid output or one error line, never a traceback.

Seeded (derandomized) and bounded for CI; ``python3 tasks.py fuzz`` runs the same probe at many
more inputs. COLLISIONLAB_EXAMPLES overrides the count.
"""

from __future__ import annotations

import os

from hypothesis import given

from tests.fuzz_harness import COMMAND_LINES, FUZZ_SETTINGS, guarded, probe_command_line


@FUZZ_SETTINGS(int(os.environ.get("COLLISIONLAB_EXAMPLES", "250")))
@given(COMMAND_LINES)
def test_command_line_ends_in_a_documented_outcome(argv: list[str]) -> None:
    outcome = guarded(probe_command_line, argv)
    assert not outcome.failed, outcome.detail
