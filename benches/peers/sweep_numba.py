#!/usr/bin/env python3
"""One part of a study file, solved in Python with NumbaLSODA on a multiprocessing pool.

This is the Python peer of `hdw study FILE --part NAME`: the same grid of full-model runs
(every combination of the part's axes, each a parameter of seed_numba.FIELDS or
`friction_scale`), each solved from rest with LSODA on a uniform grid of --dt-out, and the
θz amplitude of the last 5 drive cycles taken from it. Timed as a whole process by
benches/peers.py, so interpreter start, imports and the numba JIT are all included.

    python benches/peers/sweep_numba.py studies/table4.toml --part full-sine --procs 2 \
        --out /tmp/amps.npz

Writes an .npz with the axis values of every run (one array per axis) and `thz_amp` [rad].
"""

from __future__ import annotations

import argparse
import itertools
import multiprocessing as mp
import os
import sys
import tomllib

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import seed_numba as sn  # noqa: E402  (compiles the right-hand side)


def axis_values(ax: dict) -> np.ndarray:
    """The values of one study axis: logspace, linspace or an explicit list."""
    if "logspace" in ax:
        s = ax["logspace"]
        return np.logspace(np.log10(s["start"]), np.log10(s["stop"]), int(s["num"]))
    if "linspace" in ax:
        s = ax["linspace"]
        return np.linspace(s["start"], s["stop"], int(s["num"]))
    if "values" in ax:
        return np.asarray(ax["values"], dtype=float)
    raise SystemExit(f"axis {ax.get('name')!r}: only logspace, linspace and values are read here")


def read_part(path: str, name: str) -> dict:
    """t_end, input and grid of one part of a study file; refuses what it cannot mirror."""
    with open(path, "rb") as f:
        study = tomllib.load(f)
    parts = [p for p in study.get("part", []) if p.get("name") == name]
    if not parts:
        raise SystemExit(f"{path}: no part named {name!r}")
    part = parts[0]
    if part.get("variant", study.get("base", {}).get("variant", "full")) != "full":
        raise SystemExit(f"{path}, part {name!r}: only the full variant is mirrored in Python")
    inp = dict(study.get("input", {}))
    inp.update(part.get("input", {}))
    if inp.get("kind", "sine") != "sine":
        raise SystemExit(f"{path}, part {name!r}: only a sine input is mirrored in Python")
    t_end = float(part.get("t_end", study.get("base", {}).get("t_end", 0.2)))
    axes = {}
    for ax in part.get("axis", []):
        if ax["name"] not in sn.FIELDS and ax["name"] != "friction_scale":
            raise SystemExit(f"{path}, part {name!r}: axis {ax['name']!r} is not mirrored")
        axes[ax["name"]] = axis_values(ax)
    return dict(t_end=t_end, voltage=float(inp.get("voltage", 24.0)),
                freq=float(inp.get("freq", 50.0)), axes=axes)


def rows_of(part: dict) -> tuple[np.ndarray, dict]:
    """Packed parameter rows of every run (the grid's product) and the axis value per run."""
    names = list(part["axes"])
    combos = list(itertools.product(*(part["axes"][n] for n in names)))
    rows = np.empty((len(combos), sn.NDATA))
    for k, vals in enumerate(combos):
        over = dict(zip(names, vals))
        fs = over.pop("friction_scale", 1.0)
        rows[k] = sn.pack(None, friction_scale=fs, u_amp=part["voltage"], freq=part["freq"],
                          **over)
    cols = {n: np.array([c[i] for c in combos]) for i, n in enumerate(names)}
    return rows, cols


_JOB = {}


def _work(chunk: np.ndarray) -> np.ndarray:
    t, rtol, atol, freq = _JOB["t"], _JOB["rtol"], _JOB["atol"], _JOB["freq"]
    thz, ok = sn.solve_many(chunk, t, rtol, atol)
    amps = np.array([sn.thz_amp(t, thz[k], freq) for k in range(len(chunk))])
    amps[~ok] = np.nan
    return amps


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("study")
    ap.add_argument("--part", required=True)
    ap.add_argument("--procs", type=int, default=os.cpu_count())
    ap.add_argument("--rtol", type=float, default=1e-6, help="hdw study's default: 1e-6")
    ap.add_argument("--atol", type=float, default=1e-9, help="hdw study's default: 1e-9")
    ap.add_argument("--dt-out", type=float, default=1e-4, help="sample spacing [s]")
    ap.add_argument("--out", help="write the axis values and thz_amp of every run (.npz)")
    a = ap.parse_args()
    part = read_part(a.study, a.part)
    rows, cols = rows_of(part)
    n = int(round(part["t_end"] / a.dt_out)) + 1
    _JOB.update(t=sn.grid(part["t_end"], n), rtol=a.rtol, atol=a.atol, freq=part["freq"])
    sn.solve_many(rows[:1], _JOB["t"][:3], a.rtol, a.atol)  # JIT once, before the fork
    chunks = np.array_split(rows, max(1, a.procs) * 16)
    with mp.get_context("fork").Pool(a.procs) as pool:
        amps = np.concatenate(pool.map(_work, chunks))
    failed = int(np.isnan(amps).sum())
    print(f"{len(amps)} runs, {failed} failed, procs {a.procs}, rtol {a.rtol:g}, atol {a.atol:g}")
    if a.out:
        np.savez(a.out, thz_amp=amps, **cols)


if __name__ == "__main__":
    main()
