"""collisionlab.atomic: files written whole or not at all, through special files, naming the
user's path (issue 11, item 10: every writer, not only --output)."""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest

from collisionlab.atomic import atomic_path
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
