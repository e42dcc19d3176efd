"""A fleet of logs fitted and tested for drift: :func:`fleet`."""

from __future__ import annotations

import json
import os
import pathlib
from typing import Any, Dict, List, Optional, Sequence

from ._fmu import _hdw_binary, _run_cli


class FleetResult:
    """The outcome of :func:`fleet`: the tables of ``hdw fleet`` as polars DataFrames.

    Attributes:
        fits: fits.parquet, a row per log × parameter (manifest columns, ``unit_id``,
            ``day``, ``status``, ``error``, ``parameter``, ``value``, ``std_error``,
            ``ci95_lo``, ``ci95_hi``, ``determined``, ``param_unit``, ``resid_over_noise``,
            ``fit_time_s``); failed logs are rows with ``status == "failed"`` and the reason.
        drift: drift.parquet, a row per log × tested parameter (``normalised``,
            ``change_pct``, ``z``, ``cusum_upper``, ``cusum_lower``, ``flagged``, ``note``).
        alarms: alarms.csv: ``unit_id``, ``parameter``, ``first_flagged``, ``onset``,
            ``direction``, ``change_pct`` with ``ci95_lo``/``ci95_hi``.
        report: drift.json as a dict (settings, each parameter's normalisation: the
            candidate models with their BIC, the chosen one, its coefficients).
        out: the output folder.
        log: what hdw printed (stderr): counts, timing, alarms.
    """

    def __init__(self, out: pathlib.Path, log: str):
        import polars as pl

        self.out = out
        self.log = log
        self.fits = pl.read_parquet(out / "fits.parquet")
        self.drift = pl.read_parquet(out / "drift.parquet") if (out / "drift.parquet").exists() else None
        alarms = out / "alarms.csv"
        self.alarms = pl.read_csv(alarms, infer_schema_length=None) if alarms.exists() else None
        report = out / "drift.json"
        self.report: Optional[Dict[str, Any]] = json.loads(report.read_text()) if report.exists() else None

    def __repr__(self) -> str:
        n = 0 if self.alarms is None else self.alarms.height
        return f"FleetResult({self.fits['log_index'].n_unique()} logs, {n} alarms, out={self.out})"


def fleet(
    manifest: "Optional[os.PathLike[str] | str]" = None,
    *,
    pattern: Optional[str] = None,
    out: "os.PathLike[str] | str" = "out/fleet",
    unit: Sequence[str] = ("robot", "joint"),
    time: str = "date",
    covariates: Sequence[str] = (),
    fit: str = "plateaus",
    baseline_days: float = 20.0,
    false_alarm: float = 0.05,
    normalise: str = "auto",
    resume: bool = False,
    threads: Optional[int] = None,
    options: Sequence[str] = (),
    hdw: Optional[str] = None,
) -> FleetResult:
    """Fit every log of a fleet and test each unit's parameters for drift (``hdw fleet``).

    The logs come from a manifest (CSV or Parquet: the file, the unit's identifiers, a
    timestamp, covariates) or a path pattern (``"logs/{robot}/{joint}/{date}.csv"``); every
    log gets the same fit (``fit``: ``plateaus``, ``transient``, ``steady``, ``drive`` with
    ``options=["--drive-config", "fit.toml"]``, or ``hysteresis``
    with ``options=["--law", "memory"]`` for a stiffness law per torque–deflection log), in parallel,
    committed in parts (``resume=True`` continues an interrupted run). Then each parameter
    is normalised for the covariates over a baseline and Page's CUSUM flags the units whose
    normalised estimates drift, at a fleet-wide false-alarm probability ``false_alarm``.
    See docs/fleet.md.

    Args:
        manifest: the manifest file; or give ``pattern``.
        pattern: a path pattern whose ``{fields}`` become columns.
        out: the output folder (fits.parquet, drift.parquet, alarms.csv, drift.json, plots/).
        unit: columns identifying a unit.
        time: the timestamp column.
        covariates: numeric columns to normalise for (e.g. ``["temperature"]``).
        fit: the per-log fit: plateaus, transient, steady, hysteresis or drive.
        baseline_days: each unit's first days, over which the covariate model is fitted.
        false_alarm: probability of any false alarm over the fleet and record.
        normalise: ``"auto"`` (the covariate model of least BIC) or ``"none"``.
        resume: continue an interrupted run in ``out``.
        threads: worker threads (default: all cores).
        options: further ``hdw fleet`` options, e.g. ``["--columns", "t,w,tq"]``.
        hdw: the hdw binary; default ``$HDW`` or ``hdw`` on PATH.

    Returns:
        :class:`FleetResult` with ``fits``, ``drift`` and ``alarms`` as polars DataFrames.

    Raises:
        ValueError: hdw refused the manifest or a setting (its one-line message names the
            manifest, column or option).
        FileNotFoundError: the hdw binary was not found.
    """
    binary = _hdw_binary(hdw, "fleet")
    args: List[str] = [binary, "fleet"]
    if manifest is not None:
        args += ["--manifest", os.fspath(manifest)]
    if pattern is not None:
        args += ["--pattern", pattern]
    args += ["--unit", ",".join(unit), "--time", time, "--fit", fit]
    if covariates:
        args += ["--covariates", ",".join(covariates)]
    args += ["--baseline-days", repr(float(baseline_days)), "--false-alarm", repr(float(false_alarm))]
    args += ["--normalise", normalise, "--out", os.fspath(out)]
    if resume:
        args.append("--resume")
    if threads is not None:
        args += ["--threads", str(threads)]
    args += list(options)
    p = _run_cli(args)
    return FleetResult(pathlib.Path(out), p.stderr)


__all__: List[str] = ["FleetResult", "fleet"]
