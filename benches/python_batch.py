#!/usr/bin/env python3
"""hdw.simulate_many against a Python loop over hdw.simulate and against NumbaLSODA.

The batch: 2 000 parameter sets of the seed case (full model, 24 V sine at 50 Hz, 0.2 s
from rest, rtol 1e-6, atol 1e-9), with c, mem_A, mem_B, sigma0 and Jz drawn uniformly
within ±10 % of their defaults (seeded). Three ways through it:

1. ``hdw.simulate_many(x, names=...)`` on ``--threads`` threads (default 2);
2. a Python loop calling ``hdw.simulate(params, trace=False)`` once per set (one core);
3. NumbaLSODA (LSODA with a numba cfunc right-hand side, from benches/peers/seed_numba.py)
   on the same rows, split over ``--threads`` processes of a fork pool, sampled every
   1e-4 s (200 samples per drive cycle, what hdw samples); timed after the JIT has
   compiled, in a separate interpreter that has numba and numbalsoda
   (``--numba-python``, default target/peers-venv/bin/python, made by
   benches/setup-peers.sh).

Each timing is the best of ``--reps``. The script prints the times, the speed-ups against
the targets of issue #13 (≥ 1.8× the loop, ≥ 3× NumbaLSODA) and how closely the three
agree on thz_amp.

    target/py-tests/bin/python benches/python_batch.py      # after tests/python/run.sh
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
NAMES = ["c", "mem_A", "mem_B", "sigma0", "Jz"]
DEFAULTS = [52_000.0, 40_000.0, 300.0, 1.2e5, 2.4e-2]
# The same quantities in seed_numba's packed-row names.
NUMBA_NAMES = ["c", "mem_a", "mem_b", "sigma0", "jz"]
T_END, RTOL, ATOL, DT = 0.2, 1e-6, 1e-9, 1e-4


def design(n: int, seed: int = 13) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.asarray(DEFAULTS) * rng.uniform(0.9, 1.1, size=(n, len(NAMES)))


def best_of(fn, reps: int):
    best, out = float("inf"), None
    for _ in range(reps):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def numba_worker(rows_path: str, procs: int, reps: int, peers: str) -> None:
    """Runs inside the interpreter that has numba: time the batch, print JSON."""
    import multiprocessing as mp

    sys.path.insert(0, peers)
    import seed_numba as sn

    x = np.load(rows_path)
    rows = np.stack([sn.pack({k: v for k, v in zip(NUMBA_NAMES, r)}) for r in x])
    t = sn.grid(T_END, int(round(T_END / DT)) + 1)
    global _T
    _T = t
    sn.solve_many(rows[:1], t[:3], RTOL, ATOL)  # JIT before timing, and before the fork

    def batch():
        chunks = np.array_split(rows, procs * 16)
        with mp.get_context("fork").Pool(procs) as pool:
            return np.concatenate(pool.map(_numba_chunk, chunks))

    sec, amps = best_of(batch, reps)
    print(json.dumps({"seconds": sec, "thz_amp": amps.tolist()}))


_T = None


def _numba_chunk(chunk: np.ndarray) -> np.ndarray:
    import seed_numba as sn

    thz, ok = sn.solve_many(chunk, _T, RTOL, ATOL)
    amps = np.array([sn.thz_amp(_T, thz[k], 50.0) for k in range(len(chunk))])
    amps[~ok] = np.nan
    return amps


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=2000, help="parameter sets")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--numba-python", default=os.path.join(REPO, "target/peers-venv/bin/python"))
    ap.add_argument("--peers", default=os.path.join(REPO, "benches/peers"),
                    help="folder holding seed_numba.py")
    ap.add_argument("--numba-worker", metavar="ROWS.npy", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.numba_worker:
        numba_worker(a.numba_worker, a.threads, a.reps, a.peers)
        return

    import hdw

    x = design(a.n)
    print(f"{a.n} parameter sets, seed case 0.2 s each, rtol {RTOL:g}, atol {ATOL:g}; "
          f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}")
    hdw.simulate_many(x[:4], names=NAMES, threads=a.threads)  # warm the thread pool
    t_many, df = best_of(
        lambda: hdw.simulate_many(x, names=NAMES, threads=a.threads, metrics=["thz_amp"]),
        a.reps,
    )
    cols = df if isinstance(df, dict) else {k: df[k].to_numpy() for k in ("status", "thz_amp")}
    assert all(s == "ok" for s in cols["status"]), "a run of the batch failed"
    amp_many = np.asarray(cols["thz_amp"], dtype=float)
    print(f"simulate_many, {a.threads} threads: {t_many:.2f} s ({a.n / t_many:.0f} runs/s)")

    def loop():
        return np.array([
            hdw.simulate(dict(zip(NAMES, r)), trace=False).metrics["thz_amp"] for r in x
        ])

    t_loop, amp_loop = best_of(loop, a.reps)
    print(f"Python loop over simulate:  {t_loop:.2f} s ({a.n / t_loop:.0f} runs/s)")
    assert np.array_equal(amp_loop, amp_many), "the batch and the loop disagree"
    print(f"  speed-up of simulate_many: {t_loop / t_many:.2f}× (target ≥ 1.8×) "
          f"{'PASS' if t_loop / t_many >= 1.8 else 'FAIL'}; thz_amp identical in every run")

    seed_numba = os.path.join(a.peers, "seed_numba.py")
    if not (os.path.exists(seed_numba) and os.path.exists(a.numba_python)):
        print(f"NumbaLSODA: skipped (needs {seed_numba} and {a.numba_python}; "
              "see benches/setup-peers.sh)")
        return
    with tempfile.TemporaryDirectory() as tmp:
        rows = os.path.join(tmp, "rows.npy")
        np.save(rows, x)
        p = subprocess.run(
            [a.numba_python, os.path.abspath(__file__), "--numba-worker", rows,
             "--threads", str(a.threads), "--reps", str(a.reps), "--peers", a.peers],
            capture_output=True, text=True, check=True,
        )
    res = json.loads(p.stdout.strip().splitlines()[-1])
    t_nb, amp_nb = res["seconds"], np.asarray(res["thz_amp"], dtype=float)
    print(f"NumbaLSODA, {a.threads} processes: {t_nb:.2f} s ({a.n / t_nb:.0f} runs/s), JIT excluded")
    rel = np.nanmax(np.abs(amp_nb - amp_many) / amp_many)
    print(f"  speed-up of simulate_many: {t_nb / t_many:.2f}× (target ≥ 3×) "
          f"{'PASS' if t_nb / t_many >= 3 else 'FAIL'}; thz_amp agrees within {rel:.1e} "
          f"(relative; NumbaLSODA's from samples every {DT:g} s)")


if __name__ == "__main__":
    main()
