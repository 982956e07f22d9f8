"""The numba cache's housekeeping: stale compiled code goes, fresh code stays, and two processes
doing it at once (pytest-xdist workers, two runs started together) do not trip each other."""

from __future__ import annotations

import os
import pickle
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from collisionlab import numba_cache


def _write(path: Path, mtime: float) -> Path:
    path.write_bytes(b"x")
    os.utime(path, (mtime, mtime))
    return path


@pytest.fixture
def package(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)  # the cache then sits in __pycache__
    folder = tmp_path / "kernels"
    (folder / "__pycache__").mkdir(parents=True)
    return folder


def test_cached_code_older_than_a_source_it_inlines_is_removed(package: Path) -> None:
    source = _write(package / "geometry.py", 2_000.0)
    stale = [
        _write(package / "__pycache__" / name, 1_000.0) for name in ("step.run-9.py311.nbi", "step.run-9.py311.1.nbc")
    ]
    other = _write(package / "__pycache__" / "loop.run-3.py311.nbi", 1_000.0)  # not one of the stems
    numba_cache.forget_stale(package, ["step"], [source])
    assert [f.exists() for f in stale] == [False, False]
    assert other.exists()


def test_cached_code_newer_than_every_source_is_kept(package: Path) -> None:
    source = _write(package / "geometry.py", 1_000.0)
    fresh = _write(package / "__pycache__" / "step.run-9.py311.nbi", 2_000.0)
    numba_cache.forget_stale(package, ["step"], [source])
    assert fresh.exists()


def test_a_file_another_process_removed_while_we_looked_is_skipped(
    package: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Another worker removed step.run-9.py311.nbi between our listing and our stat: the listing
    # still names it. Before the fix this raised FileNotFoundError and failed every test of the
    # worker (CI of 2026-11-25, a second run in the same folder as the first).
    source = _write(package / "geometry.py", 2_000.0)
    stale = _write(package / "__pycache__" / "step.run-9.py311.1.nbc", 1_000.0)
    gone = package / "__pycache__" / "step.run-9.py311.nbi"
    monkeypatch.setattr(numba_cache, "cache_files", lambda _: [gone, stale])
    numba_cache.forget_stale(package, ["step"], [source])
    assert not stale.exists()


def test_nothing_cached_is_nothing_to_do(package: Path) -> None:
    source = _write(package / "geometry.py", 2_000.0)
    numba_cache.forget_stale(package, ["step"], [source])
    assert list((package / "__pycache__").iterdir()) == []


def test_cache_files_finds_what_numba_wrote(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # The oracle is numba itself: a cached function compiled in another process, with
    # NUMBA_CACHE_DIR set, must be found by cache_files (and so be removable when stale).
    package = tmp_path / "kernels"
    package.mkdir()
    (package / "twice.py").write_text("import numba\n@numba.njit(cache=True)\ndef twice(x):\n    return 2 * x\n")
    cache = tmp_path / "cache"
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "PYTHONPATH": str(package)}
    code = "import twice; assert twice.twice(21) == 42"
    subprocess.run([sys.executable, "-c", code], env=env, check=True, capture_output=True)
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(cache))
    found = sorted(f.suffix for f in numba_cache.cache_files(package))
    assert found == [".nbc", ".nbi"]
    # and what every loader asks: the entry is there, another is not, nor one of another file
    assert numba_cache.holds(package, "twice", "twice")
    assert not numba_cache.holds(package, "twice", "thrice")
    assert not numba_cache.holds(package, "other", "twice")


@pytest.mark.parametrize("enabled", [True, False])
def test_gc_paused_leaves_the_collector_as_it_found_it(enabled: bool) -> None:
    import gc

    was = gc.isenabled()
    (gc.enable if enabled else gc.disable)()
    try:
        with pytest.raises(RuntimeError), numba_cache.gc_paused():
            assert not gc.isenabled()
            raise RuntimeError("a failed load")
        assert gc.isenabled() is enabled
    finally:
        (gc.enable if was else gc.disable)()


_HOLDER = """
import sys, time
from pathlib import Path
from collisionlab import numba_cache
with numba_cache.compile_lock(Path(sys.argv[1]), "step"):
    print("held", flush=True)
    time.sleep(0.5)  # the other process asks for the lock meanwhile
    Path(sys.argv[2]).write_text("done")  # written while the lock is still held
"""


def test_a_second_process_waits_for_the_compile_lock_then_goes_on(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Two processes wanting the same uncached kernels: the second waits until the first has
    finished (it then loads what the first cached) instead of compiling them beside it."""
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "cache"))
    package = tmp_path / "kernels"
    package.mkdir()
    marker = tmp_path / "marker"
    holder = subprocess.Popen(
        [sys.executable, "-c", _HOLDER, str(package), str(marker)], stdout=subprocess.PIPE, text=True
    )
    try:
        assert holder.stdout is not None and holder.stdout.readline().strip() == "held"
        with numba_cache.compile_lock(package, "step"):
            assert marker.read_text() == "done"  # the holder's block ran to its end first
    finally:
        holder.wait()
    assert holder.returncode == 0
    with numba_cache.compile_lock(package, "exact"):  # another file's lock: not held by anyone
        pass


def test_the_compile_lock_is_skipped_where_no_lock_file_can_be_made(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("x")
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(blocker))  # its folder cannot be made
    ran = []
    with numba_cache.compile_lock(tmp_path, "step"):
        ran.append(True)
    assert ran == [True]


def _overloads(index: Path) -> dict[Any, Any]:
    """What numba's index file ``index`` lists (none if another numba wrote it), in the format its
    ``IndexDataCacheFile`` reads: a pickled version, then ``(source stamp, overloads)``, each
    overload's key ``(argument types, target machine, hash of the function's code)``. numba
    writes an index again, with only the present source's overloads, whenever it compiles the
    function after its source changed."""
    import numba

    with index.open("rb") as f:
        version = pickle.load(f)
        _, overloads = pickle.loads(f.read())
    return overloads if version == numba.__version__ else {}


def test_every_kernel_is_compiled_for_one_set_of_argument_types() -> None:
    """numba compiles a function once for each set of argument types it is called with, and a
    variable that starts at a constant (``k = 0``) is first typed as that constant
    (``Literal[int](0)``): a kernel it was passed to was compiled twice, the exact stepper's
    ``_impacts`` for two minutes more (non_literal._int). The session's fixture has compiled or
    loaded every kernel (conftest.py), so their index files are there to read, in the cache
    folder numba was given (``__pycache__`` may hold files of runs without one)."""
    import collisionlab
    from collisionlab import edmd, engine

    types_of: dict[tuple[str, Any], list[Any]] = {}
    for package in (collisionlab, engine, edmd):
        folder = numba_cache._cache_folder(Path(str(package.__file__)).resolve().parent)
        for index in folder.glob("*.nbi"):
            for signature, *target in _overloads(index):
                types_of.setdefault((index.name, tuple(target)), []).append(signature)
    names = {name.split("-")[0] for name, _ in types_of}
    for entry in ("exact_kernels.run_exact_steps", "step_kernels.run_steps", "loop.run_events", "text_kernels.lay_out"):
        assert entry in names  # read, not skipped
    twice = {name: [str(s) for s in signatures] for (name, _), signatures in types_of.items() if len(signatures) > 1}
    assert not twice


def _no_cache_folder_env(tmp_path: Path) -> dict[str, str]:
    """An environment with no writable cache folder: HOME and XDG_CACHE_HOME under a plain file
    (nobody, root included, can make a folder there), NUMBA_CACHE_DIR unset, and numba kept from
    writing beside the sources (as for a package installed in a read-only folder)."""
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    (tmp_path / "tmp").mkdir()
    env = {key: value for key, value in os.environ.items() if key != "NUMBA_CACHE_DIR"}
    env.update(
        HOME=str(blocker / "home"),
        XDG_CACHE_HOME=str(blocker / "cache"),
        TMPDIR=str(tmp_path / "tmp"),
        NUMBA_CACHE_LOCATOR_CLASSES="UserProvidedCacheLocator,UserWideCacheLocator",
    )
    return env


def test_a_run_with_no_writable_cache_folder_caches_in_a_private_temporary_one(tmp_path: Path) -> None:
    # Before: "unexpected error: RuntimeError: cannot cache function 'lay_out': no locator
    # available", exit 1. The JSON writer's kernel is compiled by numba even for a tiny run.
    scenario = Path(__file__).resolve().parents[1] / "examples" / "head-on.toml"
    command = [sys.executable, "-m", "collisionlab", "run", str(scenario), "--format", "json"]
    result = subprocess.run(command, env=_no_cache_folder_env(tmp_path), capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stderr
    assert '"collisions": 1' in result.stdout
    said = [line for line in result.stderr.splitlines() if "cannot write the compile cache" in line]
    assert len(said) == 1 and "Traceback" not in result.stderr
    folder = tmp_path / "tmp" / f"collisionlab-numba-{os.getuid()}"
    assert str(folder) in said[0]
    assert list(folder.rglob("text_kernels.lay_out-*.nbi"))  # cached there: the next run loads it
    assert folder.stat().st_mode & 0o077 == 0


def test_a_temporary_cache_folder_open_to_others_is_not_used(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # Another user could have planted compiled code (pickles) in a folder they can write.
    monkeypatch.setattr(numba_cache.tempfile, "tempdir", str(tmp_path))
    shared = tmp_path / f"collisionlab-numba-{os.getuid()}"
    shared.mkdir()
    shared.chmod(0o777)
    chosen = numba_cache._temporary_cache()
    assert chosen != shared and chosen.parent == tmp_path and chosen.stat().st_mode & 0o077 == 0
    shared.chmod(0o700)
    assert numba_cache._temporary_cache() == shared


def test_every_loader_compiles_with_the_one_set_of_options() -> None:
    """The engine's kernel files, the event-driven loop and the writers' text kernel are all
    compiled through numba_cache.kernel: cached on disk, the GIL released, numpy's error model
    (a division by zero is inf, never an exception), and nothing else but the two ways a
    function may be asked for (inlined into its callers, or without reference counts)."""
    import types

    from numba.core.registry import CPUDispatcher

    from collisionlab import text_kernels
    from collisionlab.edmd import collide, loop, predict, schedule
    from collisionlab.engine import compiled

    modules: list[types.ModuleType] = [compiled.kernels(), compiled.exact_kernels(), compiled.contact_kernels()]
    modules += [sys.modules[name] for name in list(sys.modules) if ".engine._compiled_" in name]
    modules += [loop, predict, schedule, collide]
    dispatchers = [value for module in modules for value in vars(module).values() if isinstance(value, CPUDispatcher)]
    dispatchers.append(text_kernels.compiled())
    assert len(dispatchers) > 100  # every file's functions, not a few
    for dispatcher in dispatchers:
        options = dict(dispatcher.targetoptions)
        assert options.pop("error_model") == "numpy" and options.pop("nogil") is True, dispatcher
        assert dispatcher._cache.__class__.__name__ == "FunctionCache", dispatcher  # cache=True
        assert set(options) <= {"nopython", "boundscheck", "inline", "_nrt"}, dispatcher
        assert options.get("inline", "always") == "always" and options.get("_nrt", False) is False, dispatcher
