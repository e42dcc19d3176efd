"""Shared helpers of the hdw Python-package tests: the `hdw` binary ($HDW, default
target/debug/hdw) and comparisons of its JSON outputs with the package's."""

import json
import math
import os
import pathlib
import subprocess

ROOT = pathlib.Path(__file__).resolve().parents[2]
HDW = os.environ.get("HDW", str(ROOT / "target" / "debug" / "hdw"))


def hdw(*args, cwd=ROOT):
    """Run the hdw binary; fail the test with its stderr if it fails."""
    p = subprocess.run([HDW, *map(str, args)], cwd=cwd, capture_output=True, text=True)
    assert p.returncode == 0, f"hdw {' '.join(map(str, args))} failed:\n{p.stderr}"
    return p


def read_json(path):
    return json.loads(pathlib.Path(path).read_text())


def same_number(a, b):
    """Equal to the last digit; JSON null and NaN both mean undefined."""
    if a is None or (isinstance(a, float) and math.isnan(a)):
        return b is None or (isinstance(b, float) and math.isnan(b))
    return a == b


def without(doc, keys):
    """`doc` with `keys` removed at every depth (e.g. wall times, which differ run to run)."""
    if isinstance(doc, dict):
        return {k: without(v, keys) for k, v in doc.items() if k not in keys}
    if isinstance(doc, list):
        return [without(v, keys) for v in doc]
    return doc


def sobol_study(name, t_end, n, seed, params):
    """A small Sobol' study file of the full model (24 V, 50 Hz) keeping thz_amp and
    efficiency; ``params`` is a list of (name, lo, hi)."""
    head = f"""name = "{name}"
[base]
variant = "full"
t_end = {t_end}
[input]
kind = "sine"
voltage = 24.0
freq = 50.0
[metrics]
keep = ["thz_amp", "efficiency"]
cycles = 1
[sample]
method = "sobol"
n = {n}
seed = {seed}
"""
    dims = "".join(f'[[sample.param]]\nname = "{p}"\nlo = {lo}\nhi = {hi}\n' for p, lo, hi in params)
    return head + dims
