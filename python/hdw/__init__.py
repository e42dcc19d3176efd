"""hdw: the harmonic-drive workbench from Python.

Simulate a DC motor driving an inertial load through a harmonic drive (hysteretic
stiffness, LuGre friction), run many parameter sets in parallel, run study files, and fit
model parameters to recorded data. Numbers come back as numpy arrays, tables as polars
DataFrames when polars is installed (dicts of numpy arrays otherwise).

    >>> import hdw
    >>> r = hdw.simulate()                 # the seed case: full model, 24 V, 50 Hz, 0.2 s
    >>> r.metrics["thz_amp"]               # load-angle amplitude [rad]
    >>> runs = hdw.simulate_many([{"c": 4e4}, {"c": 6e4}])

Functions: :func:`parameters`, :func:`metrics`, :func:`simulate`, :func:`simulate_many`,
:func:`run_study`, :func:`fit_hysteresis`, :func:`fit_friction`, :func:`sobol_indices`,
:func:`export_fmu` (an FMU of the drive), :func:`fit_drive` (a whole drive from its
logged loop), :func:`fleet` (a fleet's logs tested for drift) and :func:`design` (the next
test of a compliant drive), the last four through the hdw command line.
Errors: ``ValueError`` for bad input (naming the field and what was expected),
:class:`SimulationError` when the integrator cannot finish a run.
"""

from __future__ import annotations

from typing import Any, List

from . import _hdw
from ._design import DesignResult, design
from ._fit import FitResult, fit_friction, fit_hysteresis
from ._fit_drive import DriveFitResult, fit_drive
from ._fleet import FleetResult, fleet
from ._fmu import export_fmu
from ._run import SimResult, simulate, simulate_many
from ._sensitivity import sobol_indices
from ._study import run_study
from ._tables import table as _table

SimulationError = _hdw.SimulationError
__version__: str = _hdw.__version__

__all__ = [
    "DesignResult",
    "DriveFitResult",
    "FitResult",
    "FleetResult",
    "SimResult",
    "SimulationError",
    "design",
    "export_fmu",
    "fit_drive",
    "fit_friction",
    "fit_hysteresis",
    "fleet",
    "metrics",
    "parameters",
    "run_study",
    "simulate",
    "simulate_many",
    "sobol_indices",
]


def parameters() -> Any:
    """The parameter registry: one row per parameter with name, unit (SI), default (the
    seed's tables), min, max, min_inclusive, range (as error messages state it), aliases
    (other accepted names, e.g. ``A`` for ``mem_A``) and description. A polars DataFrame,
    or a dict of columns without polars."""
    return _table(_hdw.parameters())


def metrics() -> List[str]:
    """Every metric name a run reports, in output order (docs/columns.md gives units)."""
    return list(_hdw.metric_names())
