"""Sobol' indices of any Saltelli-ordered sample: :func:`sobol_indices`."""

from __future__ import annotations

from typing import Any, Optional, Sequence

import numpy as np

from . import _hdw
from ._tables import table


def sobol_indices(
    y: Any,
    names: Sequence[str],
    *,
    bootstrap: int = 1000,
    confidence: float = 0.95,
    seed: int = 0,
) -> Any:
    """First-order (S1) and total (ST) Sobol' indices with bootstrap intervals, computed
    by the estimators of ``hdw sensitivity`` (Saltelli 2010 for S1, Jansen for ST,
    percentile bootstrap over base rows; docs/sensitivity.md).

    Args:
        y: one output per run of a Saltelli design of ``len(names)`` parameters, grouped
            by base row as A, A_B^(1) … A_B^(d), B. That is the row order of hdw's sobol
            designs and of SALib's ``sobol.sample(problem, N, calc_second_order=False)``,
            so SALib's samples run through :func:`simulate_many` can be analysed here as
            well as by ``SALib.analyze.sobol``. NaN (a failed run) drops its base row.
        names: the parameters, in the design's column order.
        bootstrap: bootstrap resamples (0: no intervals).
        confidence: confidence level of the intervals.
        seed: seed of the bootstrap resampling.

    Returns:
        A table with one row per parameter: parameter, S1, S1_lo, S1_hi, ST, ST_lo, ST_hi,
        n_used, n_dropped (base rows), note.
    """
    y = np.asarray(y, dtype=float).ravel()
    raw = _hdw.sobol_indices(y, len(names), bootstrap, confidence, seed)
    d = len(names)
    cols = {"parameter": [str(n) for n in names]}
    for k in ("S1", "S1_lo", "S1_hi", "ST", "ST_lo", "ST_hi"):
        cols[k] = raw[k]
    cols["n_used"] = np.full(d, raw["n_used"], dtype=np.uint64)
    cols["n_dropped"] = np.full(d, raw["n_dropped"], dtype=np.uint64)
    note: Optional[str] = raw["note"]
    cols["note"] = [note] * d
    return table(cols)
