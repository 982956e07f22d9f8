"""The walkthrough notebook in docs/ runs from top to bottom with the installed library, so it
cannot go stale: every cell asserts what it shows, and an error in any cell fails this test."""

from __future__ import annotations

from pathlib import Path

import nbformat
from nbclient import NotebookClient

NOTEBOOK = Path(__file__).resolve().parents[1] / "docs" / "walkthrough.ipynb"


def test_the_walkthrough_notebook_runs_and_its_checks_hold(tmp_path: Path) -> None:
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    nbformat.validate(notebook)
    NotebookClient(
        notebook, timeout=None, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
    ).execute()
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    # The record draws itself inline (RunRecord._repr_png_), and the gas cell printed its check.
    assert any("image/png" in o.get("data", {}) for o in outputs)
    assert any("after 300 steps" in o.get("text", "") for o in outputs)
