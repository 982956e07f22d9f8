"""Run a sweep on ``dask.distributed``: one task per point and replica, rows kept as they arrive.

By default a ``LocalCluster`` of one single-threaded worker process per core of this machine
(processes, not threads: the scalar simulation holds the GIL); ``scheduler="tcp://HOST:PORT"``
uses a running cluster instead. Dask runs a task again elsewhere when its worker dies; a task
that keeps losing its workers is submitted afresh up to ``RESUBMITS`` times, and if it still
fails its row is left unwritten (``--resume`` runs it), never written twice (the store keeps one
row per point and replica).
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import time
import uuid
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..errors import CollisionLabError
from ..extras import require
from .points import Task, metric_columns, run_point
from .spec import SweepSpec, Value
from .store import Column, ResultStore, column_type

if TYPE_CHECKING:
    from distributed import Client

__all__ = [
    "CONNECT_SECONDS",
    "RESUBMITS",
    "SweepOutcome",
    "dask_client",
    "machine_workers",
    "run_sweep",
    "table_columns",
]

#: Seconds to wait for a scheduler given by address before giving up.
CONNECT_SECONDS = 10.0
#: Times a task whose workers keep dying is submitted again before its row is left for --resume.
RESUBMITS = 2

#: ``progress(rows_done, rows_total, seconds_elapsed, rows_done_by_this_run)``.
Progress = Callable[[int, int, float, int], None]


@dataclass(frozen=True)
class SweepOutcome:
    """What a sweep did: rows in the sweep, rows found already written (``--resume``), rows written
    now, rows whose point reported an error, rows left unwritten (workers lost), and time."""

    total: int
    skipped: int
    written: int
    errors: int
    lost: int
    seconds: float
    workers: int


def machine_workers() -> int:
    """One worker per core this process may run on."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


def table_columns(spec: SweepSpec) -> list[Column]:
    """The table's columns: point, replica, seed, each parameter, error, then the metrics'."""
    parameters = [(p.path, column_type(p.values)) for p in spec.parameters]
    metrics = metric_columns(spec.kind, spec.metrics)
    return [("point", "int"), ("replica", "int"), ("seed", "int"), *parameters, ("error", "str"), *metrics]


def _cell(value: Value, kind: str) -> object:
    """A parameter's value as its column holds it (so a row read back from the CSV is equal)."""
    if kind == "float":
        return float(value)  # type: ignore[arg-type]
    if kind == "str":
        return value if isinstance(value, str) else json.dumps(value)
    return value


@contextlib.contextmanager
def dask_client(scheduler: str | None = None, workers: int | None = None) -> Iterator[Client]:
    """A ``distributed.Client``: on the cluster at ``scheduler``, or on a new local cluster of
    ``workers`` single-threaded processes (default :func:`machine_workers`), closed on leaving."""
    require("distributed", "sweep", "sweeps")
    from distributed import Client, LocalCluster

    if scheduler is not None:
        try:
            client = Client(scheduler, timeout=CONNECT_SECONDS)
        except (OSError, TimeoutError, ValueError) as error:
            raise CollisionLabError(f"--scheduler: cannot reach {scheduler}: {error}") from None
        with client:
            yield client
        return
    cluster = LocalCluster(
        n_workers=workers or machine_workers(),
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        # Its HTTP server (there even with no dashboard) on a free port: on 8787, a second sweep
        # running at once warned "Port 8787 is already in use".
        scheduler_kwargs={"dashboard_address": ":0"},
        silence_logs=logging.CRITICAL,  # its own errors (a heartbeat cut at shutdown) are not ours to print
    )
    with cluster, Client(cluster) as client:
        yield client


def run_sweep(
    spec: SweepSpec,
    store: ResultStore,
    client: Client,
    progress: Progress | None = None,
    check: Callable[[], None] | None = None,
) -> SweepOutcome:
    """Run every row of ``spec`` that ``store`` does not hold yet, adding each row as it arrives.
    ``check`` runs as each row arrives and once at the end (the CLI raises an interrupt there that
    Python may have dropped on the way). The store is closed (both files written whole) on the way
    out, also on Ctrl-C."""
    from distributed import as_completed

    columns = dict(store.columns)
    points = {point.index: point for point in spec.points()}
    tasks = [task for task in spec.tasks() if task.key not in store.rows]
    total, skipped = len(points) * spec.replicas, len(store.rows)
    run_id = uuid.uuid4().hex[:8]
    began = time.monotonic()
    written = lost = 0

    def key(task: Task, attempt: int) -> str:
        return f"collisionlab-sweep-{run_id}-{task.point}-{task.replica}-{attempt}"

    try:  # one batch (client.map): submitting task by task costs several ms a task
        submitted = client.map(run_point, tasks, key=[key(task, 0) for task in tasks], pure=False) if tasks else []
        futures = {future: (task, 0) for future, task in zip(submitted, tasks, strict=True)}
        pending = as_completed(list(futures))
        for future in pending:
            if check is not None:
                check()
            task, attempt = futures.pop(future)
            if future.status != "finished":  # its workers died (KilledWorker) or it was lost
                if attempt < RESUBMITS:
                    again = client.submit(run_point, task, key=key(task, attempt + 1), pure=False)
                    futures[again] = (task, attempt + 1)
                    pending.add(again)
                else:
                    lost += 1
                continue
            row = future.result()
            values = points[task.point].values
            row.update({path: _cell(value, columns[path]) for path, value in values.items()})
            if store.add(row):
                written += 1
                if progress is not None:
                    progress(skipped + written, total, time.monotonic() - began, written)
        if check is not None:
            check()
    finally:
        store.close()
    errors = sum(1 for row in store.rows.values() if row["error"])
    workers = len(client.scheduler_info().get("workers", {}))
    return SweepOutcome(total, skipped, written, errors, lost, time.monotonic() - began, workers)
