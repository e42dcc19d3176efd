#!/usr/bin/env python3
"""Time the harmonic-drive model in scipy against the hd-model Rust solver.

The equations are those of docs/model.md, written here a second time in the state
coordinates that hd-model integrates (crates/hd-model/src/state.rs):

    y = [θj, ωj, θ, ωz, z, w]      θ = θj/N − θz (gear deflection), w = σ0·s (bristle torque)

and with the same tolerance scaling (crates/hd-model/src/system.rs, `abs_scale`): every
state has absolute tolerance `atol`, except the deflection θ, which has `atol/k0` with
k0 = c + A for the full model and k0 = K̄ for the linear spring. The Rust run also carries
quadrature states (energy integrals); they are outside its error control and are left
out here.

For each case the script
  1. runs `cargo run --release -q -p hd-model --example bench_case` (best-of-N wall time of
     `hd_model::simulate` without a trace, plus θz on the grid t_k = k·dt_out) with the
     method `auto` picks (Rodas4 for the full model) and, for the full model, with Dopri5,
  2. integrates the same problem with `scipy.integrate.solve_ivp(method="LSODA")`, with and
     without the analytic Jacobian, and with `odeint` (the same LSODA Fortran code, driven
     without solve_ivp's per-step Python loop), and
  3. prints the wall times, the ratios, max|Δθz| over the grid divided by the θz amplitude,
     and the error of every run against a reference solution.

The reference is hd-model at rtol 1e-12, atol 1e-15 with the method `auto` picks, checked
against hd-model's other method at the same tolerances (`--ref rust`, the default), or
scipy's Radau at rtol 1e-12 with the analytic Jacobian (`--ref radau`, slow). The amplitude
is hd-model's `thz_amp`: half the peak-to-peak of θz over the last 5 drive cycles.

    python3 benches/scipy_compare.py                  # headline: full model, 1 s, rtol 1e-8
    python3 benches/scipy_compare.py --case all       # also the 0.2 s default-tolerance cases
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import time

import numpy as np
from scipy.integrate import LSODA, odeint, solve_ivp

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "peers"))
from common import best_of as timed  # noqa: E402

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# Seed parameters (docs/model.md §1; crates/hd-model/src/params.rs defaults).
P = dict(
    a=0.12, b=0.56, c=52_000.0, mem_a=40_000.0, mem_b=300.0,
    sigma0=1.2e5, sigma1=0.8, sigma2=0.0, tc=0.15, ts=0.25, ws=0.01,
    r=6.0, km=0.52, ke=0.52, jj=6.8e-4, jz=2.4e-2, cj=0.003, cz=0.005, n=100.0,
    kbar=7.8e5, c0bar=0.16,
)
U_AMP, FREQ = 24.0, 50.0  # seed input: 24 V sine at 50 Hz

CASES = {
    # name: (variant, rtol, atol, t_end)
    "seed-1s": ("full", 1e-8, 1e-11, 1.0),
    "seed-0.2s": ("full", 1e-6, 1e-9, 0.2),
    "damped-0.2s": ("damped", 1e-6, 1e-9, 0.2),
}


def make_full():
    """Right-hand side and Jacobian of the full model (hysteretic stiffness + LuGre)."""
    a, b, c = P["a"], P["b"], P["c"]
    ma, mb = P["mem_a"], P["mem_b"]
    s0, s1, s2 = P["sigma0"], P["sigma1"], P["sigma2"]
    tc, ts, ws = P["tc"], P["ts"], P["ws"]
    r, km, ke = P["r"], P["km"], P["ke"]
    jj, jz, cj, cz, n = P["jj"], P["jz"], P["cj"], P["cz"], P["n"]
    om = 2.0 * math.pi * FREQ
    sin, exp = math.sin, math.exp

    def rhs(t, y):
        wj, th, wz, z, w = y[1], y[2], y[3], y[4], y[5]
        i = (U_AMP * sin(om * t) - ke * wj) / r
        thd = wj / n - wz
        v = wj / n
        tb = ((a * th + b) * th + c) * th + z
        g = tc + (ts - tc) * exp(-(v / ws) ** 2)
        sd = v - abs(v) * w / g
        tf = w + s1 * sd + s2 * v
        return [
            wj,
            (km * i - cj * wj - (tb + tf) / n) / jj,
            thd,
            (tb - cz * wz) / jz,
            ma * thd - mb * z,
            s0 * sd,
        ]

    def jac(t, y):
        wj, th, w = y[1], y[2], y[5]
        v = wj / n
        e = exp(-(v / ws) ** 2)
        g = tc + (ts - tc) * e
        dg = (ts - tc) * e * (-2.0 * v / ws**2)
        sv = 1.0 if v > 0.0 else (-1.0 if v < 0.0 else 0.0)
        sd_v = 1.0 - w * (sv * g - abs(v) * dg) / (g * g)
        sd_w = -abs(v) / g
        kth = (3.0 * a * th + 2.0 * b) * th + c
        tf_v = s1 * sd_v + s2
        tf_w = 1.0 + s1 * sd_w
        J = np.zeros((6, 6))
        J[0, 1] = 1.0
        J[1, 1] = (-km * ke / r - cj - tf_v / (n * n)) / jj
        J[1, 2] = -kth / (n * jj)
        J[1, 4] = -1.0 / (n * jj)
        J[1, 5] = -tf_w / (n * jj)
        J[2, 1] = 1.0 / n
        J[2, 3] = -1.0
        J[3, 2] = kth / jz
        J[3, 3] = -cz / jz
        J[3, 4] = 1.0 / jz
        J[4, 1] = ma / n
        J[4, 3] = -ma
        J[4, 4] = -mb
        J[5, 1] = s0 * sd_v / n
        J[5, 5] = s0 * sd_w
        return J

    return rhs, jac, c + ma


def make_damped():
    """Right-hand side and Jacobian of the `damped` variant (K̄·θ, viscous C̄0·v)."""
    k, c0 = P["kbar"], P["c0bar"]
    r, km, ke = P["r"], P["km"], P["ke"]
    jj, jz, cj, cz, n = P["jj"], P["jz"], P["cj"], P["cz"], P["n"]
    om = 2.0 * math.pi * FREQ
    sin = math.sin

    def rhs(t, y):
        wj, th, wz = y[1], y[2], y[3]
        i = (U_AMP * sin(om * t) - ke * wj) / r
        tb = k * th
        tf = c0 * wj / n
        return [wj, (km * i - cj * wj - (tb + tf) / n) / jj, wj / n - wz,
                (tb - cz * wz) / jz, 0.0, 0.0]

    def jac(t, y):
        J = np.zeros((6, 6))
        J[0, 1] = 1.0
        J[1, 1] = (-km * ke / r - cj - c0 / (n * n)) / jj
        J[1, 2] = -k / (n * jj)
        J[2, 1] = 1.0 / n
        J[2, 3] = -1.0
        J[3, 2] = k / jz
        J[3, 3] = -cz / jz
        return J

    return rhs, jac, k


def theta_z(y):
    """θz = θj/N − θ for a (6, m) array of states."""
    return y[0] / P["n"] - y[2]


def run_rust(variant, rtol, atol, t_end, reps, dt_out, build=True, method="auto"):
    cmd = ["cargo", "run", "--release", "-q", "-p", "hd-model", "--example", "bench_case",
           "--", variant, repr(rtol), repr(atol), repr(t_end), str(reps), repr(dt_out), method]
    if not build:
        exe = os.path.join(REPO, "target", "release", "examples", "bench_case")
        cmd = [exe] + cmd[cmd.index("--") + 1:]
    out = subprocess.run(cmd, cwd=REPO, check=True, capture_output=True, text=True).stdout
    d = json.loads(out)
    d["t"] = np.array(d["t"])
    d["theta_z"] = np.array(d["theta_z"])
    return d


def lsoda_steps(rhs, jac, y0, t_end, rtol, atol_v):
    """Steps LSODA takes: solve_ivp's own stepping loop, repeated untimed to count them."""
    kw = {"jac": jac} if jac is not None else {}
    s = LSODA(rhs, 0.0, y0, t_end, rtol=rtol, atol=atol_v, **kw)
    n = 0
    while s.status == "running":
        s.step()
        n += 1
    return n


def scipy_runs(variant, rtol, atol, t_end, grid, reps, with_odeint=True):
    rhs, jac, k0 = (make_full if variant == "full" else make_damped)()
    y0 = np.zeros(6)
    atol_v = np.full(6, atol)
    atol_v[2] = atol / k0
    rows = {}
    for name, j in (("LSODA + jac", jac), ("LSODA, no jac", None)):
        def go(j=j):
            kw = {"jac": j} if j is not None else {}
            sol = solve_ivp(rhs, (0.0, t_end), y0, method="LSODA", rtol=rtol, atol=atol_v,
                            t_eval=grid, **kw)
            if not sol.success:
                raise RuntimeError(f"{name}: {sol.message}")
            return sol
        wall, sol = timed(go, reps)
        rows[f"solve_ivp {name}"] = dict(wall=wall, thz=theta_z(sol.y),
                                         steps=lsoda_steps(rhs, j, y0, t_end, rtol, atol_v),
                                         nfev=int(sol.nfev), njev=int(sol.njev))
    if with_odeint:
        def go_odeint():
            y, info = odeint(rhs, y0, grid, Dfun=jac, rtol=rtol, atol=atol_v, tfirst=True,
                             full_output=True, mxstep=10**8)
            if info["message"] != "Integration successful.":
                raise RuntimeError(f"odeint: {info['message']}")
            return y, info
        wall, (y, info) = timed(go_odeint, reps)
        rows["odeint (LSODA) + jac"] = dict(wall=wall, thz=theta_z(y.T),
                                             steps=int(info["nst"][-1]),
                                             nfev=int(info["nfe"][-1]),
                                             njev=int(info["nje"][-1]))
    return rows


def radau_reference(variant, t_end, grid, rtol=1e-12, atol=1e-15):
    rhs, jac, k0 = (make_full if variant == "full" else make_damped)()
    atol_v = np.full(6, atol)
    atol_v[2] = atol / k0
    sol = solve_ivp(rhs, (0.0, t_end), np.zeros(6), method="Radau", rtol=rtol, atol=atol_v,
                    jac=jac, t_eval=grid)
    if not sol.success:
        raise RuntimeError(f"Radau reference: {sol.message}")
    return theta_z(sol.y)


def compare(case, args):
    variant, rtol, atol, t_end = CASES[case]
    if args.rtol is not None:  # work-precision runs: same case, other tolerance
        rtol, atol = args.rtol, args.rtol * 1e-3
    print(f"\n=== {case}: variant {variant}, 24 V 50 Hz sine, t_end {t_end} s, "
          f"rtol {rtol:g}, atol {atol:g} (θ: atol/k0), θz grid dt {args.dt_out:g} s ===")
    rust = run_rust(variant, rtol, atol, t_end, args.rust_reps, args.dt_out, build=args.build)
    others = []
    if variant == "full":  # `auto` picks Rodas4 here; time the explicit method too
        others.append(run_rust(variant, rtol, atol, t_end, args.rust_reps, args.dt_out,
                               build=False, method="dopri5"))
    grid = rust["t"]
    amp = rust["thz_amp"]
    if args.ref == "rust":
        r1 = run_rust(variant, 1e-12, 1e-15, t_end, 1, args.dt_out, build=False)
        other = "dopri5" if r1["method"] == "Rodas4" else "rodas4"
        r2 = run_rust(variant, 1e-12, 1e-15, t_end, 1, args.dt_out, build=False, method=other)
        ref = r1["theta_z"]
        ref_label = (f"hd-model {r1['method']} rtol 1e-12 atol 1e-15 (hd-model {r2['method']} "
                     f"at the same tolerances differs from it by "
                     f"{np.max(np.abs(r2['theta_z'] - ref)) / rust['thz_amp']:.1e} of the "
                     f"amplitude)")
    else:
        ref_label = "scipy Radau rtol 1e-12 atol 1e-15 + jac"
        t0 = time.perf_counter()
        ref = radau_reference(variant, t_end, grid)
        ref_label += f" ({time.perf_counter() - t0:.0f} s)"
    rows = scipy_runs(variant, rtol, atol, t_end, grid, args.reps, with_odeint=not args.no_odeint)

    def err(thz):
        return float(np.max(np.abs(thz - ref)) / amp)

    rw = rust["wall_best_s"]
    print(f"θz amplitude (hd-model thz_amp, last 5 cycles): {amp:.6e} rad")
    print(f"reference: {ref_label}")
    print(f"{'solver':28s} {'wall [s]':>11s} {'x hd':>8s} {'steps':>8s} {'f evals':>9s} "
          f"{'jac':>7s} {'max|Δθz| vs Rust':>17s} {'err vs ref':>11s}")
    print(f"{'hd-model ' + rust['method']:28s} {rw:11.5f} {1.0:8.2f} {rust['steps']:8d} "
          f"{rust['rhs_evals']:9d} {rust['jac_evals']:7d} {0.0:17.2e} "
          f"{err(rust['theta_z']):11.2e}")
    summary = dict(case=case, rtol=rtol, atol=atol, amp=amp, reference=ref_label,
                   rust=dict(method=rust["method"], wall=rw, steps=rust["steps"],
                             rejected=rust["rejected"], err=err(rust["theta_z"])))
    for o in others:
        d = float(np.max(np.abs(o["theta_z"] - rust["theta_z"])) / amp)
        print(f"{'hd-model ' + o['method']:28s} {o['wall_best_s']:11.5f} "
              f"{o['wall_best_s'] / rw:8.2f} {o['steps']:8d} {o['rhs_evals']:9d} "
              f"{o['jac_evals']:7d} {d:17.2e} {err(o['theta_z']):11.2e}")
        summary["rust_" + o["method"].lower()] = dict(wall=o["wall_best_s"], steps=o["steps"],
                                                     rejected=o["rejected"], dthz=d,
                                                     err=err(o["theta_z"]))
    for name, r in rows.items():
        d = float(np.max(np.abs(r["thz"] - rust["theta_z"])) / amp)
        steps = "-" if r["steps"] is None else str(r["steps"])
        print(f"{name:28s} {r['wall']:11.5f} {r['wall'] / rw:8.2f} {steps:>8s} "
              f"{r['nfev']:9d} {r['njev']:7d} {d:17.2e} {err(r['thz']):11.2e}")
        summary[name] = dict(wall=r["wall"], ratio=r["wall"] / rw, dthz=d, err=err(r["thz"]),
                             nfev=r["nfev"], njev=r["njev"], steps=r["steps"])
    head = rows["solve_ivp LSODA + jac"]
    print(f"headline: solve_ivp LSODA (analytic jac) / hd-model {rust['method']} "
          f"(the method `auto` picks) = {head['wall'] / rw:.1f}x; max|Δθz|/amplitude = "
          f"{np.max(np.abs(head['thz'] - rust['theta_z'])) / amp:.2e}")
    for o in others:
        print(f"          solve_ivp LSODA (analytic jac) / hd-model {o['method']} = "
              f"{head['wall'] / o['wall_best_s']:.1f}x")
    return summary


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--case", default="seed-1s", choices=[*CASES, "all"])
    ap.add_argument("--rtol", type=float, help="override the case's rtol (atol = rtol·1e-3)")
    ap.add_argument("--reps", type=int, default=3, help="scipy repetitions (best of)")
    ap.add_argument("--rust-reps", type=int, default=20, help="hd-model repetitions (best of)")
    ap.add_argument("--dt-out", type=float, default=1e-4, help="θz comparison grid [s]")
    ap.add_argument("--ref", choices=["rust", "radau"], default="rust")
    ap.add_argument("--no-odeint", action="store_true", help="skip the odeint row")
    ap.add_argument("--no-build", dest="build", action="store_false",
                    help="use target/release/examples/bench_case as built")
    ap.add_argument("--json", help="also write the summary to this file")
    args = ap.parse_args()
    cases = list(CASES) if args.case == "all" else [args.case]
    import scipy
    print(f"python {sys.version.split()[0]}, numpy {np.__version__}, scipy {scipy.__version__}")
    summaries = [compare(c, args) for c in cases]
    if args.json:
        with open(args.json, "w") as f:
            json.dump(summaries, f, indent=1)


if __name__ == "__main__":
    main()
