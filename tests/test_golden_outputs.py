"""Every shipped example and the lab's four cases print what they printed before the contact
solver came (the files in tests/golden were written by ``collisionlab run EXAMPLE`` and
``collisionlab demo`` at commit ee931d5, before it): a change to the engine that moves any of
these numbers, in any digit printed, fails here.

To write them again after a change that is meant to move them, run each example as the test
does and replace the file, and say why in the commit.

A heavy example (``HEAVY_EXAMPLES`` in tests/cli_helpers.py: ramp-pour's 2,000 spheres take
minutes over their 2,000 steps) is run, and its golden files were written, with
``--steps N --every N`` (``heavy_options``): its first N steps, which hold its first
collisions, with the first and last frames only. ramp-pour's were written with the example
(commit "ramp-pour: a small random velocity...") by
``collisionlab run examples/ramp-pour.toml --steps 10 --every 10 [--format json]``, and written
again when theory's column of the ledger came to count the contact solve's work (its collisions
figure, -0.201909 J, unchanged; theory's went from -0.171806 to the same). gas-mixture's (two
[[gas]] tables of discs run event by event, with their species in the summary) were written with
the example (commit "scenario files: several [[gas]] tables in a [box] run event by event...") by
``collisionlab run examples/gas-mixture.toml [--format json]``.

The ledger's energies and momenta were sums by BLAS (``np.dot``), whose rounding follows the
CPU: on an AVX2 machine ramp-pour's ledger ended 1e-16 relative away from the file written on
an AVX-512 one. They are exactly rounded sums now (:mod:`collisionlab.sums`), and ramp-pour's and
gas-mixture's files were written again for those figures alone (the steps are unchanged).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.cli_helpers import EXAMPLE_NAMES, EXAMPLES, heavy_options, run_cli

GOLDEN = Path(__file__).resolve().parent / "golden"


def test_every_example_has_its_golden_files() -> None:
    assert sorted(p.stem for p in GOLDEN.glob("*.table") if p.stem != "demo") == EXAMPLE_NAMES
    assert sorted(p.stem for p in GOLDEN.glob("*.json")) == EXAMPLE_NAMES


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
@pytest.mark.parametrize("form", ["table", "json"])
def test_an_example_prints_what_it_printed(name: str, form: str) -> None:
    result = run_cli(["run", str(EXAMPLES / f"{name}.toml"), "--format", form, *heavy_options(name)])
    assert result.status == 0, result.err
    assert result.out == (GOLDEN / f"{name}.{form}").read_text(encoding="utf-8")


def test_the_labs_four_cases_print_what_they_printed() -> None:
    result = run_cli(["demo"])
    assert result.status == 0, result.err
    assert result.out == (GOLDEN / "demo.table").read_text(encoding="utf-8")
