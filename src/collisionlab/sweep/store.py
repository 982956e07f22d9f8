"""The sweep's table on disk, kept as rows arrive: ``PREFIX.csv`` and ``PREFIX.parquet``.

* The CSV is the journal: each row is appended as one line the moment it arrives, and flushed
  (synced to disk at least every ``SYNC_SECONDS``), so an interrupted sweep (Ctrl-C, a killed
  process, the machine going down) keeps every row it finished, bar at most the last
  ``SYNC_SECONDS`` on a power cut. A last line cut short is dropped when the sweep resumes.
* The Parquet file is rewritten whole, atomically (:mod:`collisionlab.atomic`), at most every
  ``SNAPSHOT_SECONDS`` and at the end: it is never half-written.
* At the end (or on Ctrl-C) both are rewritten sorted by point and replica, so the same sweep
  gives the same files whatever order its rows came in.

Floats are written with ``repr`` (the shortest text that reads back to the same bits), so a
resumed table is the same to the last bit as one run straight through. Each row is kept once:
a second row for the same point and replica (a task that ran twice because its worker died
after finishing it) is dropped.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import time
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from ..atomic import atomic_path
from ..errors import CollisionLabError
from ..extras import require

__all__ = ["SNAPSHOT_SECONDS", "SYNC_SECONDS", "Column", "ResultStore", "column_type", "format_cell", "parse_cell"]

#: (name, type): type is "int", "float", "bool" or "str".
Column = tuple[str, str]
#: Seconds between two syncs of the CSV journal to disk.
SYNC_SECONDS = 0.5
#: Seconds between two rewrites of the Parquet file while the sweep runs.
SNAPSHOT_SECONDS = 2.0


def format_cell(value: object, kind: str) -> str:
    """The CSV text of one cell (empty for a missing value).

    >>> [format_cell(v, k) for v, k in ((0.1, "float"), (3, "int"), (None, "int"), (True, "bool"), ([1, 2], "str"))]
    ['0.1', '3', '', 'true', '[1, 2]']
    """
    if value is None:
        return ""
    if kind == "float":
        return repr(float(value))  # type: ignore[arg-type]
    if kind == "int":
        return str(int(value))  # type: ignore[call-overload]
    if kind == "bool":
        return "true" if value else "false"
    return value if isinstance(value, str) else json.dumps(value)


def parse_cell(text: str, kind: str) -> object:
    """The value of a CSV cell written by :func:`format_cell`.

    >>> parse_cell("0.30000000000000004", "float") == 0.1 + 0.2
    True
    >>> parse_cell("", "int") is None
    True
    """
    if text == "" and kind != "str":
        return None
    if kind == "float":
        return float(text)
    if kind == "int":
        return int(text)
    if kind == "bool":
        return text == "true"
    return text


def _line(cells: Iterable[str]) -> str:
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="\n").writerow(list(cells))
    return buffer.getvalue()


class ResultStore:
    """The rows of one sweep, in memory and on disk. ``columns`` fixes the table's columns and types;
    a row is a dict by column name, keyed by its ``(point, replica)``."""

    def __init__(self, prefix: str | Path, columns: list[Column]) -> None:
        prefix = Path(prefix)
        self.csv_path = prefix.with_name(prefix.name + ".csv")
        self.parquet_path = prefix.with_name(prefix.name + ".parquet")
        self.columns = columns
        self.rows: dict[tuple[int, int], dict[str, Any]] = {}
        self._journal: io.TextIOWrapper | None = None
        self._started = False
        self._last_sync = self._last_snapshot = time.monotonic()
        self._unsynced = False

    @property
    def names(self) -> list[str]:
        return [name for name, _ in self.columns]

    # --- opening ------------------------------------------------------------------------------
    def start(self, resume: bool) -> None:
        """Check the files before anything runs: absent (else refused unless ``resume``), or, with
        ``resume``, read their rows back (a cut last line dropped). Nothing is written until the
        first row arrives, so a sweep that fails before (no cluster) leaves no file behind."""
        exists = self.csv_path.exists()
        if exists and not resume:
            raise CollisionLabError(
                f"{self.csv_path} exists: --resume continues that sweep, or remove it (or pick --output) to start again"
            )
        if exists:
            self._read_back()
        self._started = True

    def _open_journal(self) -> io.TextIOWrapper:
        if self._journal is None:
            if not self.csv_path.exists():
                with atomic_path(self.csv_path) as temporary:
                    temporary.write_text(_line(self.names), encoding="utf-8")
            self._journal = open(self.csv_path, "a", encoding="utf-8", newline="")  # noqa: SIM115 (closed in close())
        return self._journal

    def _read_back(self) -> None:
        data = self.csv_path.read_bytes()
        complete = data[: data.rfind(b"\n") + 1]
        if len(complete) != len(data):  # the machine went down mid-line: that row is run again
            with open(self.csv_path, "r+b") as handle:
                handle.truncate(len(complete))
        lines = list(csv.reader(io.StringIO(complete.decode("utf-8"))))
        if not lines or lines[0] != self.names:
            raise CollisionLabError(
                f"{self.csv_path}: its columns are not this sweep's; it was written by another sweep "
                "(remove it or pick --output)"
            )
        kinds = [kind for _, kind in self.columns]
        for cells in lines[1:]:
            if len(cells) != len(kinds):
                raise CollisionLabError(f"{self.csv_path}: a row has {len(cells)} cells, expected {len(kinds)}")
            row = {name: parse_cell(text, kind) for (name, kind), text in zip(self.columns, cells, strict=True)}
            self.rows.setdefault((int(row["point"]), int(row["replica"])), row)  # type: ignore[call-overload]

    # --- adding -------------------------------------------------------------------------------
    def add(self, row: Mapping[str, Any]) -> bool:
        """Keep ``row`` and append it to the journal; False (and nothing written) if its point
        and replica are already there."""
        key = (int(row["point"]), int(row["replica"]))
        if key in self.rows:
            return False
        kept = {name: row.get(name) for name in self.names}
        self.rows[key] = kept
        if self._started:
            journal = self._open_journal()
            journal.write(_line(format_cell(kept[name], kind) for name, kind in self.columns))
            journal.flush()
            self._unsynced = True
        now = time.monotonic()
        if now - self._last_sync >= SYNC_SECONDS:
            self._sync()
        if self._started and now - self._last_snapshot >= SNAPSHOT_SECONDS:
            self.write_parquet()
        return True

    def _sync(self) -> None:
        if self._journal is not None and self._unsynced:
            os.fsync(self._journal.fileno())
            self._unsynced = False
        self._last_sync = time.monotonic()

    # --- writing whole ------------------------------------------------------------------------
    def sorted_rows(self) -> list[dict[str, Any]]:
        return [self.rows[key] for key in sorted(self.rows)]

    def write_parquet(self) -> None:
        """Rewrite the Parquet file with every row so far, sorted, atomically."""
        pa = require("pyarrow", "sweep", "sweeps")
        pq = require("pyarrow.parquet", "sweep", "sweeps")

        types = {"int": pa.int64(), "float": pa.float64(), "bool": pa.bool_(), "str": pa.string()}
        rows = self.sorted_rows()
        arrays = {}
        for name, kind in self.columns:
            values = [row[name] for row in rows]
            if kind == "str":
                values = [format_cell(v, kind) if v is not None else None for v in values]
            arrays[name] = pa.array(values, type=types[kind])
        with atomic_path(self.parquet_path) as temporary:
            pq.write_table(pa.table(arrays), temporary)
        self._last_snapshot = time.monotonic()

    def close(self) -> None:
        """Write both files whole and sorted (atomically), and close the journal (nothing, if no
        row ever came)."""
        if self._journal is not None:
            self._journal.close()
            self._journal = None
        if not self._started or not self.rows:
            return
        self._started = False
        with atomic_path(self.csv_path) as temporary, open(temporary, "w", encoding="utf-8", newline="") as handle:
            handle.write(_line(self.names))
            for row in self.sorted_rows():
                handle.write(_line(format_cell(row[name], kind) for name, kind in self.columns))
            handle.flush()
            os.fsync(handle.fileno())
        self.write_parquet()


def column_type(values: Iterable[object]) -> str:
    """The column type of a parameter from its values: bool, int, float, or str (anything else,
    vectors written as JSON).

    >>> column_type([1, 2]), column_type([1, 2.5]), column_type([True]), column_type([[1, 0], [2, 0]])
    ('int', 'float', 'bool', 'str')
    """
    values = list(values)
    if all(isinstance(v, bool) for v in values):
        return "bool"
    if all(isinstance(v, int) and not isinstance(v, bool) for v in values):
        return "int"
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in values):
        return "float"
    return "str"
