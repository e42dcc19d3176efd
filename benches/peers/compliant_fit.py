#!/usr/bin/env python3
"""The compliant-drive fit peer of benches/compliant_peers.py: scipy `least_squares` on a
numba-compiled fixed-step simulation of the drive under a voltage test, written apart from
hdw from docs/model.md §2 (variant `full`, memory law, friction on the wave generator) and
docs/fit-drive.md ("The compliant drive"), as a user's script would have it.

Model (SI units, all states zero at the start but the angles, which start at the record's
first encoder readings; the drive is at rest and the gear unloaded):

    i = (u − Ke·ωj)/R,  Km = Ke
    Jj·ω̇j = Km·i − Cj·ωj − (Tb + Tf)/N        Jz·ω̇z = Tb − Cz·ωz − TL
    θ̇j = ωj,  θ̇ = ωj/N − ωz,  θz = θj/N − θ (plus the start's offset)
    Tb = c·θ + b·θ² + a·θ³ + z,               ż = mem_A·θ̇ − mem_B·z
    v = ωj/N,  G(v) = Tc + (Ts − Tc)·exp(−(v/ωs)²)   (= σ0·g(v), held ≥ 1e-9·Ts if Tc ≈ 0)
    w = σ0·s,  ẇ = σ0·(v − |v|·w/G(v)),      Tf = w + σ1·ṡ + σ2·v

Integration: each sample interval (the voltage u_k held over it: `voltage_between = hold`)
is cut into M equal substeps (default 4). Each substep is classical RK4 on (θj, ωj, θ, ωz,
z); the bristle w is written as its distance from the level it relaxes to at the substep's
start speed v0, w̄ = sign(v0)·G(v0), and that distance is carried by the integrating
factor e^{−λ·τ}, λ = σ0·|v0|/G(v0) (RK4 in the Lawson form about w̄): at a speed held over
the substep the bristle's update is the exact solution of its linear equation, however
fast it relaxes. The current at sample k is read after the voltage u_k is applied:
i_k = (u_k − Ke·ωj(t_k))/R.

Residuals: simulated − logged motor angle, load angle and current, each divided by its
noise level (encoders one count/√12 unless given; the current's from the record's third
differences, RMS(Δ³i)/√20, unless given), and each output's mean taken off: the encoder
zeros and the current sensor's offset are fitted as constants, which is the same as
projecting the residual's mean out. Cost = Σ r² over the 3·n residuals (hdw's fit.json
cost; scipy's `cost` is half of it).

Parameters: the free ones by name (default the benchmark's 11: R, Ke, Jj, Jz, Cj, c, mem_A,
sigma0, Tc, Ts, ws), bounded to [start/1000, start·1000] as hdw's default, either as their
logarithms (`--positive log`, the default) or linear with those bounds (`--positive bound`).
Every other parameter and N come from the params TOML (hd-model's defaults where it is
silent). least_squares(method='trf' or 'dogbox', x_scale='jac', jac='2-point'; ftol = xtol = gtol =
`--tol`, scipy's default 1e-8).

Timing: numba compiles the simulation on the first 50 samples (the JIT time, reported
apart); the fit is then timed warm. Prints one JSON object.

    target/peers-venv/bin/python benches/peers/compliant_fit.py REC.csv \
        --params data/compliant/start.toml [--substeps 4] [--positive log|bound] [--truth]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
import tomllib

import numpy as np

# The simulation's parameter vector (a subset of hdw's registry, in this order).
NAMES = ["R", "Km", "Ke", "Jj", "Jz", "Cj", "Cz", "c", "a", "b", "mem_A", "mem_B",
         "sigma0", "sigma1", "sigma2", "Tc", "Ts", "ws", "TL"]
IX = {k: i for i, k in enumerate(NAMES)}
# hd-model's defaults (crates/hd-model/src/params.rs): the drive `hdw synth drive` records.
DEFAULTS = {"R": 6.0, "Km": 0.52, "Ke": 0.52, "Jj": 6.8e-4, "Jz": 2.4e-2, "Cj": 0.003,
            "Cz": 0.005, "c": 52_000.0, "a": 0.12, "b": 0.56, "mem_A": 40_000.0,
            "mem_B": 300.0, "sigma0": 1.2e5, "sigma1": 0.8, "sigma2": 0.0, "Tc": 0.15,
            "Ts": 0.25, "ws": 0.01, "TL": 0.0, "N": 100.0}
FREE = ["R", "Ke", "Jj", "Jz", "Cj", "c", "mem_A", "sigma0", "Tc", "Ts", "ws"]
# Keys of a params file this model does not hold (refused rather than ignored).
REFUSED_NONZERO = ["L", "mu_c_fwd", "mu_s_fwd", "mu_c_back", "mu_s_back", "Tc_load",
                   "Ts_load", "Tc_neg", "Ts_neg"]
FLOOR = 1e-9  # hd-model's LEVEL_FLOOR_SHARE


def _jit():
    """The numba kernel (compiled on first call)."""
    import numba

    @numba.njit(inline="always", error_model="numpy")
    def level(v, tc, ts, ws):
        r = v / ws
        g = tc + (ts - tc) * math.exp(-r * r)
        fl = FLOOR * abs(ts)
        if abs(tc) < fl and g < fl:
            g = fl
        return g

    @numba.njit(inline="always", error_model="numpy")
    def rates(wj, th, wz, z, w, u, p, inv_n):
        R, Km, Ke, Jj, Jz, Cj, Cz = p[0], p[1], p[2], p[3], p[4], p[5], p[6]
        c, a, b, mA, mB = p[7], p[8], p[9], p[10], p[11]
        s0, s1, s2, tc, ts, ws, tl = p[12], p[13], p[14], p[15], p[16], p[17], p[18]
        v = wj * inv_n
        thd = v - wz
        g = level(v, tc, ts, ws)
        sdot = v - abs(v) * w / g
        tf = w + s1 * sdot + s2 * v
        tb = ((a * th + b) * th + c) * th + z
        cur = (u - Ke * wj) / R
        dwj = (Km * cur - Cj * wj - (tb + tf) * inv_n) / Jj
        dwz = (tb - Cz * wz - tl) / Jz
        dz = mA * thd - mB * z
        dw = s0 * sdot
        return dwj, thd, dwz, dz, dw

    @numba.njit(error_model="numpy")
    def simulate(t, u, p, n_ratio, m, thj0, thz0, out_j, out_z, out_i):
        """Fill out_j, out_z, out_i [rad, rad, A] at every sample; False if not finite."""
        n = t.shape[0]
        inv_n = 1.0 / n_ratio
        s0, tc, ts, ws = p[12], p[15], p[16], p[17]
        R, Ke = p[0], p[2]
        thj, wj, th, wz, z, w = thj0, 0.0, 0.0, 0.0, 0.0, 0.0
        for k in range(n):
            out_j[k] = thj
            out_z[k] = thz0 + (thj - thj0) * inv_n - th
            out_i[k] = (u[k] - Ke * wj) / R
            if not (math.isfinite(thj) and math.isfinite(th) and math.isfinite(w)):
                return False
            if k == n - 1:
                break
            uk = u[k]
            d = (t[k + 1] - t[k]) / m
            hd = 0.5 * d
            for _ in range(m):
                v0 = wj * inv_n
                if v0 != 0.0:
                    g0 = level(v0, tc, ts, ws)
                    lam = s0 * abs(v0) / g0
                    wbar = g0 if v0 > 0.0 else -g0
                else:
                    lam, wbar = 0.0, 0.0
                eh = math.exp(-lam * hd)
                ef = eh * eh
                q0 = w - wbar
                # Stage 1 (the bristle's rate less its frozen linear part: gk).
                a1, b1, c1, d1, e1 = rates(wj, th, wz, z, w, uk, p, inv_n)
                f1 = wj
                g1 = e1 + lam * (w - wbar)
                # Stage 2.
                wj2 = wj + hd * a1
                th2 = th + hd * b1
                wz2 = wz + hd * c1
                z2 = z + hd * d1
                w2 = wbar + eh * (q0 + hd * g1)
                a2, b2, c2, d2, e2 = rates(wj2, th2, wz2, z2, w2, uk, p, inv_n)
                f2 = wj2
                g2 = e2 + lam * (w2 - wbar)
                # Stage 3.
                wj3 = wj + hd * a2
                th3 = th + hd * b2
                wz3 = wz + hd * c2
                z3 = z + hd * d2
                w3 = wbar + eh * q0 + hd * g2
                a3, b3, c3, d3, e3 = rates(wj3, th3, wz3, z3, w3, uk, p, inv_n)
                f3 = wj3
                g3 = e3 + lam * (w3 - wbar)
                # Stage 4.
                wj4 = wj + d * a3
                th4 = th + d * b3
                wz4 = wz + d * c3
                z4 = z + d * d3
                w4 = wbar + ef * q0 + eh * d * g3
                a4, b4, c4, d4, e4 = rates(wj4, th4, wz4, z4, w4, uk, p, inv_n)
                f4 = wj4
                g4 = e4 + lam * (w4 - wbar)
                s6 = d / 6.0
                thj = thj + s6 * (f1 + 2.0 * (f2 + f3) + f4)
                wj = wj + s6 * (a1 + 2.0 * (a2 + a3) + a4)
                th = th + s6 * (b1 + 2.0 * (b2 + b3) + b4)
                wz = wz + s6 * (c1 + 2.0 * (c2 + c3) + c4)
                z = z + s6 * (d1 + 2.0 * (d2 + d3) + d4)
                w = wbar + ef * q0 + s6 * (ef * g1 + 2.0 * eh * (g2 + g3) + g4)
        return True

    return simulate


_SIM = None


def sim_kernel():
    global _SIM
    if _SIM is None:
        _SIM = _jit()
    return _SIM


def read_record(path: str) -> dict:
    """Columns of a CSV as `hdw synth drive` writes it (t, u, i, theta_m, theta_l, ...)."""
    with open(path) as f:
        head = f.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return {k: np.ascontiguousarray(data[:, j]) for j, k in enumerate(head)}


def read_params(path: str | None) -> dict:
    """hd-model's defaults overridden by a params TOML (hdw simulate's format)."""
    p = dict(DEFAULTS)
    if path:
        with open(path, "rb") as f:
            given = tomllib.load(f)
        alias = {"A": "mem_A", "B": "mem_B"}
        for k, v in given.items():
            k = alias.get(k, k)
            if k in REFUSED_NONZERO and v:
                sys.exit(f"{path}: {k} = {v}: this peer's model does not hold it")
            if k == "stiffness" and v != "memory":
                sys.exit(f"{path}: stiffness = {v!r}: this peer has the memory law only")
            if k == "friction_velocity" and v != "motor":
                sys.exit(f"{path}: friction_velocity = {v!r}: this peer has `motor` only")
            if k in p:
                p[k] = float(v)
    return p


def third_difference_noise(x: np.ndarray) -> float:
    """RMS(Δ³x)/√20: white noise of size σ has Var(Δ³x) = 20σ²."""
    d = x[3:] - 3.0 * x[2:-1] + 3.0 * x[1:-2] - x[:-3]
    return float(math.sqrt(np.mean(d * d) / 20.0))


class CompliantFit:
    """The residual r(x) of one record for scipy (x: the free parameters, as logarithms
    or linear), and the plain simulation at a full parameter dict."""

    def __init__(self, rec: dict, params: dict, free: list[str], noise: dict, substeps: int,
                 positive: str = "log", factor: float = 1e3):
        self.t, self.u = rec["t"], rec["u"]
        self.ym, self.yl, self.yi = rec["theta_m"], rec["theta_l"], rec["i"]
        self.n = len(self.t)
        self.params, self.free = dict(params), list(free)
        self.noise, self.m, self.log = noise, int(substeps), positive == "log"
        self.start = np.array([params[k] for k in free], dtype=float)
        if np.any(self.start <= 0.0):
            sys.exit("every free parameter needs a positive start (bounds start/1000..·1000)")
        self.lo, self.hi = self.start / factor, self.start * factor
        self.buf = [np.empty(self.n) for _ in range(3)]
        self.nfun = 0

    def vector(self, values: dict) -> np.ndarray:
        p = np.array([values[k] for k in NAMES], dtype=float)
        p[IX["Km"]] = p[IX["Ke"]]  # km_equals_ke: one constant in SI units
        return p

    def values_of(self, x) -> dict:
        v = dict(self.params)
        phys = np.exp(x) if self.log else np.asarray(x)
        v.update(zip(self.free, (float(a) for a in phys)))
        v["Km"] = v["Ke"]
        return v

    def x0(self):
        return np.log(self.start) if self.log else self.start.copy()

    def bounds(self):
        return (np.log(self.lo), np.log(self.hi)) if self.log else (self.lo, self.hi)

    def run(self, values: dict, t=None, u=None):
        """Simulated (θj, θz, i) at `values` (whole record unless t, u are given)."""
        t = self.t if t is None else t
        u = self.u if u is None else u
        out = self.buf if len(t) == self.n else [np.empty(len(t)) for _ in range(3)]
        ok = sim_kernel()(t, u, self.vector(values), values["N"], self.m, float(self.ym[0]),
                          float(self.yl[0]), out[0], out[1], out[2])
        return ok, out

    def fun(self, x) -> np.ndarray:
        self.nfun += 1
        ok, (sj, sz, si) = self.run(self.values_of(x))
        if not ok:
            return np.full(3 * self.n, 1e50)  # a failed trial: huge but finite
        parts = []
        for s, y, key in ((sj, self.ym, "motor"), (sz, self.yl, "load"), (si, self.yi, "current")):
            r = (s - y) / self.noise[key]
            parts.append(r - r.mean())  # the zero / offset fitted as a constant
        r = np.concatenate(parts)
        return r if np.all(np.isfinite(r)) else np.full(3 * self.n, 1e50)

    def scores(self, x) -> dict:
        r = self.fun(x).reshape(3, self.n)
        rms = np.sqrt(np.mean(r * r, axis=1))
        return {"cost": float(np.sum(r * r)),
                "rms_over_noise": dict(zip(("motor", "load", "current"), map(float, rms)))}


def replay_truth(rec: dict, truth: dict, substeps: int, motor_counts: int, load_counts: int):
    """Max |simulated − true| of θj, θz against the record's theta_j_true / theta_z_true,
    in encoder counts, at the true parameters (starting from the true angles' first
    values)."""
    sim = sim_kernel()
    n = len(rec["t"])
    out = [np.empty(n) for _ in range(3)]
    p = np.array([truth[k] for k in NAMES], dtype=float)
    sim(rec["t"], rec["u"], p, truth["N"], substeps, float(rec["theta_j_true"][0]),
        float(rec["theta_z_true"][0]), *out)
    qm, ql = 2 * math.pi / motor_counts, 2 * math.pi / load_counts
    ej = np.abs(out[0] - rec["theta_j_true"])
    ez = np.abs(out[1] - rec["theta_z_true"])
    return {"substeps": substeps, "max_motor_counts": float(ej.max() / qm),
            "max_load_counts": float(ez.max() / ql), "max_motor_rad": float(ej.max()),
            "max_load_rad": float(ez.max()),
            "rms_motor_counts": float(np.sqrt(np.mean(ej ** 2)) / qm),
            "rms_load_counts": float(np.sqrt(np.mean(ez ** 2)) / ql)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("record", help="CSV with t, u, i, theta_m, theta_l (hdw synth drive)")
    ap.add_argument("--params", help="params TOML: start values, N and the fixed parameters")
    ap.add_argument("--free", default=",".join(FREE), help="free parameters, comma-separated")
    ap.add_argument("--substeps", type=int, default=4, help="RK4 substeps per sample")
    ap.add_argument("--positive", choices=["log", "bound"], default="log",
                    help="free parameters as logarithms, or linear with their bounds")
    ap.add_argument("--bound-factor", type=float, default=1e3,
                    help="bounds start/F to start·F (hdw's default F = 1000)")
    ap.add_argument("--motor-counts", type=int, default=65536)
    ap.add_argument("--load-counts", type=int, default=1 << 20)
    ap.add_argument("--noise-motor", type=float, help="[rad]; default one count/√12")
    ap.add_argument("--noise-load", type=float, help="[rad]; default one count/√12")
    ap.add_argument("--noise-current", type=float,
                    help="[A]; default from the record's third differences")
    ap.add_argument("--max-nfev", type=int, default=2000)
    ap.add_argument("--tol", type=float, default=1e-8,
                    help="least_squares ftol = xtol = gtol (scipy's default 1e-8)")
    ap.add_argument("--method", choices=["trf", "dogbox"], default="trf")
    ap.add_argument("--truth", action="store_true",
                    help="also replay hd-model's defaults against theta_j_true/theta_z_true")
    ap.add_argument("--truth-substeps", default="",
                    help="extra substep counts for the replay, comma-separated")
    ap.add_argument("--no-fit", action="store_true", help="only the replay (with --truth)")
    ap.add_argument("--json", help="also write the result to this file")
    a = ap.parse_args()

    from scipy.optimize import least_squares
    import numba
    import scipy

    rec = read_record(a.record)
    params = read_params(a.params)
    free = [k.strip() for k in a.free.split(",") if k.strip()]
    for k in free:
        if k not in IX or k == "Km":
            sys.exit(f"--free {k}: expected one of {', '.join(n for n in NAMES if n != 'Km')}")
    noise = {
        "motor": a.noise_motor or 2 * math.pi / a.motor_counts / math.sqrt(12),
        "load": a.noise_load or 2 * math.pi / a.load_counts / math.sqrt(12),
        "current": a.noise_current or third_difference_noise(rec["i"]),
    }
    prob = CompliantFit(rec, params, free, noise, a.substeps, a.positive, a.bound_factor)

    # The JIT, on a short slice.
    t0 = time.perf_counter()
    prob.run(params, rec["t"][:50], rec["u"][:50])
    jit = time.perf_counter() - t0

    out = {
        "machine": {"host": platform.node(), "cores": os.cpu_count(),
                    "load_average": [round(x, 2) for x in os.getloadavg()],
                    "blas_threads": os.environ.get("OPENBLAS_NUM_THREADS", "unset"),
                    "python": sys.version.split()[0], "numpy": np.__version__,
                    "scipy": scipy.__version__, "numba": numba.__version__},
        "record": os.path.abspath(a.record), "samples": prob.n, "residuals": 3 * prob.n,
        "substeps": a.substeps, "positive": a.positive, "tol": a.tol, "method": a.method,
        "noise": noise, "free": free,
        "N": params["N"], "jit_seconds": jit,
    }
    if a.truth:
        truth = dict(DEFAULTS)
        counts = [a.substeps] + [int(s) for s in a.truth_substeps.split(",") if s.strip()]
        out["truth_replay"] = [replay_truth(rec, truth, m, a.motor_counts, a.load_counts)
                               for m in counts]
        tp = CompliantFit(rec, truth, free, noise, a.substeps, "log")
        out["truth_scores"] = tp.scores(tp.x0())
    if not a.no_fit:
        x0 = prob.x0()
        out["start_scores"] = prob.scores(x0)
        prob.nfun = 0
        t0 = time.perf_counter()
        res = least_squares(prob.fun, x0, jac="2-point", method=a.method, x_scale="jac",
                            bounds=prob.bounds(), max_nfev=a.max_nfev, ftol=a.tol,
                            xtol=a.tol, gtol=a.tol)
        wall = time.perf_counter() - t0
        values = prob.values_of(res.x)
        sc = prob.scores(res.x)
        at_bound = [k for k, x, lo, hi in zip(free, res.x, *prob.bounds())
                    if x <= lo * (1 + 1e-9) or x >= hi * (1 - 1e-9)]
        out.update({
            "parameters": {k: values[k] for k in ["Km"] + free},
            "fixed": {k: values[k] for k in NAMES if k not in free and k != "Km"},
            "cost": sc["cost"], "scipy_cost": float(res.cost),
            "rms_over_noise": sc["rms_over_noise"],
            "nfev": int(res.nfev), "njev": int(res.njev or 0),
            "simulations": prob.nfun, "status": int(res.status), "message": res.message,
            "optimality": float(res.optimality), "at_bound": at_bound,
            "fit_seconds": wall,
        })
    text = json.dumps(out, indent=1)
    if a.json:
        with open(a.json, "w") as f:
            f.write(text)
    print(text)


if __name__ == "__main__":
    main()
