"""The drive as a co-simulation FMU: :func:`export_fmu`."""

from __future__ import annotations

import os
import pathlib
import shutil
import subprocess
import tempfile
from typing import Any, List, Mapping, Optional


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(float(v))
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    raise ValueError(f"cannot write {v!r} to a params file: expected a number or a string")


def _params_toml(
    params: Optional[Mapping[str, float]],
    stiffness: Optional[str],
    controller: Optional[Mapping[str, Any]],
) -> str:
    """A params file (docs/model.md): registry names, the stiffness law, a [controller]
    table whose dict values become sub-tables (``reference``, ``model``)."""
    lines = []
    if stiffness is not None:
        lines.append(f"stiffness = {_toml_value(stiffness)}")
    for name, value in (params or {}).items():
        lines.append(f"{name} = {_toml_value(value)}")
    if controller is not None:
        tables = {k: v for k, v in controller.items() if isinstance(v, Mapping)}
        lines.append("[controller]")
        lines += [f"{k} = {_toml_value(v)}" for k, v in controller.items() if k not in tables]
        for name, table in tables.items():
            lines.append(f"[controller.{name}]")
            lines += [f"{k} = {_toml_value(v)}" for k, v in table.items()]
    return "\n".join(lines) + "\n"


def _hdw_binary(hdw: Optional[str], caller: str = "export_fmu") -> str:
    found = hdw or os.environ.get("HDW") or shutil.which("hdw")
    if not found:
        raise FileNotFoundError(
            f"{caller} runs the hdw command line, which was not found: build it with "
            "`cargo build -p hd-cli` and pass hdw=PATH, set $HDW, or put it on PATH"
        )
    return found


def _run_cli(args: List[str]) -> "subprocess.CompletedProcess[str]":
    """Run the hdw command line ``args``; a refusal raises ValueError with the command's
    last ``error:`` line (or its whole stderr)."""
    p = subprocess.run(args, capture_output=True, text=True)
    if p.returncode != 0:
        lines = [l for l in p.stderr.strip().splitlines() if l.startswith("error: ")]
        raise ValueError((lines[-1] if lines else p.stderr.strip()).removeprefix("error: "))
    return p


def export_fmu(
    out: "os.PathLike[str] | str",
    params: Optional[Mapping[str, float]] = None,
    variant: str = "full",
    stiffness: Optional[str] = None,
    fmi: int = 2,
    controller: Optional[Mapping[str, Any]] = None,
    rtol: float = 1e-6,
    atol: float = 1e-9,
    method: str = "auto",
    friction_velocity: str = "motor",
    t_end: float = 0.2,
    lib: "Optional[os.PathLike[str] | str]" = None,
    hdw: Optional[str] = None,
    fixed_substeps: Optional[int] = None,
) -> pathlib.Path:
    """Write a co-simulation FMU (FMI 2.0 or 3.0) of the drive, as ``hdw export fmu`` does.

    The FMU runs the drive exactly as :func:`simulate` and ``hdw simulate`` do, one
    communication step at a time: inputs ``u`` [V] (open loop) and ``T_load`` [N·m],
    outputs the trace columns (``theta_z``, ``Tb``, …), every parameter a tunable start
    value (docs/fmu.md).

    Args:
        out: the .fmu file to write.
        params: parameter start values by registry name, e.g. ``{"c": 6e4}``.
        variant: ``linear``, ``damped`` or ``full``.
        stiffness: the full variant's law (``memory``, ``maxwell-slip``, ``bouc-wen``,
            ``catalogue``); default memory.
        fmi: 2 or 3.
        controller: a ``[controller]`` table as a dict (e.g. ``{"kp": 2000, "reference":
            {"kind": "step", "amplitude": 1e-3}}``): a closed-loop FMU whose input is
            ``T_load`` only.
        rtol, atol, method, friction_velocity: the solver and friction settings of
            ``hdw simulate``.
        t_end: stop time of the FMU's default experiment [s].
        lib: the FMU binary (hd-fmu's libhd_fmu.so); default: beside the hdw binary.
        hdw: the hdw binary; default ``$HDW`` or ``hdw`` on PATH.
        fixed_substeps: integrate each communication step in this many fixed Runge–Kutta
            substeps instead of the adaptive solver (real-time and HIL hosts; open-loop
            ``full`` drives with L = 0, docs/fmu.md "Fixed step"); default adaptive.

    Returns:
        The path of the FMU.

    Raises:
        ValueError: hdw refused the settings (its message names the field).
    """
    if fmi not in (2, 3):
        raise ValueError(f"fmi = {fmi!r}: expected 2 or 3")
    out = pathlib.Path(out)
    with tempfile.TemporaryDirectory() as tmp:
        params_file = pathlib.Path(tmp) / "params.toml"
        params_file.write_text(_params_toml(params, stiffness, controller))
        args = [
            _hdw_binary(hdw), "export", "fmu",
            "--params", str(params_file),
            "--variant", variant,
            "--fmi", str(fmi),
            "--rtol", repr(rtol),
            "--atol", repr(atol),
            "--method", method,
            "--friction-velocity", friction_velocity,
            "--t-end", repr(t_end),
            "--out", str(out),
        ]
        if lib is not None:
            args += ["--lib", os.fspath(lib)]
        if fixed_substeps is not None:
            if isinstance(fixed_substeps, bool) or not isinstance(fixed_substeps, int) \
                    or fixed_substeps < 1:
                raise ValueError(
                    f"fixed_substeps = {fixed_substeps!r}: expected a whole number >= 1")
            args += ["--fixed-substeps", str(fixed_substeps)]
        p = subprocess.run(args, capture_output=True, text=True)
    if p.returncode != 0:
        raise ValueError(p.stderr.strip().removeprefix("error: "))
    return out
