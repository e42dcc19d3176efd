"""The cases of benches/memory.py: each runs hdw under a cap and returns rows of
(check, measured, PASS/FAIL/–) plus its raw numbers."""

from __future__ import annotations

import glob
import os
import re

import capped

MB = 1_000_000
PLOT_EXT = (".svg", ".png")


def files_by_size(folder: str, exts=PLOT_EXT) -> list[tuple[int, str]]:
    """(size [bytes], path relative to folder) of the plots under `folder`, largest first."""
    found = []
    for path in glob.glob(os.path.join(folder, "**", "*"), recursive=True):
        if path.endswith(exts) and os.path.isfile(path):
            found.append((os.path.getsize(path), os.path.relpath(path, folder)))
    return sorted(found, reverse=True)


def parquet_rows(path: str) -> int | None:
    try:
        import pyarrow.parquet as pq
    except ImportError:
        return None
    return pq.ParquetFile(path).metadata.num_rows


def simulate(hdw, tmp, t_end: float, timeout, cap) -> dict:
    """`hdw simulate --t-end T` with default outputs: peak RSS, response.svg, trace rows."""
    out = os.path.join(tmp, f"sim-{t_end:g}")
    o = capped.run([hdw, "simulate", "--t-end", repr(t_end), "--out", out], timeout, cap)
    r = dict(outcome=o, t_end=t_end, expected_rows=int(round(t_end / 1e-4)) + 1)
    if o.status == "ok":
        svg = os.path.join(out, "response.svg")
        r["svg"] = os.path.getsize(svg) if os.path.exists(svg) else None
        trace = os.path.join(out, "trace.parquet")
        r["rows"] = parquet_rows(trace) if os.path.exists(trace) else 0
        r["trace_bytes"] = os.path.getsize(trace) if os.path.exists(trace) else 0
    return r


def hysteresis_fit(hdw, tmp, samples: int, timeout, cap) -> dict:
    """Synthesize a hysteresis record of `samples` samples, fit it, and size its plots."""
    data = os.path.join(tmp, "hyst.parquet")
    o1 = capped.run([hdw, "synth", "hysteresis", "--samples", str(samples), "--out", data],
                    timeout, cap)
    if o1.status != "ok":
        return dict(outcome=o1, stage="synth")
    out = os.path.join(tmp, "fit")
    o2 = capped.run([hdw, "fit", "hysteresis", data, "--out", out], timeout, cap)
    return dict(outcome=o2, stage="fit", plots=files_by_size(out) if os.path.isdir(out) else [])


def grid_study_file(path: str, n1: int, n2: int, t_end: float = 0.003) -> str:
    """A linear-variant study of n1 × n2 tiny runs (24 V step, t_end [s]) on a K̄ × Jz grid."""
    with open(path, "w") as f:
        f.write(f"""name = "memory-grid"
description = "benches/memory.py: {n1} x {n2} tiny linear runs"

[base]
t_end = {t_end!r}

[input]
kind = "step"
voltage = 24.0

[metrics]
keep = ["thz_peak", "final_speed"]

[[part]]
name = "grid"
variant = "linear"

[[part.axis]]
name = "Kbar"
logspace = {{ start = 1.0e5, stop = 1.0e7, num = {n1} }}

[[part.axis]]
name = "Jz"
logspace = {{ start = 1.0e-3, stop = 1.0e-1, num = {n2} }}
""")
    return path


def study(hdw, tmp, n1, n2, timeout, cap, extra=(), watch=None) -> dict:
    """`hdw study` of an n1 × n2 grid with --no-report (and `extra` flags)."""
    runs = n1 * n2
    spec = grid_study_file(os.path.join(tmp, f"grid-{n1}x{n2}.toml"), n1, n2)
    out = os.path.join(tmp, f"study-{n1}x{n2}")
    o = capped.run([hdw, "study", spec, "--no-report", "--out", out, *extra], timeout, cap,
                   watch=(watch or (lambda out: {}))(out))
    r = dict(outcome=o, runs=runs, out=out, spec=spec)
    if o.status == "ok":
        r["runs_per_s"] = runs / o.wall
        sizes = {os.path.relpath(p, out): os.path.getsize(p)
                 for p in glob.glob(os.path.join(out, "**", "*"), recursive=True)
                 if os.path.isfile(p)}
        r["sizes"] = sizes
    return r


def report(hdw, study_dir, timeout, cap) -> dict:
    """`hdw report DIR` of a finished study: time, peak RSS, largest plot."""
    o = capped.run([hdw, "report", study_dir], timeout, cap)
    return dict(outcome=o, plots=files_by_size(study_dir))


def one_sentence(stderr: str) -> bool:
    """One non-empty line, no panic message, no backtrace, no allocation abort."""
    lines = [ln for ln in stderr.strip().splitlines() if ln.strip()]
    bad = ("panicked", "backtrace", "memory allocation of", "RUST_BACKTRACE", "   at ")
    return len(lines) == 1 and not any(b in stderr for b in bad)


def names_count(stderr: str, count: int) -> bool:
    """Whether the message states the run count (any digit grouping, or as 10^k / 1e k)."""
    digits = re.sub(r"(?<=\d)[ ,_\u202f\u2009'](?=\d)", "", stderr)
    k = len(str(count)) - 1
    forms = (str(count), f"1e{k}", f"1e+{k}", f"10^{k}", "10" + str(k).translate(
        str.maketrans("0123456789", "⁰¹²³⁴⁵⁶⁷⁸⁹")))
    return any(f in digits for f in forms)
