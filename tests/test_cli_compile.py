"""``collisionlab compile`` (issue 28): every kernel loaded or compiled ahead of any run."""

from __future__ import annotations

import re

from tests.cli_helpers import run_cli


def test_compile_exits_0_with_progress_on_stderr_and_its_time_on_stdout() -> None:
    result = run_cli(["compile"])
    assert result.status == 0, result.err
    assert re.fullmatch(r"compiled every kernel in \d+\.\d s\n", result.out)
    progress = result.err.splitlines()
    assert progress[0].startswith("[1/6] euler") and progress[-1].startswith("[6/6] text: ")
