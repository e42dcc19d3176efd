#!/usr/bin/env python3
"""hdw's friction fits against a scipy + numba peer with its own, independent multi-start.

For each record, `hdw fit friction --transient` runs symmetric and `--asymmetric` as whole
processes (best of --reps, reading and writing included); the fit each one reports is read
from its fit.json, and the series it fitted (t, omega, torque) from its
transient-fitted.parquet, so the peer fits exactly the same numbers (the tribometer's speed
is hdw's Savitzky–Golay derivative of the position). The peer (benches/peers/lugre_fit.py)
is scipy `least_squares` on a numba-compiled LuGre residual with the bristle stepped
exactly over each sample, as hdw does (docs/model.md §5), in the physical parameters with
bounds (levels ≥ 0, so a level can sit exactly on 0; σ1, σ2 ≥ 0; ωs, σ0 > 0) and
x_scale='jac'. It knows nothing of hdw's starts: it derives its own from the record, as a
user's script would (a grid of four decades over σ0 around the record's plausible range,
the Coulomb level from the median |torque| while sliding, and Stribeck-dominated starts;
the asymmetric fit also from the peer's own symmetric optimum), and the best start wins.
It runs as one Python process per record (its two fits): the process's wall time includes
imports and numba's compilation, as a user sees it; each fit is then timed again warm.

Records:
- `tribometer`: data/tribometer-reciprocating.txt (42 579 samples, real).
- `joint`: a synthetic joint-friction test of about 25 000 samples made by
  `hdw synth friction --transient --profile joint` (asymmetric levels, 2 % noise).
- `joint-tc0`: the same profile with Tc = 0 (Ts 0.45 N·m, ωs 0.09 rad/s): friction that
  falls from its static level to nothing over the speed range, an optimum with the
  Coulomb level on its bound.

    benches/setup-peers.sh   # or a venv with numpy, scipy, numba, pyarrow
    target/peers-venv/bin/python benches/fit_peers.py [--reps 3] [--json out.json]

It ends with PASS/FAIL against the targets of issue #50 (and the fit times of issue #36).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "peers"))
from common import child_cpu  # noqa: E402
REPO = os.path.dirname(HERE)
WORK = os.path.join(REPO, "target", "fit-peers")

TRIBOMETER = [
    "data/tribometer-reciprocating.txt", "--transient-columns", "Time [s],Friction [uN]",
    "--position-column", "Position [mm]", "--position-scale", "1e-3", "--torque-scale", "-1e-6",
]
# A robot-joint-like friction test: plateaus at 8 speeds from 1e-3 to 1 rad/s, 5 kHz,
# 8·2·(0.26 + 0.05) s = 4.96 s → 24 800 samples; asymmetric levels, 2 % noise.
JOINT_SYNTH = [
    "synth", "friction", "--transient", "--profile", "joint", "--dwell", "0.26",
    "--set", "Tc=2.0", "--set", "Ts=2.6", "--set", "ws=0.02", "--set", "sigma0=2e4",
    "--set", "sigma1=5", "--set", "sigma2=3", "--set", "Tc_neg=2.4", "--set", "Ts_neg=2.9",
    "--noise", "0.02", "--seed", "36",
]
# The same profile with the Coulomb level at 0 (issue #50's second recording had its
# script optimum there: Tc = 0, Ts = 0.452 N·m, ωs = 0.088 rad/s); symmetric, 2 % noise.
# Then, as in crates/hd-ident/tests/joint_corpus.rs, TC0_BELOW·sign(ω) is taken off where
# the Stribeck term has faded (a Coulomb level a little below 0), so that the best fit of
# either law has Tc exactly on its bound 0 (with Tc = 0 exactly, σ1·ṡ favours a Coulomb
# level a little above 0: docs/model.md §5).
JOINT_TC0_SYNTH = [
    "synth", "friction", "--transient", "--profile", "joint", "--dwell", "0.26",
    "--set", "Tc=0", "--set", "Ts=0.45", "--set", "ws=0.09", "--set", "sigma0=5e4",
    "--set", "sigma1=0.3", "--set", "sigma2=0.02",
    "--noise", "0.02", "--seed", "50",
]
TC0_BELOW, TC0_WS = 0.03, 0.09
SYNTH = {"joint": JOINT_SYNTH, "joint-tc0": JOINT_TC0_SYNTH}
RECORDS = ["tribometer", "joint", "joint-tc0"]

# Targets of issue #50.
RMS_SLACK = 1.005  # hdw's RMS at most 0.5 % above the peer's best
SPEEDUP = 10.0  # the peer's run against hdw symmetric + asymmetric
# Fit times of issue #36 (fit.json wall_time_s).
TRIBOMETER_SECONDS = 0.5  # all six LuGre parameters
JOINT_SECONDS = 0.15  # each ~25k-sample fit

SHOWN = ["Tc", "Ts", "ws", "sigma0", "sigma1", "sigma2", "Tc_neg", "Ts_neg", "offset"]


def run_hdw(hdw: str, args: list[str], out: str, reps: int) -> dict:
    """Best wall time of the whole `hdw fit friction` process, and its fit.json."""
    cmd = [hdw, "fit", "friction", "--transient", *args, "--out", out]
    walls, fit_walls, cpus = [], [], []
    for _ in range(max(reps, 1)):
        t0, c0 = time.perf_counter(), child_cpu()
        p = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True)
        walls.append(time.perf_counter() - t0)
        cpus.append(child_cpu() - c0)
        if p.returncode != 0:
            sys.exit(f"{' '.join(cmd)} failed: {p.stderr.strip()[-2000:]}")
        with open(os.path.join(out, "fit.json")) as f:
            fit = json.load(f)
        fit_walls.append(fit["wall_time_s"])
    params = {k: v["value"] for k, v in fit["parameters"].items()
              if isinstance(v, dict) and "value" in v}
    return {"process": min(walls), "walls": walls, "fit_wall": min(fit_walls), "cpu": min(cpus),
            "rms": fit["rms"], "nested_rms": (fit.get("nested") or {}).get("rms"), "params": params, "starts": len(fit.get("refinement_starts", [])),
            "iterations": fit["iterations"], "evaluations": fit["evaluations"]}


def series(out: str):
    import pyarrow.parquet as pq

    tab = pq.read_table(os.path.join(out, "transient-fitted.parquet"))
    return [tab.column(c).to_numpy() for c in ("t", "omega", "torque")]


def worker(job_path: str, jac: str, method: str, positive: str, nested: bool) -> None:
    """The peer's process: its fits of one record cold (JIT on first use), then warm. The
    asymmetric fit also starts from this round's symmetric optimum when nested."""
    t_start = time.perf_counter()
    import numpy as np

    from lugre_fit import fit_multistart

    with open(job_path) as f:
        job = json.load(f)
    results, cold_end, cpu_cold = [], None, None
    for rnd in ("cold", "warm"):
        sym_x = None
        for fit in job:
            d = np.load(fit["data"])
            extra = [sym_x] if (nested and fit["asymmetric"] and sym_x is not None) else []
            r = fit_multistart(d["t"], d["omega"], d["torque"], fit["asymmetric"],
                               fit["asymmetric"], jac, method, positive, extra_x=extra)
            if not fit["asymmetric"]:
                sym_x = r["x"]
            r.update(record=fit["record"], asymmetric=fit["asymmetric"], round=rnd)
            results.append(r)
        if cold_end is None:
            cold_end, cpu_cold = time.time(), time.process_time()
    print(json.dumps({"results": results, "cold_end": cold_end, "cpu_cold": cpu_cold,
                      "inside": time.perf_counter() - t_start}))


def fmt(x) -> str:
    return "–" if x is None else f"{x:.4g}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--hdw", default=os.path.join(REPO, "target", "release", "hdw"))
    ap.add_argument("--reps", type=int, default=3, help="best of N hdw processes")
    ap.add_argument("--jac", choices=["analytic", "2-point"], default="analytic",
                    help="the peer's Jacobian: numba sensitivities or scipy's difference")
    ap.add_argument("--method", choices=["dogbox", "trf"], default="trf",
                    help="least_squares method (both take the bounds)")
    ap.add_argument("--positive", choices=["bound", "log"], default="bound",
                    help="ωs and σ0 linear with a lower bound, or as logarithms")
    ap.add_argument("--no-nested", action="store_true",
                    help="no asymmetric start from the peer's own symmetric optimum")
    ap.add_argument("--only", choices=RECORDS, action="append")
    ap.add_argument("--json", help="also write every measurement to this file")
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.worker:
        worker(a.worker, a.jac, a.method, a.positive, not a.no_nested)
        return

    import numba
    import numpy as np
    import scipy

    commit = subprocess.run(["git", "log", "-1", "--format=%h %cI"], cwd=REPO,
                            capture_output=True, text=True).stdout.strip()
    hdw_mtime = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime(os.path.getmtime(a.hdw)))
    print(f"{platform.node()}: {os.cpu_count()} cores, load average "
          f"{' '.join(f'{x:.1f}' for x in os.getloadavg())}; "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; main at {commit}, hdw "
          f"built {hdw_mtime}; python {sys.version.split()[0]}, numpy {np.__version__}, "
          f"scipy {scipy.__version__}, numba {numba.__version__}; peer: least_squares "
          f"method={a.method}, x_scale='jac', jac={a.jac}, ωs and σ0 "
          f"{'as logarithms' if a.positive == 'log' else 'linear, bounded'}, "
          f"{'no ' if a.no_nested else ''}nested start")
    os.makedirs(WORK, exist_ok=True)
    names = a.only or RECORDS
    records = {}
    for name in names:
        if name == "tribometer":
            records[name] = TRIBOMETER
        else:
            path = os.path.join(WORK, f"{name}.csv")
            subprocess.run([a.hdw, *SYNTH[name], "--out", path], cwd=REPO, check=True,
                           capture_output=True)
            if name == "joint-tc0":
                d = np.genfromtxt(path, delimiter=",", names=True)
                cols = d.dtype.names
                w = d[cols[1]]
                d[cols[2]] -= TC0_BELOW * np.sign(w) * (1.0 - np.exp(-((w / TC0_WS) ** 2)))
                np.savetxt(path, np.column_stack([d[c] for c in cols]), delimiter=",",
                           header=",".join(cols), comments="", fmt="%.17g")
            records[name] = [path]

    hdw, job = {}, []
    for name, args in records.items():
        for asym in (False, True):
            key = f"{name}{' --asymmetric' if asym else ''}"
            out = os.path.join(WORK, f"{name}-{'asym' if asym else 'sym'}")
            r = run_hdw(a.hdw, args + (["--asymmetric"] if asym else []), out, a.reps)
            hdw[key] = r
            t, w, y = series(out)
            data = os.path.join(WORK, f"{name}-{'asym' if asym else 'sym'}.npz")
            np.savez(data, t=t, omega=w, torque=y)
            job.append({"record": name, "asymmetric": asym, "data": data, "key": key,
                        "n": len(t)})
    # One peer process per record, as a user would run a script on one file.
    peer_process, peer_cpu, results = {}, {}, []
    for name in records:
        part = [j for j in job if j["record"] == name]
        job_path = os.path.join(WORK, f"job-{name}.json")
        with open(job_path, "w") as f:
            json.dump(part, f)
        t0, c0 = time.time(), child_cpu()
        # One BLAS thread: on the shared 2-core machine OpenBLAS's spinning threads made the
        # peer 1.8× slower (5.65 s against 3.09 s for the joint record's process).
        env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
                   MKL_NUM_THREADS="1")
        cmd = [sys.executable, os.path.abspath(__file__), "--worker", job_path, "--jac", a.jac,
               "--method", a.method, "--positive", a.positive]
        p = subprocess.run(cmd + (["--no-nested"] if a.no_nested else []),
                           capture_output=True, text=True, env=env)
        if p.returncode != 0:
            sys.exit(f"peer failed: {p.stderr[-3000:]}")
        out = json.loads(p.stdout.strip().splitlines()[-1])
        # From the process's start to the end of its cold round (the warm round after it
        # is the bench's, not the user's).
        peer_process[name] = out["cold_end"] - t0
        peer_cpu[name] = (child_cpu() - c0, out["cpu_cold"])
        results += out["results"]
    cold = {(r["record"], r["asymmetric"]): r for r in results if r["round"] == "cold"}
    warm = {(r["record"], r["asymmetric"]): r for r in results if r["round"] == "warm"}

    print()
    print("| record | fit | samples | hdw process (CPU) | hdw fit | hdw RMS | peer starts | "
          "peer cold | peer warm | peer best RMS | hdw / peer RMS |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    checks = []
    for j in job:
        k = (j["record"], j["asymmetric"])
        h, c, w = hdw[j["key"]], cold[k], warm[k]
        # The cold and warm rounds run the same starts; their optima agree to rounding.
        peer_rms = min(c["rms"], w["rms"])
        ratio = h["rms"] / peer_rms
        j["ratio"] = ratio
        print(f"| {j['record']} | {'asymmetric' if j['asymmetric'] else 'symmetric'} | "
              f"{j['n']} | {h['process']:.3f} s ({h['cpu']:.3f} s) | {h['fit_wall']:.3f} s | "
              f"{h['rms']:.6g} | {len(c['starts'])} | {c['wall']:.2f} s | {w['wall']:.2f} s | "
              f"{peer_rms:.6g} | {ratio:.5f} |")
        checks.append((f"{j['key']}: hdw RMS ≤ {RMS_SLACK} × the peer's best",
                       ratio <= RMS_SLACK, f"{h['rms']:.6g} / {peer_rms:.6g} = {ratio:.5f}"))
    print()
    print("| record | fit | side | " + " | ".join(SHOWN) + " |")
    print("|---|---|---|" + "---:|" * len(SHOWN))
    for j in job:
        k = (j["record"], j["asymmetric"])
        h = hdw[j["key"]]["params"]
        pbest = min((cold[k], warm[k]), key=lambda r: r["rms"])["params"]
        fit = "asymmetric" if j["asymmetric"] else "symmetric"
        for side, pv in (("hdw", h), ("peer", pbest)):
            print(f"| {j['record']} | {fit} | {side} | "
                  + " | ".join(fmt(pv.get(n)) for n in SHOWN) + " |")
    for name in records:
        hs, ha = hdw[name]["rms"], hdw[f"{name} --asymmetric"]["rms"]
        checks.append((f"{name}: hdw asymmetric RMS ≤ symmetric RMS", ha <= hs,
                       f"{ha:.6g} against {hs:.6g}"))
    for name in records:
        hs = sum(hdw[j["key"]]["process"] for j in job if j["record"] == name)
        pc = sum(cold[(name, asym)]["wall"] for asym in (False, True))
        pw = sum(warm[(name, asym)]["wall"] for asym in (False, True))
        pp = peer_process[name]
        hc = sum(hdw[j["key"]]["cpu"] for j in job if j["record"] == name)
        print(f"\n{name}: CPU time, hdw's two processes {hc:.3f} s, the peer's process to the "
              f"end of its two fits {peer_cpu[name][1]:.2f} s ({peer_cpu[name][1] / hc:.1f}×)")
        print(f"{name}: hdw symmetric + asymmetric processes {hs:.3f} s; peer process "
              f"{pp:.2f} s ({pp / hs:.1f}×; its two fits {pc:.2f} s with JIT, {pw:.2f} s warm: "
              f"{pw / hs:.1f}×)")
        checks.append((f"{name}: peer's run ≥ {SPEEDUP}× hdw's two fits", pp / hs >= SPEEDUP,
                       f"{pp:.2f} s / {hs:.3f} s = {pp / hs:.1f}× (warm fits alone "
                       f"{pw / hs:.1f}×)"))
        # The asymmetric process fits the symmetric law first (its nested start) and reports
        # it in fit.json's `nested`: that one process gives both laws (the symmetric one
        # with the asymmetric law's offset, where the peer's symmetric fit has none).
        one = hdw[f"{name} --asymmetric"]
        if one.get("nested_rms") is not None:
            print(f"{name}: hdw's asymmetric process alone, which also reports the nested "
                  f"symmetric law (RMS {one['nested_rms']:.6g}, with the offset), "
                  f"{one['process']:.3f} s: {pp / one['process']:.1f}× the peer's run")
    for j in job:
        if j["record"] == "tribometer" and j["asymmetric"]:
            continue  # issue #36's 0.5 s is for the six parameters of the symmetric law
        limit = TRIBOMETER_SECONDS if j["record"] == "tribometer" else JOINT_SECONDS
        h = hdw[j["key"]]
        checks.append((f"{j['key']}: hdw fit ≤ {limit} s (issue #36)", h["fit_wall"] <= limit,
                       f"{h['fit_wall']:.3f} s (process {h['process']:.3f} s)"))
    print()
    for what, ok, got in checks:
        print(f"{'PASS' if ok else 'FAIL'}  {what}: {got}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"hdw": hdw, "peer": results, "peer_process": peer_process,
                       "peer_cpu": peer_cpu, "job": job}, f, indent=1)


if __name__ == "__main__":
    main()
