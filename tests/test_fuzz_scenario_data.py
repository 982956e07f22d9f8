"""Fuzz: scenario-data (tests/fuzz_harness.py).

Parsed-TOML data of any shape, and plausible scenarios whose numbers span the whole float range:
a scenario that runs and renders finite, valid output, or one ScenarioError naming the file
(65), or a run stopped as out of range (65).

Seeded (derandomized) and bounded for CI; ``python3 tasks.py fuzz`` runs the same probe at many
more inputs. COLLISIONLAB_EXAMPLES overrides the count.
"""

from __future__ import annotations

import os
from typing import Any

from hypothesis import given

from tests.fuzz_harness import FUZZ_SETTINGS, SCENARIO_DATA, guarded, probe_scenario_data


@FUZZ_SETTINGS(int(os.environ.get("COLLISIONLAB_EXAMPLES", "300")))
@given(SCENARIO_DATA)
def test_scenario_data_ends_in_a_documented_outcome(data: dict[str, Any]) -> None:
    outcome = guarded(probe_scenario_data, data)
    assert not outcome.failed, outcome.detail
