"""Fuzz: menu-answers (tests/fuzz_harness.py).

Menu sessions: a case, then answers good and bad (then Enter to the end): bad answers are asked
again, a session ends in a run (0) or at the end of input (1), never a traceback.

Seeded (derandomized) and bounded for CI; ``python3 tasks.py fuzz`` runs the same probe at many
more inputs. COLLISIONLAB_EXAMPLES overrides the count.
"""

from __future__ import annotations

import os

from hypothesis import given

from tests.fuzz_harness import FUZZ_SETTINGS, MENU_SESSIONS, guarded, probe_menu


@FUZZ_SETTINGS(int(os.environ.get("COLLISIONLAB_EXAMPLES", "120")))
@given(MENU_SESSIONS)
def test_menu_ends_in_a_documented_outcome(session: tuple[str, list[str]]) -> None:
    outcome = guarded(probe_menu, session)
    assert not outcome.failed, outcome.detail
