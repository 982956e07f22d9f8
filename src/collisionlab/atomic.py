"""Write a file atomically: a temporary file in the same folder, renamed over the target only
when complete, so a failed or interrupted run never leaves a half-written file."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path

__all__ = ["atomic_path", "write_text_atomically"]


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_path(target: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside ``target``; on success it replaces ``target``, on any
    error (or Ctrl-C) it is removed and ``target`` is left as it was."""
    target = Path(target)
    folder = target.parent if str(target.parent) else Path(".")
    # Same folder (so the rename is atomic) and same extension (writers that pick the format
    # from the name, such as matplotlib, still see it).
    handle, name = tempfile.mkstemp(prefix=f".{target.stem}.", suffix=f".tmp{target.suffix}", dir=folder)
    os.close(handle)
    temporary = Path(name)
    try:
        yield temporary
        os.chmod(temporary, 0o666 & ~_umask())  # mkstemp makes it private; this is an ordinary file
        os.replace(temporary, target)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise


def write_text_atomically(target: str | Path, produce: Callable[[], str]) -> None:
    """Write ``produce()`` to ``target`` atomically (``produce`` runs before anything is replaced)."""
    text = produce()
    with atomic_path(target) as temporary:
        temporary.write_text(text, encoding="utf-8")
