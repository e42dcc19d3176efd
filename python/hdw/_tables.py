"""Tables handed back to Python: a polars DataFrame when polars is installed, otherwise the
dict of columns itself (numpy arrays for numbers, lists for text)."""

from __future__ import annotations

from typing import Any, Dict

try:  # polars is optional: the extension never needs it
    import polars as _pl
except ImportError:  # pragma: no cover - exercised only without polars
    _pl = None

import numpy as np

Columns = Dict[str, Any]


def have_polars() -> bool:
    """Whether tables come back as polars DataFrames."""
    return _pl is not None


def table(columns: Columns) -> Any:
    """A polars DataFrame of ``columns`` (NaN numbers become null, as in the Parquet
    outputs), or the dict unchanged when polars is not installed."""
    if _pl is None:
        return columns
    series = []
    for name, col in columns.items():
        if isinstance(col, np.ndarray) and col.dtype.kind == "f":
            s = _pl.Series(name, col).fill_nan(None)
        elif isinstance(col, np.ndarray):
            s = _pl.Series(name, col)
        elif all(v is None or isinstance(v, str) for v in col):
            s = _pl.Series(name, col, dtype=_pl.String)
        else:
            s = _pl.Series(name, col)
        series.append(s)
    return _pl.DataFrame(series)
