"""tasks.py (the README's two commands) and .ci/run: waiting for apt's lock, CI mode."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import pytest

REPO = Path(__file__).resolve().parents[1]


def _tasks() -> ModuleType:
    spec = importlib.util.spec_from_file_location("tasks_under_test", REPO / "tasks.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_browser_setup_waits_for_apts_lock_and_tries_again(monkeypatch: pytest.MonkeyPatch) -> None:
    # Another apt process holding the dpkg lock made apt-get exit 100, and `tasks.py test` with it.
    tasks = _tasks()
    statuses = iter([100, 100, 0])
    calls: list[list[str]] = []

    def fake_run(words: list[str], **_: object) -> subprocess.CompletedProcess[bytes]:
        calls.append(words)
        return subprocess.CompletedProcess(words, next(statuses))

    waits: list[float] = []
    monkeypatch.setattr(tasks.subprocess, "run", fake_run)
    monkeypatch.setattr(tasks.time, "sleep", waits.append)
    tasks.sh_waiting_for_apt("bash", "tests/setup_browser.sh")
    assert len(calls) == 3 and waits == [tasks.LOCK_WAIT_SECONDS] * 2


def test_other_failures_of_the_browser_setup_are_not_retried(monkeypatch: pytest.MonkeyPatch) -> None:
    tasks = _tasks()
    calls: list[list[str]] = []

    def fake_run(words: list[str], **_: object) -> subprocess.CompletedProcess[bytes]:
        calls.append(words)
        return subprocess.CompletedProcess(words, 1)

    monkeypatch.setattr(tasks.subprocess, "run", fake_run)
    with pytest.raises(SystemExit) as stop:
        tasks.sh_waiting_for_apt("bash", "tests/setup_browser.sh")
    assert stop.value.code == 1 and len(calls) == 1


def test_the_test_task_uses_the_waiting_setup() -> None:
    source = (REPO / "tasks.py").read_text()
    assert 'sh_waiting_for_apt("bash", "tests/setup_browser.sh")' in source


def test_ci_exports_ci_so_a_missing_browser_fails_the_browser_test() -> None:
    result = subprocess.run(
        ["bash", "-c", f"source <(sed 's/^python3 tasks.py test$/env/' {REPO / '.ci' / 'run'}) | grep '^CI='"],
        capture_output=True,
        text=True,
        check=False,
        env={"PATH": "/usr/bin:/bin"},
    )
    assert result.stdout.strip() == "CI=1", result.stderr


def test_every_task_is_listed_in_the_usage() -> None:
    result = subprocess.run([sys.executable, str(REPO / "tasks.py")], capture_output=True, text=True, check=False)
    assert result.returncode == 2
    assert "run|test|bench|" in result.stderr and "|fuzz" in result.stderr


def test_tasks_run_compiles_every_kernel_before_the_demos(monkeypatch: pytest.MonkeyPatch) -> None:
    # issue 28: the first demo must not wait for the compiler.
    tasks = _tasks()
    calls: list[list[str]] = []

    def fake_run(words: list[str], **_: object) -> subprocess.CompletedProcess[bytes]:
        calls.append(words)
        return subprocess.CompletedProcess(words, 0)

    monkeypatch.setattr(tasks, "setup", lambda *extras: None)
    monkeypatch.setattr(tasks.subprocess, "run", fake_run)
    tasks.run()
    assert [Path(words[0]).name for words in calls] == ["collisionlab", "collisionlab"]
    assert [words[1:] for words in calls] == [["compile"], ["demo"]]
