"""The light core: ``pip install collisionlab`` brings numpy, numba, matplotlib and orjson; sweeps,
the interactive page and GSD trajectories are extras, never imported by the lab's own commands, and a command that
needs a missing one says which in one line (status 1, no traceback)."""

from __future__ import annotations

import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from collisionlab.extras import MissingExtraError, require
from tests.cli_helpers import EXAMPLES, REPO

EXTRA_MODULES = ("dask", "distributed", "pyarrow", "pandas", "plotly", "gsd")
HEAD_ON = str(EXAMPLES / "head-on.toml")


def _python(code: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, check=False)


def test_the_core_install_is_numpy_numba_matplotlib_and_orjson() -> None:
    project = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    names = {dep.split(">")[0].split("[")[0].strip() for dep in project["dependencies"]}
    assert names == {"numpy", "numba", "matplotlib", "orjson"}
    extras = project["optional-dependencies"]
    assert any(dep.startswith("dask[distributed]") for dep in extras["sweep"])
    assert {"pyarrow", "pandas"} <= {dep.split(">")[0] for dep in extras["sweep"]}
    assert [dep.split(">")[0] for dep in extras["html"]] == ["plotly"]
    assert [dep.split(">")[0] for dep in extras["trajectory"]] == ["gsd"]
    assert extras["all"] == ["collisionlab[sweep,html,trajectory]"]
    assert "collisionlab[all]" in extras["dev"]  # the test setup installs every extra


@pytest.mark.parametrize(
    "argv",
    [["run", HEAD_ON], ["demo"], ["gas", "--n", "100", "--steps", "10"]],
    ids=["run", "demo", "gas"],
)
def test_the_labs_commands_import_no_extra(argv: list[str]) -> None:
    code = (
        "import sys\n"
        "from collisionlab.cli import main\n"
        f"status = main({argv!r})\n"
        f"loaded = sorted(m for m in {EXTRA_MODULES!r} if m in sys.modules)\n"
        "print('STATUS', status, 'LOADED', loaded, file=sys.stderr)\n"
    )
    result = _python(code)
    assert "STATUS 0 LOADED []" in result.stderr.splitlines()[-1], result.stderr[-2000:]


def _missing(module: str, argv: list[str]) -> subprocess.CompletedProcess[str]:
    """``main(argv)`` in a fresh interpreter where importing ``module`` fails (as if not installed)."""
    code = f"import sys\nsys.modules[{module!r}] = None\nfrom collisionlab.cli import main\nsys.exit(main({argv!r}))\n"
    return _python(code)


def test_html_without_plotly_names_the_html_extra(tmp_path: Path) -> None:
    page = tmp_path / "page.html"
    result = _missing("plotly", ["run", HEAD_ON, "--html", str(page)])
    assert result.returncode == 1
    assert result.stderr.splitlines() == [
        "collisionlab: interactive pages (--html) need the 'html' extra: pip install 'collisionlab[html]'"
    ]
    assert result.stdout == ""  # failed before the run
    assert not page.exists()


@pytest.mark.parametrize("module", ["distributed", "pyarrow", "pandas"])
def test_a_sweep_without_its_extra_names_the_sweep_extra(module: str, tmp_path: Path) -> None:
    sweep_file = next(EXAMPLES.glob("sweep-*.toml"))
    result = _missing(module, ["sweep", str(sweep_file), "--output", str(tmp_path / "rows")])
    assert result.returncode == 1
    assert result.stderr.splitlines() == [
        "collisionlab: sweeps need the 'sweep' extra: pip install 'collisionlab[sweep]'"
    ]
    assert list(tmp_path.iterdir()) == []


def test_require_returns_the_module_or_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    assert require("json", "none", "tests").__name__ == "json"
    monkeypatch.setitem(sys.modules, "plotly_missing_for_this_test", None)
    with pytest.raises(MissingExtraError, match=r"^pages need the 'html' extra: pip install 'collisionlab\[html\]'$"):
        require("plotly_missing_for_this_test", "html", "pages")
