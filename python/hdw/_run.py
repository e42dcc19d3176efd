"""One run (:func:`simulate`) and many runs in parallel (:func:`simulate_many`)."""

from __future__ import annotations

import json
from typing import Any, Dict, Mapping, Optional, Sequence, Union

import numpy as np

from . import _hdw
from ._io import read_profile
from ._tables import table

Params = Mapping[str, float]


def _input_dict(input: Union[None, str, Mapping[str, Any]]) -> Optional[Dict[str, Any]]:
    """The input as the extension takes it: a kind name becomes ``{"kind": name}``, and a
    recorded input given as ``file`` is read into ``t`` and ``u`` arrays."""
    if input is None:
        return None
    if isinstance(input, str):
        return {"kind": input}
    d = dict(input)
    if "file" in d:
        if d.get("kind", "recorded") != "recorded":
            raise ValueError(f"input.file is only for kind 'recorded', not '{d['kind']}'")
        d["kind"] = "recorded"
        d["t"], d["u"] = read_profile(d.pop("file"))
    return d


def _options(
    variant: str,
    input: Union[None, str, Mapping[str, Any]],
    t_end: float,
    rtol: float,
    atol: float,
    dt_out: float,
    controller: Optional[Mapping[str, Any]],
    method: str,
    friction_velocity: str,
    cycles: int,
    load_torque: Optional[float],
    max_steps: Optional[int],
    stiffness: str = "memory",
) -> Dict[str, Any]:
    return {
        "variant": variant,
        "stiffness": stiffness,
        "input": _input_dict(input),
        "t_end": t_end,
        "rtol": rtol,
        "atol": atol,
        "dt_out": dt_out,
        "method": method,
        "friction_velocity": friction_velocity,
        "cycles": cycles,
        "max_steps": max_steps,
        "controller": None if controller is None else json.dumps(dict(controller)),
        "load_torque": load_torque,
    }


class SimResult:
    """The outcome of :func:`simulate`.

    Attributes:
        trace: the sampled signals (columns of ``trace.parquet``: t [s], u [V], i [A],
            theta_j, omega_j, theta_z, omega_z, theta [rad, rad/s], z, Tb, Tf [N·m], s [rad],
            K [N·m/rad], C0 [N·m·s/rad], and the closed-loop columns), a polars DataFrame
            or a dict of numpy arrays; None with ``trace=False``.
        metrics: every metric of metrics.json, ``{name: value}`` in SI units; NaN where a
            metric is undefined for the run (null in metrics.json).
        solver: the ``solver`` object of metrics.json (method, tolerances, steps,
            rejected_steps, rhs_evaluations, …, wall_time_s).
        parameters: every parameter used, ``{name: value}``.
        config: the full run configuration (as hd-model serialises it).
    """

    def __init__(self, raw: Dict[str, Any]) -> None:
        self._trace_columns: Optional[Dict[str, np.ndarray]] = raw["trace"]
        self.trace: Any = None if raw["trace"] is None else table(raw["trace"])
        self.metrics: Dict[str, float] = raw["metrics"]
        self.solver: Dict[str, Any] = raw["solver"]
        self.parameters: Dict[str, float] = raw["parameters"]
        self.config: Dict[str, Any] = json.loads(raw["config"])

    def __repr__(self) -> str:
        cols = self._trace_columns
        n = len(next(iter(cols.values()))) if cols else 0
        return (
            f"SimResult({self.config['variant']}, {n} trace samples, "
            f"{self.solver['steps']} steps, thz_amp={self.metrics['thz_amp']!r})"
        )


def simulate(
    params: Optional[Params] = None,
    variant: str = "full",
    input: Union[None, str, Mapping[str, Any]] = None,
    t_end: float = 0.2,
    rtol: float = 1e-6,
    atol: float = 1e-9,
    dt_out: float = 0.0,
    controller: Optional[Mapping[str, Any]] = None,
    *,
    method: str = "auto",
    friction_velocity: str = "motor",
    cycles: int = 5,
    load_torque: Optional[float] = None,
    max_steps: Optional[int] = None,
    trace: bool = True,
    stiffness: str = "memory",
    states: Optional[Sequence[str]] = None,
) -> SimResult:
    """Simulate one run of the motor–harmonic-drive–load system from rest, as
    ``hdw simulate`` does (same defaults: the full model, 24 V sine at 50 Hz, 0.2 s).

    Args:
        params: parameters that differ from the defaults, ``{name: value}`` by registry
            name or alias (see :func:`parameters`), e.g. ``{"c": 6e4, "A": 3e4}``.
        variant: ``"linear"``, ``"damped"`` or ``"full"``.
        stiffness: the full variant's hysteretic law, ``"memory"`` (default),
            ``"maxwell-slip"``, ``"bouc-wen"`` or ``"catalogue"`` (docs/model.md §2.11–2.14).
        input: the armature voltage, as a study file's ``[input]`` table:
            ``{"kind": "sine", "voltage": 24, "freq": 50}``, ``{"kind": "step",
            "voltage": 12, "t0": 0}``, ``{"kind": "constant", "voltage": 5}``,
            ``{"kind": "chirp", "voltage": 24, "f0": 5, "f1": 500, "duration": 1}``,
            ``{"kind": "stepped_sine", "voltage": 24, "freqs": [...], "dwell": 0.2}``, or a
            recording ``{"kind": "recorded", "t": array [s], "u": array [V]}`` (or
            ``{"file": "profile.csv"}`` with columns t, u). A plain kind name works too.
            Default: 24 V sine at 50 Hz.
        t_end: simulated time [s].
        rtol, atol: solver tolerances (atol in the state's units: rad, rad/s, N·m, A).
        dt_out: trace sampling interval [s]; 0 = automatic (200 samples per drive cycle).
        controller: a closed-loop controller, as a params file's ``[controller]`` table,
            e.g. ``{"kp": 2000, "ki": 2e4, "kd": 0, "feedback": "load", "reference":
            {"kind": "sine", "amplitude": 1e-3, "freq": 0.2}}``; None for open loop.
        method: ``"auto"``, ``"dopri5"``, ``"dop853"``, ``"rodas4"``, ``"imex"`` or ``"imex5"``.
        friction_velocity: where the friction acts and the speed it sees: ``"motor"``,
            ``"deflection"`` or ``"load"`` (the load alone, v = ωz).
        cycles: whole drive cycles at the end of the run used for the periodic metrics.
        load_torque: a constant external load torque on the load side [N·m].
        max_steps: step budget of the integrator (default 50 million).
        trace: keep the sampled trace (False saves memory when only metrics are needed).
        states: record only these trace columns, all of them states or the time (``"t"``,
            ``"theta_j"``, ``"omega_j"``, ``"theta_z"``, ``"omega_z"``, ``"theta"``): they are
            read from the solution at each grid time and no other signal is evaluated, so
            the run costs about what the solve alone does. ``trace`` is then ignored.

    Returns:
        :class:`SimResult` with ``.trace``, ``.metrics``, ``.solver``, ``.parameters``.

    Raises:
        ValueError: a bad parameter (naming it and its valid range), input or setting.
        SimulationError: the integrator could not finish the run.
    """
    opts = _options(
        variant, input, t_end, rtol, atol, dt_out, controller, method, friction_velocity,
        cycles, load_torque, max_steps, stiffness,
    )
    raw = _hdw.simulate(
        opts,
        None if params is None else dict(params),
        trace,
        None if states is None else list(states),
    )
    return SimResult(raw)


def simulate_many(
    params: Any,
    names: Optional[Sequence[str]] = None,
    *,
    base: Optional[Params] = None,
    variant: str = "full",
    input: Union[None, str, Mapping[str, Any]] = None,
    t_end: float = 0.2,
    rtol: float = 1e-6,
    atol: float = 1e-9,
    controller: Optional[Mapping[str, Any]] = None,
    method: str = "auto",
    friction_velocity: str = "motor",
    cycles: int = 5,
    load_torque: Optional[float] = None,
    max_steps: Optional[int] = None,
    metrics: Optional[Sequence[str]] = None,
    threads: Optional[int] = None,
    stiffness: str = "memory",
) -> Any:
    """Simulate many parameter sets in parallel (rayon, all cores by default, the GIL
    released) and return one row per run, as a sweep's ``runs.parquet``.

    Args:
        params: the parameter sets, either a list of dicts ``[{name: value}, ...]``, or a
            2-D array of shape (runs, parameters) with ``names`` naming its columns, or a
            polars/pandas DataFrame whose columns are parameter names.
        names: column names of a 2-D array ``params``.
        base: parameters applied to every run before its own set.
        variant, input, t_end, rtol, atol, controller, method, friction_velocity, cycles,
            load_torque, max_steps: as for :func:`simulate`, shared by every run.
        metrics: metric columns to keep (default: every metric).
        threads: worker threads (default: all cores).

    Returns:
        The runs table (polars DataFrame, or dict of columns without polars): run_id,
        run_index (the position in ``params``), part (``"batch"``), variant, status
        (``ok``/``failed``), error (why a run failed, else null), every parameter, voltage,
        freq, the kept metrics (null when undefined or failed), method, steps,
        rejected_steps, rhs_evals, jac_evals, wall_time [s].

    A value outside its parameter's range, or a run the integrator cannot finish, gives a
    ``failed`` row with its error; the other runs are unaffected. An unknown parameter name
    is a ``ValueError`` before anything runs.
    """
    opts = _options(
        variant, input, t_end, rtol, atol, 0.0, controller, method, friction_velocity,
        cycles, load_torque, max_steps, stiffness,
    )
    base_d = None if base is None else dict(base)
    keep = None if metrics is None else list(metrics)
    if hasattr(params, "columns") and hasattr(params, "to_numpy") and names is None:
        names = [str(c) for c in params.columns]
        params = params.to_numpy()
    if isinstance(params, np.ndarray):
        if params.ndim != 2:
            raise ValueError(f"params: expected a 2-D array (runs × parameters), got {params.ndim}-D")
        if names is None:
            raise ValueError("params is an array: give names=[...] for its columns")
        values = np.ascontiguousarray(params, dtype=np.float64)
        raw = _hdw.simulate_array(opts, values, list(names), base_d, threads, keep)
    else:
        if names is not None:
            raise ValueError("names= is only for a 2-D array of parameter values")
        sets = [dict(p) for p in params]
        raw = _hdw.simulate_dicts(opts, sets, base_d, threads, keep)
    return table(raw)
