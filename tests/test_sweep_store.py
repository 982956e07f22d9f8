"""The sweep's table on disk: exact round trips, one row per point and replica, a cut line dropped."""

from __future__ import annotations

from pathlib import Path

import pyarrow.parquet as pq
import pytest

from collisionlab.errors import CollisionLabError
from collisionlab.sweep.store import ResultStore

COLUMNS = [
    ("point", "int"),
    ("replica", "int"),
    ("seed", "int"),
    ("body.ball.velocity", "str"),
    ("error", "str"),
    ("x", "float"),
    ("step", "int"),
    ("flag", "bool"),
]


def row(point: int, replica: int = 0, **values: object) -> dict[str, object]:
    base = {"point": point, "replica": replica, "seed": 7, "body.ball.velocity": "[1, -2, 0]", "error": ""}
    base.update({"x": 0.1 + 0.2, "step": 3, "flag": True})  # 0.30000000000000004: every bit must survive
    base.update(values)
    return base


def test_rows_survive_the_files_to_the_last_bit(tmp_path: Path) -> None:
    store = ResultStore(tmp_path / "t", COLUMNS)
    store.start(resume=False)
    rows = [
        row(1),
        row(0, 1, x=float("inf"), step=None, flag=False),
        row(0, 0, error='simulation.dt: must be > 0, "really"', x=None, step=None, flag=None),
        row(2, x=5e-324),
    ]
    for r in rows:
        assert store.add(r)
    store.close()
    again = ResultStore(tmp_path / "t", COLUMNS)
    again.start(resume=True)
    assert again.sorted_rows() == sorted(rows, key=lambda r: (r["point"], r["replica"]))
    table = pq.read_table(tmp_path / "t.parquet").to_pylist()
    assert table == again.sorted_rows()
    # the CSV is sorted by point and replica at the end, whatever order the rows came in
    lines = (tmp_path / "t.csv").read_text().splitlines()
    assert [line.split(",")[:2] for line in lines[1:]] == [["0", "0"], ["0", "1"], ["1", "0"], ["2", "0"]]
    assert "0.30000000000000004" in lines[3]
    again.close()


def test_a_row_is_kept_once(tmp_path: Path) -> None:
    store = ResultStore(tmp_path / "t", COLUMNS)
    store.start(resume=False)
    assert store.add(row(3)) is True
    assert store.add(row(3, x=9.0)) is False  # the same point and replica again (a task run twice)
    assert store.add(row(3, 1)) is True
    store.close()
    lines = (tmp_path / "t.csv").read_text().splitlines()
    assert len(lines) == 3 and store.rows[(3, 0)]["x"] == 0.1 + 0.2


def test_rows_are_on_disk_as_they_arrive_and_a_cut_line_is_dropped(tmp_path: Path) -> None:
    store = ResultStore(tmp_path / "t", COLUMNS)
    store.start(resume=False)
    store.add(row(5))
    store.add(row(6))
    # not closed: the machine goes down now, in the middle of writing a third line
    text = (tmp_path / "t.csv").read_text()
    assert len(text.splitlines()) == 3
    (tmp_path / "t.csv").write_text(text + "7,0,7,[1")
    resumed = ResultStore(tmp_path / "t", COLUMNS)
    resumed.start(resume=True)
    assert sorted(resumed.rows) == [(5, 0), (6, 0)]
    assert (tmp_path / "t.csv").read_text() == text  # the cut line is gone, the next row starts clean
    resumed.add(row(7))
    resumed.close()
    assert sorted(ResultStore(tmp_path / "t", COLUMNS).rows) == []  # a new store reads nothing until started
    final = ResultStore(tmp_path / "t", COLUMNS)
    final.start(resume=True)
    assert sorted(final.rows) == [(5, 0), (6, 0), (7, 0)]
    final.close()


def test_no_row_no_file(tmp_path: Path) -> None:
    store = ResultStore(tmp_path / "t", COLUMNS)
    store.start(resume=False)
    store.close()  # e.g. the cluster could not be reached
    assert list(tmp_path.iterdir()) == []


def test_an_existing_table_needs_resume_and_the_same_columns(tmp_path: Path) -> None:
    store = ResultStore(tmp_path / "t", COLUMNS)
    store.start(resume=False)
    store.add(row(0))
    store.close()
    with pytest.raises(CollisionLabError, match="exists: --resume"):
        ResultStore(tmp_path / "t", COLUMNS).start(resume=False)
    with pytest.raises(CollisionLabError, match="another sweep"):
        ResultStore(tmp_path / "t", COLUMNS[:-1]).start(resume=True)
