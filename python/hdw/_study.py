"""Study files run in-process: :func:`run_study`."""

from __future__ import annotations

import os
from typing import Any, Optional, Sequence

from . import _hdw
from ._io import out_dir, read_profile, write_table, write_text
from ._tables import table


def run_study(
    path: "os.PathLike[str] | str",
    out: "Optional[os.PathLike[str] | str]" = None,
    threads: Optional[int] = None,
    parts: Optional[Sequence[str]] = None,
) -> Any:
    """Run a study file (see studies/README.md) in this process and return its runs table.

    The study is read and checked, expanded and run exactly as ``hdw study`` does (the same
    library code: hd-sweep's checker, expansion, parallel runner and table builder), with
    the GIL released while the runs go.

    Args:
        path: the study file (TOML).
        out: an output folder. When given, writes there what ``hdw study --no-report``
            writes: ``runs.parquet`` (one row per run, sorted by run_index),
            ``traces.parquet`` (when the study keeps traces) and ``study.json``. The Parquet
            files are written from Python with pyarrow, with each column's unit and
            description in the field metadata as hdw writes them (with polars only, the
            same tables without that metadata). For the report (report.md and plots) run
            ``hdw report OUT`` afterwards; it reads exactly these files.
        threads: worker threads (default: all cores).
        parts: run only these parts of a multi-part study.

    Returns:
        The runs table (polars DataFrame, or dict of columns without polars), with the
        columns of ``runs.parquet`` (docs/columns.md). Failed runs are rows with status
        ``failed`` and their error.

    Raises:
        ValueError: the study file is malformed (the message names file, line and key).
    """
    raw = _hdw.run_study(
        os.fspath(path), read_profile, threads, None if parts is None else list(parts)
    )
    dir = out_dir(out)
    if dir is not None:
        # hdw study writes the plan first, then the tables.
        write_text(dir / "study.json", raw["manifest"])
        if raw["traces"] is not None:
            write_table(dir / "traces.parquet", raw["traces"])
        write_table(dir / "runs.parquet", raw["runs"])
    return table(raw["runs"])
