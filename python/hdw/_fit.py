"""Identification from numpy arrays: :func:`fit_hysteresis` and :func:`fit_friction`."""

from __future__ import annotations

import json
from typing import Any, Dict, Mapping, Optional

import numpy as np

from . import _hdw

ArrayLike = Any


class FitResult:
    """The outcome of a fit.

    Attributes:
        report: the fit.json document of ``hdw fit`` as a dict: ``parameters`` (each with
            value, unit, std_error, ci95, determined, fixed, note), ``correlation``, ``rms``,
            ``r2``, ``iterations``, ``termination``, ``samples``, ``dof``, ``noise_std``,
            ``search``, ``stages``, ``remarks``, ``wall_time_s`` (and ``loop_energy`` for
            hysteresis). Only ``data`` (the files read) is absent: the data came as arrays.
        values: ``{name: fitted value}`` in registry units.
        fitted, residuals: the model's torque along the data and measured − fitted [N·m]
            (hysteresis; friction fits keep them per stage in ``stages``).
        stages: friction fits, ``{"steady": ..., "transient": ...}``, each a dict with
            ``fitted`` and ``residuals`` arrays (None for a stage without data).
    """

    def __init__(self, raw: Dict[str, Any]) -> None:
        self.report: Dict[str, Any] = json.loads(raw["report"])
        self.values: Dict[str, float] = {
            k: v["value"] for k, v in self.report["parameters"].items()
        }
        self.fitted: Optional[np.ndarray] = raw.get("fitted")
        self.residuals: Optional[np.ndarray] = raw.get("residuals")
        self.stages: Dict[str, Optional[Dict[str, np.ndarray]]] = {
            k: (None if raw[k] is None else {"fitted": raw[k]["fitted"],
                                              "residuals": raw[k]["residuals"]})
            for k in ("steady", "transient") if k in raw
        }

    def __repr__(self) -> str:
        vals = ", ".join(f"{k}={v:.6g}" for k, v in self.values.items())
        return f"FitResult({self.report['fit']}: {vals}; rms={self.report['rms']:.4g})"


def fit_hysteresis(
    t: ArrayLike,
    theta: ArrayLike,
    torque: ArrayLike,
    law: str = "memory",
    *,
    elements: Optional[int] = None,
    offset: bool = False,
    fix: Optional[Mapping[str, float]] = None,
) -> Any:
    """Fit a stiffness law to a torque–deflection record, as ``hdw fit hysteresis``.

    Args:
        t: sample times [s], increasing.
        theta: gear deflection [rad].
        torque: transmitted torque [N·m].
        law: ``"memory"`` (the seed's law: a, b, c, mem_A, mem_B), ``"maxwell-slip"``,
            ``"bouc-wen"``, or ``"all"`` to fit every law and rank them by BIC.
        elements: Maxwell-slip elements (default 8).
        offset: also fit a constant torque offset of the rig (``offset`` [N·m]).
        fix: parameters held at given values instead of fitted, e.g. ``{"a": 0, "b": 0}``
            (memory law only).

    Returns:
        :class:`FitResult` (one law), or with ``law="all"`` a dict ``{"comparison": the
        entries of comparison.json (best BIC first: law, rms, aic, bic, delta_bic,
        parameters), "fits": {law: FitResult}}``.

    Raises:
        ValueError: bad data (lengths, non-finite values, time not increasing) or settings.
    """
    raw = _hdw.fit_hysteresis(
        np.asarray(t, dtype=float), np.asarray(theta, dtype=float),
        np.asarray(torque, dtype=float), law, elements, offset,
        None if fix is None else dict(fix),
    )
    if "comparison" in raw:
        return {
            "comparison": json.loads(raw["comparison"]),
            "fits": {k: FitResult(v) for k, v in raw["fits"].items()},
        }
    return FitResult(raw)


def fit_friction(
    t: Optional[ArrayLike] = None,
    omega: Optional[ArrayLike] = None,
    torque: Optional[ArrayLike] = None,
    steady: Optional[Mapping[str, ArrayLike]] = None,
    fix: Optional[Mapping[str, float]] = None,
    *,
    asymmetric: bool = False,
    offset: bool = False,
) -> FitResult:
    """Fit the LuGre friction parameters, as ``hdw fit friction``.

    Args:
        t, omega, torque: a time series: times [s], speed [rad/s] and friction torque
            [N·m]. Alone, every LuGre parameter is fitted at once.
        steady: a steady-state sweep ``{"omega": [rad/s], "torque": [N·m]}`` (optionally
            ``"load"``: the transmitted torque [N·m], to fit the load factors mu_*).
            Alone: Tc, Ts, ws, sigma2; with a time series, the static stage first, then
            sigma0 and sigma1 from the series with the static parameters held.
        fix: parameters held at given values, e.g. ``{"sigma2": 0}``.
        asymmetric: separate levels for negative speeds (Tc_neg, Ts_neg) and a torque
            offset.
        offset: fit a constant torque offset of the measurement.

    Returns:
        :class:`FitResult`; ``.stages`` holds each stage's fitted torque and residuals.

    Raises:
        ValueError: no data, incomplete or bad data, or a bad ``fix``.
        SimulationError: the bristle-state integration failed.
    """
    def arr(x: Optional[ArrayLike]) -> Optional[np.ndarray]:
        return None if x is None else np.asarray(x, dtype=float)

    s = dict(steady) if steady is not None else {}
    unknown = set(s) - {"omega", "torque", "load"}
    if unknown:
        raise ValueError(
            f"steady: unknown key(s) {', '.join(sorted(unknown))}: expected omega, torque, load"
        )
    raw = _hdw.fit_friction(
        arr(t), arr(omega), arr(torque), arr(s.get("omega")), arr(s.get("torque")),
        arr(s.get("load")), None if fix is None else dict(fix), asymmetric, offset,
    )
    return FitResult(raw)
