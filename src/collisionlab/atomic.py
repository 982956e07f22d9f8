"""Write a file atomically: a temporary file in the same folder, renamed over the target only
when complete, so a failed or interrupted run never leaves a half-written file.

What is replaced is always a regular file, keeping its mode. A symlink is followed (its target
is replaced, the link stays); a special file (a FIFO, a device such as ``/dev/null``) cannot be
replaced and is written through instead, once the whole output is known (by every writer here:
the run's output, pictures, event files, sweep tables). Errors name the path the user gave,
never the temporary file.
"""

from __future__ import annotations

import codecs
import contextlib
import os
import shutil
import stat
import sys
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO

from .errors import InvalidInputError, escape_controls

__all__ = [
    "atomic_path",
    "check_target",
    "copy_file",
    "write_atomically",
    "write_text_atomically",
]


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _special(path: str) -> bool:
    """Whether ``path`` is (or links to) a FIFO, a device or a socket: asked of the kernel, which
    follows ``/dev/stdout`` to a pipe (its name, ``/proc/PID/fd/pipe:[N]``, cannot be opened)."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return False
    return not stat.S_ISREG(mode) and not stat.S_ISDIR(mode)


def check_target(path: str, option: str) -> Path:
    """Before a run: ``path`` can be written (its folder exists, it is not a folder), else
    :class:`InvalidInputError` naming ``option`` and ``path``.

    >>> check_target("", "--output")
    Traceback (most recent call last):
    ...
    collisionlab.errors.InvalidInputError: --output: must be a file name, not empty
    """
    if not path:
        raise InvalidInputError(option, "must be a file name, not empty")
    shown = escape_controls(path)
    if _special(path):  # written into as it is named (/dev/stdout into a pipe)
        if not os.access(path, os.W_OK):
            raise InvalidInputError(option, f"cannot write {shown}: permission denied")
        return Path(path)
    target = Path(os.path.realpath(path))  # a symlink is written through: its target counts
    folder = target.parent
    if target.is_dir():
        raise InvalidInputError(option, f"cannot write {shown}: it is a folder")
    if not folder.is_dir():
        raise InvalidInputError(
            option, f"cannot write {shown}: the folder {escape_controls(str(folder))} does not exist"
        )
    if target.exists() and not target.is_file():  # a FIFO or a device: written through
        if not os.access(target, os.W_OK):
            raise InvalidInputError(option, f"cannot write {shown}: permission denied")
    elif not os.access(folder, os.W_OK | os.X_OK):
        raise InvalidInputError(
            option, f"cannot write {shown}: the folder {escape_controls(str(folder))} is not writable"
        )
    return target


@contextlib.contextmanager
def atomic_path(target: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside ``target``; on success it replaces ``target``, on any
    error (or Ctrl-C, or SIGTERM handled as it) it is removed and ``target`` is left as it was.
    A symlink ``target`` is followed; an existing file's mode is kept. A special file (a FIFO, a
    device such as ``/dev/null``) cannot be replaced: the temporary file is then made in the
    system's temporary folder and, once complete, its bytes are written into ``target``."""
    given = str(target)
    special = _special(given)
    target = Path(given) if special else Path(os.path.realpath(target))
    try:
        mode = stat.S_IMODE(target.stat().st_mode)
    except OSError:  # a new file: what open() would give it
        mode = 0o666 & ~_umask()
    # Same folder (so the rename is atomic) and same extension (writers that pick the format
    # from the name, such as matplotlib, still see it).
    folder = None if special else target.parent
    try:
        handle, name = tempfile.mkstemp(prefix=f".{target.stem}.", suffix=f".tmp{target.suffix}", dir=folder)
    except OSError as error:  # (the folder is gone, or not writable): name the user's path
        raise OSError(error.errno, error.strerror or str(error), given) from None
    temporary = Path(name)
    try:
        os.close(handle)
        yield temporary
        if special:
            with open(temporary, "rb") as source, open(target, "wb") as sink:
                shutil.copyfileobj(source, sink)
            temporary.unlink()
        else:
            os.chmod(temporary, mode)  # mkstemp makes it private
            os.replace(temporary, target)
    except OSError as error:
        temporary.unlink(missing_ok=True)
        # About the temporary file or the target, or a write that names no file (a full disk,
        # a file-size limit: the writes go to the temporary file): the user's path.
        if error.filename in (name, str(target), None):
            raise OSError(error.errno, error.strerror or str(error), given) from None
        raise
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise


def write_text_atomically(target: str | Path, produce: Callable[[], str]) -> None:
    """Write ``produce()`` to ``target`` atomically (``produce`` runs before anything is
    replaced); a FIFO or a device is written through. An :class:`OSError` names ``target``."""
    text = produce()
    write_atomically(target, lambda stream: stream.write(text))


def _regular(stream: IO[str] | IO[bytes]) -> int | None:
    """The descriptor of ``stream`` if it is a regular file's, else ``None``."""
    try:
        descriptor = stream.fileno()
        return descriptor if stat.S_ISREG(os.fstat(descriptor).st_mode) else None
    except (AttributeError, OSError, ValueError):  # io.UnsupportedOperation is an OSError and a ValueError
        return None


#: Whether the kernel copies between two files (Linux's sendfile; macOS's sends to sockets
#: only, Windows has none), as :mod:`shutil` decides it.
_SENDFILE = hasattr(os, "sendfile") and sys.platform.startswith("linux")


def copy_file(source: IO[str] | IO[bytes], target: IO[str]) -> None:
    """Write the whole of ``source`` (a file, from its start, whatever has been read of it; text,
    or UTF-8 bytes) at the end of what was written to ``target``. Between two regular files on
    Linux the kernel copies the bytes (``os.sendfile``: a run's JSON can be hundreds of
    megabytes, not decoded and encoded again); otherwise (a pipe, a device, a stream in memory,
    another system) they go through Python, a megabyte at a time."""
    source_descriptor, target_descriptor = _regular(source), _regular(target)
    if not _SENDFILE or source_descriptor is None or target_descriptor is None:
        source.seek(0)
        # Bytes are decoded as they come: a character cut between two pieces waits for the next.
        decoder = codecs.getincrementaldecoder("utf-8")()
        for piece in iter(lambda: source.read(1 << 20), source.read(0)):
            target.write(decoder.decode(piece) if isinstance(piece, bytes) else piece)
        target.write(decoder.decode(b"", final=True))
        return
    source.flush()
    target.flush()
    offset, size = 0, os.fstat(source_descriptor).st_size
    while offset < size:
        sent = os.sendfile(target_descriptor, source_descriptor, offset, size - offset)
        if sent == 0:  # the source was cut short meanwhile
            break
        offset += sent
    target.seek(0, os.SEEK_END)  # the stream's idea of its position follows the descriptor's


def write_atomically(target: str | Path, write: Callable[[IO[str]], object]) -> None:
    """Call ``write`` with a text stream whose content replaces ``target`` atomically once
    ``write`` returns; a FIFO or a device is written through. An :class:`OSError` names
    ``target``."""
    real = Path(os.path.realpath(target))
    try:
        if real.exists() and not real.is_file():  # a FIFO or a device: it cannot be replaced
            with open(real, "w", encoding="utf-8") as stream:
                write(stream)
            return
        with atomic_path(real) as temporary, open(temporary, "w", encoding="utf-8") as stream:
            write(stream)
    except OSError as error:
        raise OSError(error.errno, error.strerror or str(error), str(target)) from None
