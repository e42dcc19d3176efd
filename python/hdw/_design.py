"""The next test of a compliant drive, designed from its fit: :func:`design`."""

from __future__ import annotations

import json
import os
import pathlib
from typing import Any, Dict, List, Optional, Sequence

from ._fmu import _hdw_binary, _run_cli


class DesignResult:
    """The outcome of :func:`design`: the outputs of ``hdw design``.

    Attributes:
        input: input.parquet, the designed input ready for the rig, as a polars DataFrame
            (``t`` [s], ``u`` [V]; in closed loop ``t``, ``reference`` [rad]).
        report: design.json as a dict: ``criterion``, ``limits``, ``noise``, ``free``,
            ``design`` (the peaks against the limits and which one binds), ``parameters``
            (per parameter its value and the absolute standard errors and predicted
            verdicts of the fitted records alone, the design alone and with them, and each
            default input), ``defaults``, ``weakest_direction``, ``weak_directions``,
            ``verdicts``, ``searched`` and, after a refit check, ``check``.
        parameters: ``report["parameters"]`` as a polars DataFrame, a row per parameter
            (``parameter`` then the fields above).
        out: the output folder (input.csv, input.parquet, design.json, report.md, plots).
        log: what hdw printed (stderr): the designed input and the verdicts in words.
    """

    def __init__(self, out: pathlib.Path, log: str):
        import polars as pl

        self.out = out
        self.log = log
        self.input = pl.read_parquet(out / "input.parquet")
        self.report: Dict[str, Any] = json.loads((out / "design.json").read_text())
        self.parameters = pl.DataFrame(
            [{"parameter": k, **v} for k, v in self.report["parameters"].items()],
            infer_schema_length=None,
        )

    def __repr__(self) -> str:
        return f"DesignResult({self.report['input']}, {self.report['criterion']}, out={self.out})"


def _number(x: float) -> str:
    return repr(float(x))


def design(
    fit: "Optional[os.PathLike[str] | str]" = None,
    *,
    params: "Optional[os.PathLike[str] | str]" = None,
    free: Sequence[str] = (),
    out: "os.PathLike[str] | str" = "out/design",
    criterion: Optional[str] = None,
    a_params: Sequence[str] = (),
    family: Sequence[str] = ("default",),
    evaluations: int = 40,
    voltage: Optional[float] = None,
    current: Optional[float] = None,
    speed: Optional[float] = None,
    deflection: Optional[float] = None,
    controller: "Optional[os.PathLike[str] | str]" = None,
    reference: Optional[float] = None,
    load_speed: Optional[float] = None,
    torque: Optional[float] = None,
    load_angle: Optional[float] = None,
    duration: float = 2.0,
    rate: Optional[float] = None,
    motor_counts: Optional[int] = None,
    load_counts: Optional[int] = None,
    current_noise: Optional[float] = None,
    input: "Optional[os.PathLike[str] | str]" = None,
    at: "Optional[os.PathLike[str] | str]" = None,
    check: int = 0,
    truth: "Optional[os.PathLike[str] | str]" = None,
    seed: int = 1,
    options: Sequence[str] = (),
    hdw: Optional[str] = None,
) -> DesignResult:
    """Design the next voltage test of a compliant drive (``hdw design``, docs/design.md).

    From a compliant fit's output folder (``fit``: its records are the prior, its free
    parameters the unknowns) or a params file (``params`` with ``free``), and the rig's
    limits, it searches the input families for the record that maximises the information
    on what is undetermined, scales each candidate to the largest amplitude whose simulated
    voltage, current, motor speed, gear deflection, transmitted torque and load travel stay
    within the limits, and predicts
    every parameter's standard error beside the default chirp's and multisine's. With
    ``check=N`` it synthesises N records of the design with fresh noise and refits them.

    Args:
        fit: a compliant fit's output folder (``hdw fit drive``); or give ``params``.
        params: a params file (``hdw simulate``'s) of the drive, with ``free``.
        free: the unknown parameters: required with ``params``; with ``fit`` a subset of
            the fit's free ones.
        out: the output folder.
        criterion: ``"targeted"`` (the prior's weakest directions; default with ``fit``),
            ``"d"`` (default with ``params``) or ``"a"`` (with ``a_params``).
        a_params: the parameters of the A-optimal criterion.
        family: input families searched: ``chirp``, ``multisine``, ``ramp``, ``mix``, ``spectrum``;
            ``default`` (the first four) or ``all``.
        evaluations: candidates evaluated per family.
        voltage: peak voltage [V] (default: the fitted records' peak, else 12).
        current: peak current [A].
        speed: peak motor speed [rad/s].
        controller: closed loop: a TOML file with the ``[controller]`` the drive runs in
            (with ``params``); the design is then of the position reference.
        reference: closed loop: peak position reference [rad, on the fed-back encoder].
        load_speed: peak load speed [rad/s].
        deflection: peak gear deflection [rad].
        torque: peak torque the gear transmits [N·m].
        load_angle: the load's range of travel, its largest excursion from the starting
            angle either way [rad].
        duration: record length [s].
        rate: sample rate [Hz] (default: the fitted records', else 1000).
        motor_counts: motor encoder counts per revolution (default: the fit's noise level).
        load_counts: load encoder counts per revolution (default: the fit's noise level).
        current_noise: the current's noise, standard deviation [A].
        input: judge this input (CSV or Parquet, ``t`` and ``u``, or ``reference`` in closed
            loop) instead of searching.
        at: with ``fit``, predict at this params file's values instead of the fitted ones.
        check: refit check: synthesise and fit this many records.
        truth: the params file the check synthesises from (default: the designed-for drive).
        seed: seed of the check's noise and starts.
        options: further ``hdw design`` options.
        hdw: the hdw binary; default ``$HDW`` or ``hdw`` on PATH.

    Returns:
        :class:`DesignResult` with the input as a polars DataFrame and design.json as a dict.

    Raises:
        ValueError: hdw refused a file or a setting (its one-line message names it).
        FileNotFoundError: the hdw binary was not found.
    """
    binary = _hdw_binary(hdw, "design")
    args: List[str] = [binary, "design"]
    if fit is not None:
        args += ["--fit", os.fspath(fit)]
    if params is not None:
        args += ["--params", os.fspath(params)]
    if free:
        args += ["--free", ",".join(free)]
    if criterion is not None:
        args += ["--criterion", criterion]
    if a_params:
        args += ["--a-params", ",".join(a_params)]
    args += ["--family", ",".join(family), "--evaluations", str(int(evaluations))]
    for flag, x in [
        ("--voltage", voltage),
        ("--current", current),
        ("--speed", speed),
        ("--deflection", deflection),
        ("--reference", reference),
        ("--load-speed", load_speed),
        ("--torque", torque),
        ("--load-angle", load_angle),
        ("--rate", rate),
        ("--current-noise", current_noise),
    ]:
        if x is not None:
            args += [flag, _number(x)]
    args += ["--duration", _number(duration)]
    for flag, n in [("--motor-counts", motor_counts), ("--load-counts", load_counts)]:
        if n is not None:
            args += [flag, str(int(n))]
    for flag, path in [("--input", input), ("--at", at), ("--truth", truth),
                       ("--controller", controller)]:
        if path is not None:
            args += [flag, os.fspath(path)]
    args += ["--check", str(int(check)), "--seed", str(int(seed)), "--out", os.fspath(out)]
    args += list(options)
    p = _run_cli(args)
    return DesignResult(pathlib.Path(out), p.stderr)


__all__: List[str] = ["DesignResult", "design"]
