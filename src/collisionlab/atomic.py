"""Write a file atomically: a temporary file in the same folder, renamed over the target only
when complete, so a failed or interrupted run never leaves a half-written file.

A text stream (:func:`atomic_stream`: ``--output``, ``--events``, the menu's file) is, where the
system has ``O_TMPFILE`` (Linux, on most local file systems), a file with no name until it is
complete: even a SIGKILL or a crash leaves nothing beside the target. A path handed to another
writer (:func:`atomic_path`: pictures, sweep tables) has a name, hidden (``.NAME.XXXXXXXX.tmp.EXT``)
and removed on any error or handled signal; only a SIGKILL or a crash mid-write leaves it behind.

What is replaced is always a regular file, keeping its mode. A symlink is followed (its target
is replaced, the link stays); a special file (a FIFO, a device such as ``/dev/null``) cannot be
replaced and is written through instead, once the whole output is known (by every writer here:
the run's output, pictures, event files, sweep tables). Errors name the path the user gave,
never the temporary file.
"""

from __future__ import annotations

import codecs
import contextlib
import errno
import os
import secrets
import shutil
import stat
import sys
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO, TextIO

from .errors import InvalidInputError, escape_controls

__all__ = [
    "atomic_path",
    "atomic_stream",
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


#: Linux's flag for a file with no name until it is linked in (0: the system has none).
_O_TMPFILE: int = getattr(os, "O_TMPFILE", 0)
#: Where a descriptor can be named to link its file in (``linkat`` following ``/proc``'s link).
_FD_LINKS = "/proc/self/fd"


@contextlib.contextmanager
def atomic_stream(target: str | Path, newline: str | None = None) -> Iterator[TextIO]:
    """A UTF-8 text stream whose content replaces ``target`` when the block ends without error,
    as :func:`atomic_path` (a symlink followed, the mode kept, a FIFO or device written through,
    an :class:`OSError` naming ``target``). With ``O_TMPFILE`` the file has no name until it is
    complete, then is linked in under a hidden name and renamed over ``target`` at once: a
    process killed mid-write (SIGKILL) leaves nothing behind. Elsewhere, :func:`atomic_path`."""
    given = str(target)
    descriptor = None
    if _O_TMPFILE and os.path.isdir(_FD_LINKS) and not _special(given):
        real = Path(os.path.realpath(given))
        try:
            mode = stat.S_IMODE(real.stat().st_mode)
        except OSError:  # a new file: what open() would give it
            mode = 0o666 & ~_umask()
        try:
            descriptor = os.open(real.parent, _O_TMPFILE | os.O_WRONLY, 0o600)
        except OSError as error:
            # A file system without O_TMPFILE (EOPNOTSUPP; old kernels EISDIR): a named file.
            if error.errno not in (errno.EOPNOTSUPP, errno.EISDIR, errno.EINVAL):
                raise OSError(error.errno, error.strerror or str(error), given) from None
    if descriptor is None:
        with atomic_path(given) as temporary, open(temporary, "w", encoding="utf-8", newline=newline) as stream:
            yield stream
        return
    try:
        with os.fdopen(descriptor, "w", encoding="utf-8", newline=newline) as stream:
            yield stream
            stream.flush()
            os.fchmod(descriptor, mode)
            _link_in(descriptor, real)
    except OSError as error:
        # The target's folder, a write (a full disk, a file-size limit) or the rename: the user's path.
        raise OSError(error.errno, error.strerror or str(error), given) from None


def _link_in(descriptor: int, target: Path) -> None:
    """Give the unnamed file ``descriptor`` a hidden name beside ``target``, then rename it over
    ``target`` (a rename is atomic; a link cannot replace a file)."""
    folder = os.open(target.parent, os.O_RDONLY | os.O_DIRECTORY)
    try:
        while True:
            name = f".{target.stem}.{secrets.token_hex(4)}.tmp{target.suffix}"
            try:
                # With a folder's descriptor os.link calls linkat, which follows /proc's link to
                # the file (link(2), which it calls otherwise, would link the link: EXDEV).
                os.link(f"{_FD_LINKS}/{descriptor}", name, dst_dir_fd=folder, follow_symlinks=True)
                break
            except FileExistsError:
                continue
    finally:
        os.close(folder)
    named = target.parent / name
    try:
        os.replace(named, target)
    except BaseException:
        named.unlink(missing_ok=True)
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
        with atomic_stream(real) as stream:
            write(stream)
    except OSError as error:
        raise OSError(error.errno, error.strerror or str(error), str(target)) from None
