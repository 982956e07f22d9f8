"""Where numba keeps collisionlab's compiled kernels: the user's cache folder, never the
installed package (site-packages may be read-only, shared, or wiped by a reinstall).

numba reads ``NUMBA_CACHE_DIR`` once, when it is first imported, so :func:`use_user_cache` must
run before the first ``import numba``; a folder the user set is kept.
"""

from __future__ import annotations

import contextlib
import gc
import hashlib
import os
import stat
import sys
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

__all__ = [
    "COMPILE_TAKES",
    "cache_files",
    "compile_lock",
    "compiled_notice",
    "compiled_once",
    "compiling_notice",
    "forget_stale",
    "gc_paused",
    "holds",
    "kernel",
    "numba_cache_dir",
    "use_user_cache",
]


#: What a first compile takes on a 2-core machine, for each kind of kernels, as the notice says it
#: (bench/README.md's ``collisionlab compile`` row and bench/LOG.md: Forward Euler 34-36 s alone,
#: as a first ``gas`` compiles it, 20-26 s after the others; the solved contacts 44-77 s; exact
#: mode's kernels 78 s alone to 144 s beside the others; the event-driven loop 24-31 s; the
#: writers' text kernel 1-2 s; from machine to machine of this kind).
COMPILE_TAKES: dict[str, str] = {
    "euler": "up to a minute",
    "solve": "one to two minutes",
    "exact": "one to three minutes",
    "event-driven": "up to a minute",
    "text": "a few seconds",
}
#: What each kind is called in the notices.
_CALLED = {
    "euler": "the engine's kernels",
    "solve": "the engine's kernels",
    "exact": "the engine's kernels",
    "event-driven": "the event-driven kernels",
    "text": "the output writers' text kernel",
}


def compiling_notice(kind: str) -> str:
    """What a program says before numba compiles the kernels of ``kind`` (a key of
    :data:`COMPILE_TAKES`): the one notice every loader gives.

    >>> compiling_notice("event-driven")
    'compiling the event-driven kernels (once per machine; up to a minute)...'
    """
    return f"compiling {_CALLED[kind]} (once per machine; {COMPILE_TAKES[kind]})..."


def compiled_notice(kind: str, seconds: float) -> str:
    """What it says when that compile is done.

    >>> compiled_notice("solve", 41.7)
    "compiled the engine's kernels in 42 s"
    """
    return f"compiled {_CALLED[kind]} in {seconds:.0f} s"


def numba_cache_dir() -> Path:
    """The user's cache folder for collisionlab's compiled kernels: ``$XDG_CACHE_HOME`` (or
    ``~/.cache``) on Linux, ``~/Library/Caches`` on macOS, ``%LOCALAPPDATA%`` on Windows, then
    ``collisionlab/numba``."""
    if sys.platform == "win32":
        base = Path(os.environ.get("LOCALAPPDATA") or Path.home() / "AppData" / "Local")
    elif sys.platform == "darwin":
        base = Path.home() / "Library" / "Caches"
    else:
        base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "collisionlab" / "numba"


def use_user_cache() -> None:
    """Point numba's cache at :func:`numba_cache_dir`, unless ``NUMBA_CACHE_DIR`` is already set.
    A folder that cannot be made or written (no home folder, a read-only one) is replaced by a
    private folder in the temporary folder, and stderr says so once: numba would otherwise refuse
    to compile a kernel asked to be cached when the package's own folder is read-only too."""
    if "NUMBA_CACHE_DIR" in os.environ:
        return
    wanted = numba_cache_dir()
    problem = _unwritable(wanted)
    if problem is None:
        os.environ["NUMBA_CACHE_DIR"] = str(wanted)
        return
    fallback = _temporary_cache()
    os.environ["NUMBA_CACHE_DIR"] = str(fallback)  # also what later calls, and child processes, see
    # Said here, not through a caller's stream: numba reads the folder when it is first imported,
    # wherever that happens; the variable set above makes this the only time in the process.
    print(
        f"collisionlab: cannot write the compile cache {wanted} ({problem}); "
        f"compiled kernels are cached in {fallback} instead",
        file=sys.stderr,
        flush=True,
    )


def _unwritable(folder: Path) -> str | None:
    """Why ``folder`` cannot be made or written (as numba tries it), or None if it can."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
    except OSError as error:
        return error.strerror or str(error)
    return None


def _temporary_cache() -> Path:
    """A cache folder in the temporary folder that only this user can write: the same one each
    run (so the next run loads what this one compiled) if it is this user's and closed to others
    (numba's cache holds pickles: code another user could plant would run), else a fresh one."""
    if os.name == "posix":
        uid = os.getuid()
        folder = Path(tempfile.gettempdir()) / f"collisionlab-numba-{uid}"
        try:
            folder.mkdir(mode=0o700, exist_ok=True)
            info = folder.lstat()
            private = stat.S_ISDIR(info.st_mode) and info.st_uid == uid and not info.st_mode & 0o022
            if private and _unwritable(folder) is None:
                return folder
        except OSError:
            pass
    return Path(tempfile.mkdtemp(prefix="collisionlab-numba-"))


def cache_files(package: Path) -> list[Path]:
    """numba's cache files of the functions defined in the folder ``package`` (numba keeps them
    in ``NUMBA_CACHE_DIR``, in a folder named after the source folder and a hash of its path, or
    in ``__pycache__`` beside the sources when no cache folder is set)."""
    package = package.resolve()
    folders = [package / "__pycache__", _cache_folder(package)]
    return [f for folder in dict.fromkeys(folders) if folder.exists() for f in folder.glob("*.nb[ic]")]


def holds(package: Path, stem: str, entry: str) -> bool:
    """Whether numba's cache seems to hold the function ``entry`` of ``package``'s file ``stem``
    (its index file is there): its first call then loads it in well under a second instead of
    compiling it. The one rule every kernel loader asks (the engine's, the event-driven loop's,
    the output writers'); a guess, since numba could still find the entry stale. Kernels inlined
    from other files are in the entry's own code, so only its files are looked for (a loader
    drops stale ones first: :func:`forget_stale`)."""
    return any(f.name.startswith(f"{stem}.{entry}-") for f in cache_files(package))


def _cache_folder(package: Path) -> Path:
    """The folder numba writes the cached code of the resolved folder ``package`` to."""
    if not os.environ.get("NUMBA_CACHE_DIR"):
        return package / "__pycache__"
    digest = hashlib.sha1(str(package).encode()).hexdigest()
    return Path(os.environ["NUMBA_CACHE_DIR"]) / f"{package.name}_{digest}"


def forget_stale(package: Path, stems: Iterable[str], sources: Iterable[Path]) -> None:
    """Delete the cached code of ``package``'s files ``stems`` when one of ``sources`` is newer:
    numba keys a cached function on its own file only, so code it inlined from another file (or
    a constant it baked in) would otherwise run stale after that file changed.

    Other processes (test workers, two runs started together) may do the same at the same time:
    a file that vanishes between the listing and its ``stat`` was removed by one of them and is
    skipped. Fresh files are never mixed with stale ones, because each process removes every
    stale file before it compiles, so whoever lists after that sees only fresh files."""
    wanted = tuple(f"{stem}." for stem in stems)
    written: dict[Path, float] = {}
    for f in cache_files(package):
        if f.name.startswith(wanted):
            try:
                written[f] = f.stat().st_mtime
            except FileNotFoundError:
                continue
    if written and min(written.values()) < max(s.stat().st_mtime for s in sources):
        for f in written:
            f.unlink(missing_ok=True)


@contextlib.contextmanager
def gc_paused() -> Iterator[None]:
    """No cyclic garbage collection inside the block (enabled again after it, if it was). For
    numba's import and the first call of a kernel, when numba loads its cached code: they make
    hundreds of thousands of objects that live until the process ends, and Python's collector
    would walk them all, several times over, while they are made (bench/README.md).

    >>> with gc_paused():
    ...     gc.isenabled()
    False
    >>> gc.isenabled()
    True
    """
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


@contextlib.contextmanager
def compile_lock(package: Path, stem: str) -> Iterator[None]:
    """Held while this process compiles the kernels of ``package``'s file ``stem``: another
    process that wants them at the same time (pytest-xdist workers, a sweep's workers, two runs
    started together) waits here, then loads what the first one cached instead of compiling the
    same code beside it. The lock is a file beside numba's cache (``flock``: the system drops it
    when its holder ends, however it ends). Where no lock can be taken (no ``fcntl`` on Windows,
    a cache folder that cannot be written), the block runs unlocked, as without this."""
    try:
        import fcntl
    except ImportError:
        fcntl = None  # type: ignore[assignment]
    folder = _cache_folder(package.resolve())
    handle = None
    if fcntl is not None:
        try:
            folder.mkdir(parents=True, exist_ok=True)
            handle = open(folder / f"{stem}.compiling.lock", "ab")  # noqa: SIM115 (closed below)
        except OSError:
            handle = None
    try:
        if handle is not None:
            fcntl.flock(handle, fcntl.LOCK_EX)  # waits while another process holds it
        yield
    finally:
        if handle is not None:
            handle.close()  # releases the lock


def kernel(function: Any, *, inline: bool = False, refcount: bool = True) -> Any:
    """``function`` compiled by numba as every kernel of the package is, whichever loader asks
    (the engine's kernel files, :mod:`collisionlab.engine.compiled`; the event-driven loop,
    :mod:`collisionlab.edmd.compile`; the output writers', :mod:`collisionlab.text_kernels`): on
    first call, cached on disk in :func:`numba_cache_dir` (``cache``), releasing the GIL while it
    runs (``nogil``: the writers' thread formats meanwhile), with ``error_model="numpy"`` (a
    division by zero gives inf, which the predictions use for "never", and no exception check
    in every division). ``inline``: numba inlines it into its callers (it is then compiled as
    each caller is); ``refcount=False``: compiled without reference counts (it allocates
    nothing, so a call passes its arrays as they are). numba keys a cached function on its own
    file only, so a loader drops its cached code when this file changes too
    (:func:`forget_stale`)."""
    use_user_cache()  # before numba is first imported: it reads NUMBA_CACHE_DIR then
    import numba

    options: dict[str, Any] = {"cache": True, "error_model": "numpy", "nogil": True}
    if inline:
        options["inline"] = "always"
    if not refcount:
        options["_nrt"] = False  # (not in numba's stubs)
    return numba.njit(**options)(function)


def compiled_once(dispatcher: Any) -> Any:
    """``dispatcher`` (a numba function that is called, not inlined, from compiled code), made to
    compile once whatever its callers pass: numba compiles a function once for each set of
    argument types it is called with, and types a constant as itself (``Literal[int](0)``) and
    an ``int32`` array's element as ``int32``, so a helper called with ``0`` at one site, a
    count at another and an array's element at a third was compiled three times. Here its
    arguments are typed before it compiles, a constant as its plain type and every integer as
    ``int64``, and the callers' values are converted to them (``tests/test_numba_cache.py``
    checks that no kernel is compiled twice). Calls from Python are typed from their values, as
    before."""
    typed_by_callers = dispatcher.get_call_template

    def one_set_of_types(args: tuple[Any, ...], kws: dict[str, Any]) -> Any:
        return typed_by_callers(tuple(_plain(arg) for arg in args), kws)

    dispatcher.get_call_template = one_set_of_types
    return dispatcher


def _plain(argument: Any) -> Any:
    """An argument's numba type without its constant (``Literal``), integers as ``int64``."""
    from numba.core import types

    plain = types.unliteral(argument)  # type: ignore[no-untyped-call]
    return types.int64 if isinstance(plain, types.Integer) else plain
