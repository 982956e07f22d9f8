"""``collisionlab sweep FILE.toml``: run a sweep on Dask and print its table.

Thin: it parses the flags, reads the sweep file (:mod:`collisionlab.sweep.spec`), hands it to
:mod:`collisionlab.sweep.runner`, and prints the progress, the table and where the files are.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path
from typing import Any

from ..atomic import check_target
from ..demos import builtin_sweep_path
from ..errors import InvalidInputError
from ..extras import require
from .interrupts import Stopped, remembered_interrupts
from .progress import REDRAW_EVERY, SHOW_AFTER, log_interval
from .run_command import positive_int
from .streams import Streams

__all__ = ["add_parser", "run"]

_PROG = "collisionlab sweep"
#: Rows of the table printed at most (the files hold them all).
_PRINT_ROWS = 60
EXIT_DATA = 65
#: What a sweep imports from the `sweep` extra: the cluster, the Parquet file, the printed table.
SWEEP_MODULES = ("distributed", "pyarrow", "pandas")


def add_parser(subparsers: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    """Add the ``sweep`` subcommand (sets ``func=run``)."""
    parser = subparsers.add_parser(
        "sweep",
        help="run a scenario or the gas over many parameter values and seeds, on Dask",
        description=(
            "Run every point of a sweep file's [sweep] table (a scenario, a demo or the gas; parameters by "
            "dotted path; replicas), one Dask task per row, on a local cluster (default: one worker per core) "
            "or on a running one (--scheduler). Rows go to PREFIX.csv and PREFIX.parquet as they arrive."
        ),
    )
    parser.add_argument("file", metavar="FILE.toml", help="the sweep file")
    parser.add_argument(
        "--output",
        metavar="PREFIX",
        help="write PREFIX.csv and PREFIX.parquet (default: the file's name, here); x.csv or x.parquet writes both",
    )
    parser.add_argument("--workers", type=positive_int, metavar="N", help="local workers (default: one per core)")
    parser.add_argument("--scheduler", metavar="tcp://HOST:PORT", help="use the running Dask cluster at this address")
    parser.add_argument("--resume", action="store_true", help="continue an interrupted sweep: skip the rows written")
    parser.add_argument("--plot", metavar="FILE.png", help="draw a metric against a swept parameter")
    parser.add_argument("--quiet", action="store_true", help="no progress and no table, only the summary")
    parser.set_defaults(func=run)


class _Progress:
    """Rows done / total and the time left: redrawn on a terminal, a line every few seconds in a log."""

    def __init__(self, streams: Streams, quiet: bool) -> None:
        self.streams, self.quiet = streams, quiet
        self.last = time.monotonic()
        self.drawn = False
        self.log_every = log_interval(streams, quiet)

    def __call__(self, done: int, total: int, elapsed: float, done_now: int) -> None:
        now = time.monotonic()
        interval = REDRAW_EVERY if self.streams.err_terminal else self.log_every
        if self.quiet or (now - self.last < interval and done < total) or elapsed < SHOW_AFTER:
            return
        self.last = now
        left = (total - done) * elapsed / done_now if done_now else math.nan
        text = f"{_PROG}: {done}/{total} rows, {elapsed:.0f} s, about {left:.0f} s left"
        if self.streams.err_terminal:
            self.streams.stderr.write(f"\r{text}   ")
            self.streams.stderr.flush()
            self.drawn = True
        else:
            self.streams.err(text)

    def close(self) -> None:
        if self.drawn:
            self.streams.stderr.write("\n")


def _table(rows: list[dict[str, Any]], columns: list[tuple[str, str]]) -> str:
    import pandas as pd

    frame = pd.DataFrame(rows[:_PRINT_ROWS], columns=[name for name, _ in columns])
    frame = frame.astype({name: "Int64" for name, kind in columns if kind == "int"})  # whole numbers stay whole
    if not frame["error"].astype(bool).any():
        frame = frame.drop(columns="error")
    text: str = frame.to_string(index=False, na_rep="-")
    return text + (f"\n... {len(rows) - _PRINT_ROWS} more rows in the files" if len(rows) > _PRINT_ROWS else "")


def run(args: argparse.Namespace, streams: Streams) -> int:
    """0 every row written, 65 a bad sweep file, 2 bad flags, 1 rows left unwritten or a failure
    (one of them: the ``sweep`` extra is not installed)."""
    for module in SWEEP_MODULES:  # one line naming the extra, before anything is read or run
        require(module, "sweep", "sweeps")
    from ..sweep.runner import dask_client, run_sweep, table_columns
    from ..sweep.spec import SweepError, load_sweep
    from ..sweep.store import ResultStore

    if args.scheduler is not None and args.workers is not None:
        streams.err(f"{_PROG}: --workers: only for the local cluster; a --scheduler has its own workers")
        return 2
    try:
        spec = load_sweep(args.file if Path(args.file).exists() else builtin_sweep_path(args.file) or args.file)
    except SweepError as error:
        streams.err(f"{_PROG}: {error}")
        return EXIT_DATA
    if args.plot is not None:
        from ..plotting.static import check_plot_path

        check_plot_path(args.plot)  # a bad path fails now, not after the sweep
    prefix = args.output or Path(args.file).stem
    if Path(prefix).suffix in (".csv", ".parquet"):  # a file named: the pair beside it, not x.csv.csv
        prefix = str(Path(prefix).with_suffix(""))
    columns = table_columns(spec)
    store = ResultStore(prefix, columns)
    for path in (store.csv_path, store.parquet_path):  # as run --output: checked before the sweep
        check_target(str(path), "--output")
    store.start(args.resume)
    total = len(spec.points()) * spec.replicas
    if args.resume and store.rows:
        streams.err(f"{_PROG}: {len(store.rows)} of {total} rows already in {store.csv_path}: skipping them")
    progress = _Progress(streams, args.quiet)
    try:
        if len(store.rows) < total:
            with remembered_interrupts() as interrupt, dask_client(args.scheduler, args.workers) as client:
                outcome = run_sweep(spec, store, client, progress, interrupt.check)
        else:
            store.close()
            outcome = None
    except KeyboardInterrupt as stop:  # Ctrl-C, or SIGTERM or SIGHUP handled as it (Stopped)
        progress.close()
        how = f"stopped by {stop.name}" if isinstance(stop, Stopped) else "interrupted"
        streams.err(
            f"\n{_PROG}: {how}: {len(store.rows)} of {total} rows are in {store.csv_path}; "
            "run again with --resume to finish"
        )
        return stop.status if isinstance(stop, Stopped) else 130
    progress.close()
    rows = store.sorted_rows()
    if not args.quiet:
        streams.out(_table(rows, columns))
    errors = sum(1 for row in rows if row["error"])
    where = f"{store.csv_path} and {store.parquet_path}"
    if outcome is None:
        streams.err(f"{_PROG}: nothing to run: all {total} rows are in {where}")
    else:
        streams.err(
            f"{_PROG}: {outcome.written} rows written ({outcome.skipped} already there) to {where} "
            f"in {outcome.seconds:.1f} s on {outcome.workers} worker{'s' if outcome.workers != 1 else ''}"
        )
    if errors:
        streams.err(f"{_PROG}: {errors} rows report an error (see the error column)")
    if args.plot is not None:
        try:
            from ..sweep.plot import save_sweep_plot

            note = save_sweep_plot(args.plot, spec, columns, rows)
        except InvalidInputError as error:
            streams.err(f"{_PROG}: {error}")
            return 2
        streams.err(f"wrote {args.plot}" + (f" ({note})" if note else ""))
    if outcome is not None and outcome.lost:
        streams.err(f"{_PROG}: {outcome.lost} rows not written (their workers kept failing); --resume runs them")
        return 1
    return 0
