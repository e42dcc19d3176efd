"""Whole-drive identification from a logged closed loop: :func:`fit_drive`."""

from __future__ import annotations

import json
import os
import pathlib
import subprocess
import tempfile
from typing import Any, Dict, List, Optional

from ._fmu import _hdw_binary

PathLike = "os.PathLike[str] | str"


class DriveFitResult:
    """The outcome of :func:`fit_drive`.

    Attributes:
        report: the fit.json document of ``hdw fit drive`` as a dict: ``controller`` (the
            check of the recorded command per delay), ``noise``, ``best`` (the law with the
            lowest BIC), its ``parameters``, ``experiments`` and ``validation`` scores,
            ``start`` (the inverse-model start per law) and ``laws`` (every fitted law,
            best first, each with parameters, correlation, BIC, scores, the sentences on
            what the record determines, iterations and seconds). A compliant-drive fit
            (``transmission = "compliant"``) has ``best`` = ``"compliant"``, its
            ``parameters`` (each with ``determined`` and ``held``), ``determination`` and
            ``experiments``, and no ``laws``.
        best: the name of the best law.
        values: ``{name: fitted value}`` of the best law, in the axis's units.
        laws: ``{law: {name: fitted value}}`` for every fitted law.
        out: the output folder (fit.json, params.toml, report.md, plots), or None when
            the fit ran in a temporary folder.
        summary: the report as ``hdw fit drive`` prints it (Markdown).
    """

    def __init__(self, report: Dict[str, Any], out: Optional[pathlib.Path], summary: str):
        self.report = report
        self.best: str = report["best"]
        self.values: Dict[str, float] = {
            k: v["value"] for k, v in report["parameters"].items()
        }
        # A compliant-drive fit (``transmission = "compliant"``) has one model, no laws.
        self.laws: Dict[str, Dict[str, float]] = {
            law["law"]: {k: v["value"] for k, v in law["parameters"].items()}
            for law in report.get("laws", [])
        } or {self.best: dict(self.values)}
        self.out = out
        self.summary = summary

    def scores(self, law: Optional[str] = None) -> Dict[str, Any]:
        """Per experiment and output: ``rel_error`` [%], ``rmse`` and ``fit_percent`` of
        `law` (default the best), plus ``validation`` when a validation record was given."""
        if "laws" not in self.report:  # a compliant-drive fit: one model
            entry = self.report
        else:
            entry = next(e for e in self.report["laws"] if e["law"] == (law or self.best))
        out = dict(entry["experiments"])
        if entry.get("validation") is not None:
            out["validation"] = entry["validation"]
        return out

    def __repr__(self) -> str:
        vals = ", ".join(f"{k}={v:.6g}" for k, v in self.values.items())
        return f"DriveFitResult({self.best}: {vals})"


def fit_drive(
    config: PathLike,
    out: Optional[PathLike] = None,
    validate: Optional[PathLike] = None,
    *,
    hdw: Optional[str] = None,
) -> DriveFitResult:
    """Identify a drive from its logged closed loop, as ``hdw fit drive`` does
    (docs/fit-drive.md): the controller check, the inverse-model start, the output-error
    fit of each friction law of the configuration, ranked by BIC.

    It runs the hdw command line, whose readers take the configuration's CSV, Parquet and
    MAT records and whose report and plots it writes, so the result is the command's own.

    Args:
        config: the fit configuration (TOML); its paths are relative to it.
        out: folder for fit.json, params.toml, report.md and the plots; default a
            temporary folder, removed after the report is read.
        validate: a validation record read with the first experiment's column mapping.
        hdw: the hdw binary; default ``$HDW`` or ``hdw`` on PATH.

    Returns:
        :class:`DriveFitResult`.

    Raises:
        ValueError: hdw refused the configuration or a record (its one-line message names
            the file and the field).
        FileNotFoundError: the hdw binary was not found.
    """
    binary = _hdw_binary(hdw, "fit_drive")

    def run(folder: pathlib.Path) -> DriveFitResult:
        args = [binary, "fit", "drive", "--config", os.fspath(config), "--out", str(folder)]
        if validate is not None:
            args += ["--validate", os.fspath(validate)]
        p = subprocess.run(args, capture_output=True, text=True)
        if p.returncode != 0:
            raise ValueError(p.stderr.strip().removeprefix("error: "))
        report = json.loads((folder / "fit.json").read_text())
        return DriveFitResult(report, None if out is None else folder, p.stdout)

    if out is not None:
        return run(pathlib.Path(out))
    with tempfile.TemporaryDirectory() as tmp:
        return run(pathlib.Path(tmp) / "fit-drive")


__all__: List[str] = ["DriveFitResult", "fit_drive"]
