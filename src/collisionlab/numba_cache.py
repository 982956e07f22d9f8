"""Where numba keeps collisionlab's compiled kernels: the user's cache folder, never the
installed package (site-packages may be read-only, shared, or wiped by a reinstall).

numba reads ``NUMBA_CACHE_DIR`` once, when it is first imported, so :func:`use_user_cache` must
run before the first ``import numba``; a folder the user set is kept.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

__all__ = ["numba_cache_dir", "use_user_cache"]


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
    """Point numba's cache at :func:`numba_cache_dir`, unless ``NUMBA_CACHE_DIR`` is already set."""
    os.environ.setdefault("NUMBA_CACHE_DIR", str(numba_cache_dir()))
