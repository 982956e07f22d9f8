"""collisionlab.atomic: files written whole or not at all, through special files, naming the
user's path (issue 11, item 10: every writer, not only --output)."""

from __future__ import annotations

import io
import os
import signal
import stat
import tempfile
import threading
from pathlib import Path
from typing import Any

import pytest

from collisionlab import atomic
from collisionlab.atomic import atomic_path, copy_file
from tests.cli_helpers import files_in


def test_a_fifo_is_written_through_not_replaced(tmp_path: Path) -> None:
    # The pictures, --events, the sweep's tables and the menu's file go through atomic_path: it
    # replaced a FIFO (or, as root, /dev/null) by a regular file, leaving the reader with nothing.
    fifo = tmp_path / "out.csv"
    os.mkfifo(fifo)
    reader = os.open(fifo, os.O_RDONLY | os.O_NONBLOCK)  # a reader is there: the writer's open does not block
    try:
        with atomic_path(fifo) as temporary:
            temporary.write_text("a,b\n1,2\n")
        try:
            received = os.read(reader, 1 << 16)
        except BlockingIOError:  # nothing was written into the pipe
            received = b""
    finally:
        os.close(reader)
    assert stat.S_ISFIFO(fifo.stat().st_mode)
    assert received == b"a,b\n1,2\n"
    assert files_in(tmp_path) == ["out.csv"]  # no temporary file left beside it


def test_a_symlink_is_followed_and_a_regular_file_keeps_its_mode(tmp_path: Path) -> None:
    target = tmp_path / "data.txt"
    target.write_text("old")
    target.chmod(0o600)
    link = tmp_path / "link.txt"
    link.symlink_to(target.name)
    with atomic_path(link) as temporary:
        temporary.write_text("new")
    assert link.is_symlink() and target.read_text() == "new"
    assert stat.S_IMODE(target.stat().st_mode) == 0o600


def test_a_missing_folder_is_reported_with_the_users_path_not_the_temporary_file(tmp_path: Path) -> None:
    # collisionlab sweep --output missing/x said "missing/.x.rznyb3az.tmp.csv: No such file or directory".
    target = tmp_path / "missing" / "x.csv"
    with pytest.raises(OSError) as caught, atomic_path(target) as temporary:
        temporary.write_text("never")
    assert caught.value.filename == str(target)
    assert not (tmp_path / "missing").exists()


def test_a_failure_leaves_the_target_as_it_was_and_no_temporary_file(tmp_path: Path) -> None:
    target = tmp_path / "keep.txt"
    target.write_text("old")
    with pytest.raises(KeyboardInterrupt), atomic_path(target) as temporary:
        temporary.write_text("half")
        raise KeyboardInterrupt
    assert target.read_text() == "old" and files_in(tmp_path) == ["keep.txt"]


@pytest.mark.parametrize("binary", [False, True])
@pytest.mark.parametrize("sendfile", [True, False])
@pytest.mark.parametrize("target_kind", ["file", "memory", "pipe"])
def test_copy_file_appends_the_whole_source_to_what_was_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, target_kind: str, sendfile: bool, binary: bool
) -> None:
    # Between two files on disk on Linux the kernel copies the bytes (os.sendfile); the stream
    # must then go on writing after them. Into memory or a pipe, or on another system (macOS's
    # sendfile sends to sockets only, Windows has none), the copy goes through Python.
    monkeypatch.setattr(atomic, "_SENDFILE", atomic._SENDFILE and sendfile)
    # 1.7 MB, not ASCII. A source of bytes (UTF-8) is read a megabyte at a time: a repeat is 17
    # bytes and its snowman (3 bytes) starts at its 13th, so the snowman of repeat 61,681 starts
    # at byte 3 + 61,680 * 17 + 12 = 1,048,575 and the first megabyte (1,048,576) ends inside it.
    text = "abc" + "événement ☃,\n" * 100_000
    received: list[bytes] = []
    if target_kind == "file":
        target: Any = open(tmp_path / "out.txt", "w", encoding="utf-8")  # noqa: SIM115
    elif target_kind == "memory":
        target = io.StringIO()
    else:
        reader, writer = os.pipe()
        target = open(writer, "w", encoding="utf-8")  # noqa: SIM115
        drain = threading.Thread(target=lambda: received.extend(iter(lambda: os.read(reader, 1 << 16), b"")))
        drain.start()
    with tempfile.TemporaryFile("w+b") if binary else tempfile.TemporaryFile("w+", encoding="utf-8") as source:
        source.write(text.encode() if binary else text)  # type: ignore[arg-type]
        source.seek(100)  # whatever has been read of it: the whole is copied
        target.write("head ")
        copy_file(source, target)
        target.write(" middle ")
        copy_file(source, target)
        target.write(" tail")
    if target_kind == "memory":
        written = target.getvalue()
    else:
        target.close()
        if target_kind == "file":
            written = (tmp_path / "out.txt").read_text(encoding="utf-8")
        else:
            drain.join()
            os.close(reader)
            written = b"".join(received).decode()
    assert written == f"head {text} middle {text} tail"


def test_output_to_dev_stdout_goes_into_the_pipe() -> None:
    # "--output /dev/stdout | cat" exited 1, "cannot write /dev/stdout: No such file or
    # directory": the link was resolved to /proc/PID/fd/pipe:[N], which cannot be opened by name.
    import subprocess

    from tests.cli_helpers import SCRIPT

    argv = [str(SCRIPT), "run", "head-on", "--steps", "3", "--format", "csv", "--output", "/dev/stdout"]
    done = subprocess.run(argv, capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[1] == "0,0,0,0,0,2,0,0,4,0,0,-1,0,0"  # head-on's start, as its file says
    assert len(done.stdout.splitlines()) == 5  # the header and steps 0 to 3


def test_a_file_size_limit_names_the_output_and_leaves_no_file(tmp_path: Path) -> None:
    # "(ulimit -f 20; collisionlab run head-on --format json --output x.json)" printed
    # "collisionlab: : File too large": the write named no file.
    import resource
    import subprocess

    from tests.cli_helpers import SCRIPT

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (20 * 1024, 20 * 1024))

    target = tmp_path / "x.json"
    argv = [str(SCRIPT), "run", "head-on", "--format", "json", "--output", str(target)]
    done = subprocess.run(argv, capture_output=True, text=True, check=False, preexec_fn=limit)
    assert done.returncode == 1
    assert done.stderr.strip() == f"collisionlab: --output: cannot write {target}: File too large"
    assert files_in(tmp_path) == []


def _killed_mid_write(target: Path) -> None:
    """A child process that starts writing ``target`` through atomic_stream and is killed
    (SIGKILL: no handler, no clean-up runs) in the middle of it."""
    pid = os.fork()
    if pid == 0:  # the child: write, then die at once
        try:
            with atomic.atomic_stream(target) as stream:
                stream.write("half of it\n")
                stream.flush()
                os.kill(os.getpid(), signal.SIGKILL)
        finally:
            os._exit(1)  # never reached: the kill is immediate
    _, status = os.waitpid(pid, 0)
    assert os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGKILL


@pytest.mark.skipif(not atomic._O_TMPFILE or not os.path.isdir(atomic._FD_LINKS), reason="no O_TMPFILE here")
def test_a_stream_killed_mid_write_leaves_nothing_beside_the_target(tmp_path: Path) -> None:
    # atomic_path's named temporary file stays behind after a SIGKILL (".out.rowot2cp.tmp.txt");
    # with O_TMPFILE the file has no name until it is complete.
    target = tmp_path / "out.txt"
    _killed_mid_write(target)
    assert files_in(tmp_path) == []
    target.write_text("old")
    _killed_mid_write(target)
    assert files_in(tmp_path) == ["out.txt"] and target.read_text() == "old"


@pytest.mark.parametrize("unnamed", [True, False])
def test_a_stream_replaces_the_target_whole_keeping_its_mode_and_links(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, unnamed: bool
) -> None:
    if not unnamed:  # a system without O_TMPFILE: a named temporary file, as atomic_path
        monkeypatch.setattr(atomic, "_O_TMPFILE", 0)
    target = tmp_path / "data.txt"
    target.write_text("old")
    target.chmod(0o640)
    link = tmp_path / "link.txt"
    link.symlink_to(target.name)
    with atomic.atomic_stream(link) as stream:
        stream.write("new")
        assert target.read_text() == "old"  # nothing replaced before the end
    assert link.is_symlink() and target.read_text() == "new"
    assert stat.S_IMODE(target.stat().st_mode) == 0o640
    with pytest.raises(KeyboardInterrupt), atomic.atomic_stream(target) as stream:
        stream.write("half")
        raise KeyboardInterrupt
    assert target.read_text() == "new" and files_in(tmp_path) == ["data.txt", "link.txt"]
    fresh = tmp_path / "new.txt"
    with atomic.atomic_stream(fresh) as stream:
        stream.write("x")
    assert stat.S_IMODE(fresh.stat().st_mode) == 0o666 & ~atomic._umask()
    with pytest.raises(OSError) as caught, atomic.atomic_stream(tmp_path / "missing" / "x.txt") as stream:
        stream.write("never")
    assert caught.value.filename == str(tmp_path / "missing" / "x.txt")
