"""Sweeps and ensembles: one scenario (or the gas) run over a grid of parameter values and seeds,
one Dask task per row, into one table (Parquet and CSV). See the README, "Sweeps".

:mod:`.spec` reads the sweep file (:mod:`.paths`: where a parameter points in its base),
:mod:`.points` runs one row, :mod:`.store` keeps the table on disk as rows arrive, :mod:`.runner`
hands the rows to ``dask.distributed``, :mod:`.plot` draws it.
"""

from __future__ import annotations

from .points import Task, run_point
from .spec import SweepError, SweepSpec, load_sweep, parse_sweep

__all__ = ["SweepError", "SweepSpec", "Task", "load_sweep", "parse_sweep", "run_point"]
