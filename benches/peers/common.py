"""Small helpers shared by the benchmark scripts (peers.py, memory.py, fit_peers.py,
compliant_peers.py): paths, timing, tables."""

from __future__ import annotations

import math
import os
import resource
import subprocess
import sys
import time

BENCHES = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
REPO = os.path.dirname(BENCHES)
if BENCHES not in sys.path:  # for `import scipy_compare`
    sys.path.insert(0, BENCHES)


def hdw_path(given: str | None) -> str:
    """The hdw binary: the given path, or the workspace's release build."""
    exe = given or os.path.join(REPO, "target", "release", "hdw")
    if not os.access(exe, os.X_OK):
        sys.exit(f"no hdw binary at {exe}: run `cargo build --release -p hd-cli` or pass --hdw")
    return os.path.abspath(exe)


def build_bench_case() -> str:
    """Build hd-model's bench_case example in release and return its path."""
    subprocess.run(["cargo", "build", "--release", "-q", "-p", "hd-model", "--example",
                    "bench_case"], cwd=REPO, check=True)
    return os.path.join(REPO, "target", "release", "examples", "bench_case")


def child_cpu() -> float:
    """CPU time [s] (user + system) of every finished child process so far."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def best_of(fn, reps: int, slow: float = 10.0):
    """Best wall time [s] of `fn()` over `reps` calls (stops early once a call exceeds `slow` s),
    and the last result."""
    best, result = math.inf, None
    for _ in range(max(reps, 1)):
        t0 = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - t0)
        if best > slow:
            break
    return best, result


def time_process(cmd: list[str], env: dict | None = None, cwd: str = REPO) -> float:
    """Wall time [s] of one whole process; raises with its stderr if it fails."""
    t0 = time.perf_counter()
    p = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} exited {p.returncode}: {p.stderr.strip()[-2000:]}")
    return wall


def at_error(points: list[dict], target: float):
    """Time of one solver at error `target`, from its runs over several tolerances (and,
    where the points carry an `atol_factor`, over several atol = rtol·factor: each factor's
    rtol sweep is interpolated on its own and the best is taken).

    `points` are dicts with rtol, err and wall. Returns (cheapest, interpolated):
    - cheapest: the fastest run whose error is ≤ target, as (wall [s], rtol), or None;
    - interpolated: wall time at error = target, interpolated log–log between the two
      tolerances (ordered loose to tight) whose errors bracket it; the loosest run's time if
      even that one meets the target; None if no run does.
    """
    meet = [p for p in points if p["err"] <= target]
    cheapest = min(((p["wall"], p["rtol"], p.get("atol_factor")) for p in meet), default=None)
    factors = sorted({p.get("atol_factor") for p in points}, key=lambda f: -(f or 0))
    if len(factors) > 1:
        interps = [_interp([p for p in points if p.get("atol_factor") == f], target)
                   for f in factors]
        return cheapest, min((i for i in interps if i is not None), default=None)
    return cheapest, _interp(points, target)


def _interp(points: list[dict], target: float):
    """Wall time at error = target along one rtol sweep (see at_error)."""
    pts = sorted(points, key=lambda p: -p["rtol"])
    interp = None
    if pts and pts[0]["err"] <= target:
        interp = pts[0]["wall"]
    else:
        for lo, hi in zip(pts, pts[1:]):
            if lo["err"] > target >= hi["err"]:
                x0, x1 = math.log(lo["err"]), math.log(hi["err"])
                f = (math.log(target) - x0) / (x1 - x0) if x1 != x0 else 1.0
                interp = math.exp(math.log(lo["wall"]) + f * (math.log(hi["wall"])
                                                              - math.log(lo["wall"])))
                break
    return interp


def ms(x: float | None) -> str:
    """A wall time [s] as milliseconds for a table cell."""
    if x is None:
        return "—"
    return f"{x * 1e3:.3g} ms" if x < 10 else f"{x:.3g} s"


def verdict(ok: bool) -> str:
    return "PASS" if ok else "FAIL"
