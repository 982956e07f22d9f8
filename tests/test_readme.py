"""The README's Python examples run as written, and the commands it shows exist."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

README = Path(__file__).resolve().parent.parent / "README.md"
BLOCKS = re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), flags=re.S)


def test_readme_has_python_examples():
    assert BLOCKS, "the README lost its API example"


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_python_block_runs(index):
    exec(compile(BLOCKS[index], f"README.md block {index}", "exec"), {})


def test_readme_pasted_run_matches_the_program(capsys):
    from collisionlab.cli import main

    assert main(["demo", "sphere-plane", "--every", "25"]) == 0
    printed = capsys.readouterr().out.strip()
    text = README.read_text(encoding="utf-8")
    pasted = text.split("```\n", 2)[1].split("```", 1)[0].strip()
    assert pasted == printed


def test_readme_links_work_on_a_package_index_page():
    # A package index shows the README away from the repository: a relative link or image breaks there.
    text = README.read_text(encoding="utf-8")
    targets = re.findall(r"\]\(([^)\s]+)", text) + re.findall(r'(?:src|href)="([^"]+)"', text)
    relative = [t for t in targets if not t.startswith(("https://", "http://", "#", "mailto:"))]
    assert relative == []
