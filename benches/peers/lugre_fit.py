"""The fit peer of benches/fit_peers.py: scipy `least_squares` on a numba-compiled LuGre
residual, written independently of hdw from docs/model.md §2.3 and §5, with its own
multi-start derived from the data alone, as a user's script would have it.

Model (the same as `hdw fit friction --transient`):

    Tf_k = w_k + σ1·ṡ_k + σ2·v_k (+ offset),   ṡ = v − |v|·w/G(v),
    G(v) = Tc + (Ts − Tc)·exp(−(v/ωs)²)  (Tc_neg, Ts_neg for v < 0),

G held at or above 1e-9 of the side's larger level (so that a Coulomb level of exactly 0
leaves the bristle's rate |v|/G finite at high speed, as in hdw), with the bristle torque
w = σ0·s stepped exactly over each sample interval at the mean speed v̄ = (v₀ + v₁)/2 held
(an interval where the speed changes sign is split at the straight line's zero, each part
at its own mean): w₁ = w_ss + (w₀ − w_ss)·e^{−λh}, w_ss = sign(v̄)·G(v̄), λ = σ0·|v̄|/G(v̄).
The state starts at the first torque less the offset and the viscous term, held inside
[−G(−|v₀|), G(|v₀|)].

Parameters are the physical ones, x = [Tc, Ts, ωs, σ0, (Tc_neg, Ts_neg), σ1, σ2, (offset)],
with bounds: every level ≥ 0 (a level can sit exactly on 0), σ1, σ2 ≥ 0, ωs, σ0 > 0
(`positive="bound"`: a lower bound of 1e-12; `positive="log"`: ωs and σ0 as their
logarithms, the levels and σ1, σ2 still linear with their bounds). least_squares with
x_scale='jac'. The Jacobian is analytic: forward sensitivities of w carried beside it in
one numba pass (`jac="analytic"`), or scipy's forward difference of the numba residual
(`jac="2-point"`).

Starts (`data_starts`), from the record alone: the level L is the median |torque| while
sliding (|ω| above 1 % of the record's 99th-percentile speed; per side for the asymmetric
law), ωs the 10th percentile of the sliding speeds ω10, Ts = 1.3·L, and σ0 on a grid of four
decades: the values at which the bristle, at the peak level P (95th percentile of |torque|
while sliding), relaxes over 1, 10, 100 and 1000 sample intervals at ω10
(σ0 = P / (ω10 · Δt · k)). Then two Stribeck-dominated starts: Tc = 2 % of L, Ts = L, and
Tc = 2 % of P, Ts = P, each with ωs the median sliding speed and σ0 the grid's geometric
middle.
The asymmetric fit also starts from the peer's own symmetric optimum (levels copied to both
sides), as a user fitting the richer law after the poorer one would. σ1, σ2 (and the offset)
start from linear least squares at each start. The best start wins.
"""

from __future__ import annotations

import math
import time

import numba
import numpy as np
from scipy.optimize import least_squares

# Sensitivity slots of w: Tc, Ts, ωs, σ0, Tc_neg, Ts_neg, and the start's bias (offset).
NS = 7
# Share of the side's larger level below which G is not allowed to fall (hdw's
# LEVEL_FLOOR_SHARE).
FLOOR = 1e-9
# Lower bound of ωs and σ0 with positive="bound".
POS_LB = 1e-12


@numba.njit(cache=False, error_model="numpy")
def _level(v, tc, ts, ws, tcn, tsn, dg):
    """G(v) and ∂G/∂(Tc, Ts, ωs, σ0, Tc_neg, Ts_neg) into dg[0:6]."""
    for i in range(NS):
        dg[i] = 0.0
    if v < 0.0:
        c, s, kc, ks = tcn, tsn, 4, 5
    else:
        c, s, kc, ks = tc, ts, 0, 1
    r = v / ws
    e = math.exp(-r * r)
    g = c + (s - c) * e
    if c >= s:
        fl, kf, ksm, dsm = FLOOR * c, kc, ks, e
    else:
        fl, kf, ksm, dsm = FLOOR * s, ks, kc, 1.0 - e
    if g < fl:
        # Held at the floor (the smaller level within 1e-9 of the larger one, e.g. Tc on
        # its bound 0): the larger level moves it by 1e-9; the smaller level keeps the
        # derivative of the unheld level, the one-sided one that raising it off 0 sees.
        dg[kf] = FLOOR
        dg[ksm] = dsm
        return fl
    dg[kc] = 1.0 - e
    dg[ks] = e
    if e > 0.0:  # (r may be infinite where e is 0)
        dg[2] = (s - c) * e * 2.0 * r * r / ws
    return g


@numba.njit(cache=False, error_model="numpy")
def _held(v, w0, h, p, sens, dg, grad):
    """w after h at held speed v from w0; sens (∂w0/∂p) becomes ∂w/∂p when grad."""
    if v == 0.0 or h <= 0.0:
        return w0
    g = _level(v, p[0], p[1], p[2], p[4], p[5], dg)
    sv = 1.0 if v > 0.0 else -1.0
    av = abs(v)
    lam = p[3] * av / g
    decay = math.exp(-lam * h)
    w_ss = sv * g
    gap = w0 - w_ss
    if grad:
        rise = -math.expm1(-lam * h)
        d_level = sv * rise + gap * decay * h * lam / g
        for i in range(NS):
            sens[i] = decay * sens[i] + d_level * dg[i]
        sens[3] += -gap * decay * h * av / g
    return w_ss + gap * decay


@numba.njit(cache=False, error_model="numpy")
def lugre_pass(t, v, y, p, s1, s2, off, grad, res, slips, jw, js):
    """One pass: residuals y − model into res and ṡ into slips; with grad, ∂w/∂p into jw
    and ∂ṡ/∂p into js (n × NS each; the last slot is the start's bias, offset + σ2·v₀).
    p = [Tc, Ts, ωs, σ0, Tc_neg, Ts_neg]. Returns False if a residual is not finite or a
    side has no level at all."""
    n = t.shape[0]
    if max(p[0], p[1]) <= 0.0 or max(p[4], p[5]) <= 0.0 or p[2] <= 0.0 or p[3] <= 0.0:
        return False
    dg = np.zeros(NS)
    sens = np.zeros(NS)
    # Start: first torque less offset and viscous term, held inside the levels.
    bias = off + s2 * v[0]
    av0 = abs(v[0])
    dlo = np.zeros(NS)
    hi = _level(av0, p[0], p[1], p[2], p[4], p[5], dg)
    lo = _level(-max(av0, 5e-324), p[0], p[1], p[2], p[4], p[5], dlo)
    w = y[0] - bias
    if w >= hi:
        w = hi
        for i in range(NS):
            sens[i] = dg[i]
    elif w <= -lo:
        w = -lo
        for i in range(NS):
            sens[i] = -dlo[i]
    else:
        sens[6] = -1.0  # ∂w0/∂bias
    ok = True
    for k in range(n):
        if k > 0:
            h = t[k] - t[k - 1]
            a, b = v[k - 1], v[k]
            if a * b < 0.0:
                tz = h * abs(a) / (abs(a) + abs(b))
                w = _held(0.5 * a, w, tz, p, sens, dg, grad)
                w = _held(0.5 * b, w, h - tz, p, sens, dg, grad)
            else:
                w = _held(0.5 * (a + b), w, h, p, sens, dg, grad)
        vk = v[k]
        g = _level(vk, p[0], p[1], p[2], p[4], p[5], dg)
        avk = abs(vk)
        slip = vk - avk * w / g
        slips[k] = slip
        res[k] = y[k] - (w + s1 * slip + s2 * vk + off)
        if not math.isfinite(res[k]):
            ok = False
        if grad:
            d_slip_w = -avk / g
            d_slip_g = avk * w / (g * g)
            for i in range(NS):
                jw[k, i] = sens[i]
                js[k, i] = d_slip_w * sens[i] + d_slip_g * dg[i]
            js[k, 6] = d_slip_w * sens[6]
    return ok


class LuGreFit:
    """One record, symmetric or asymmetric: residual and analytic Jacobian for scipy, in
    the physical parameters (ωs and σ0 as logarithms with positive="log")."""

    def __init__(self, t, v, y, asymmetric: bool, offset: bool, positive: str = "bound"):
        self.t, self.v, self.y = (np.ascontiguousarray(a, dtype=float) for a in (t, v, y))
        self.asym, self.offset = asymmetric, offset
        self.log = positive == "log"
        self.nl = 6 if asymmetric else 4
        n = len(self.t)
        self.res = np.empty(n)
        self.slip = np.empty(n)
        self.jw = np.empty((n, NS))
        self.js = np.empty((n, NS))

    def encode(self, p6, lin=()) -> np.ndarray:
        """x from (Tc, Ts, ωs, σ0[, Tc_neg, Ts_neg]) and the linear parameters."""
        x = np.zeros(self.nl + 2 + int(self.offset))
        x[: self.nl] = p6[: self.nl]
        if self.log:
            x[2:4] = np.log(x[2:4])
        x[self.nl : self.nl + len(lin)] = lin
        return x

    def split(self, x):
        p = np.empty(6)
        p[:4] = x[:4]
        if self.log:
            p[2:4] = np.exp(x[2:4])
        p[4:] = x[4:6] if self.asym else x[:2]
        s1, s2 = x[self.nl], x[self.nl + 1]
        off = x[self.nl + 2] if self.offset else 0.0
        return p, s1, s2, off

    def bounds(self):
        m = self.nl + 2 + int(self.offset)
        lo, hi = np.full(m, -np.inf), np.full(m, np.inf)
        lo[: self.nl] = 0.0  # levels (and ωs, σ0 below)
        lo[2:4] = -np.inf if self.log else POS_LB
        lo[self.nl : self.nl + 2] = 0.0  # σ1, σ2
        return lo, hi

    def run(self, p, s1, s2, off, grad):
        return lugre_pass(self.t, self.v, self.y, p, s1, s2, off, grad, self.res, self.slip,
                          self.jw, self.js)

    def fun(self, x):
        if not self.run(*self.split(x), False):
            return np.full_like(self.res, 1e100)  # a failed trial: a huge, finite cost
        return self.res.copy()

    def jac(self, x):
        p, s1, s2, off = self.split(x)
        self.run(p, s1, s2, off, True)
        dm = self.jw + s1 * self.js  # ∂model/∂p at fixed linear parameters, per slot
        cols = []
        for k in range(4):
            c = dm[:, k].copy()
            if not self.asym and k < 2:
                c += dm[:, k + 4]  # the symmetric law's Tc, Ts set both sides
            if self.log and k >= 2:
                c *= p[k]  # ∂/∂ln p
            cols.append(c)
        if self.asym:
            cols.append(dm[:, 4])
            cols.append(dm[:, 5])
        cols.append(self.slip.copy())  # σ1 (w and ṡ do not depend on it)
        cols.append(self.v + dm[:, 6] * self.v[0])  # σ2: the viscous term and the start
        if self.offset:
            cols.append(1.0 + dm[:, 6])
        return -np.column_stack(cols)  # residual = data − model

    def rms(self, x):
        r = self.fun(x)
        return float(np.sqrt(np.mean(r * r)))

    def params(self, x) -> dict:
        p, s1, s2, off = self.split(x)
        d = {"Tc": p[0], "Ts": p[1], "ws": p[2], "sigma0": p[3], "sigma1": s1, "sigma2": s2}
        if self.asym:
            d.update(Tc_neg=p[4], Ts_neg=p[5])
        if self.offset:
            d["offset"] = off
        return {k: float(v) for k, v in d.items()}


def data_starts(t, v, y, asymmetric: bool) -> list[list[float]]:
    """The peer's own starts (Tc, Ts, ωs, σ0, Tc_neg, Ts_neg), from the record alone
    (module docstring)."""
    av = np.abs(v)
    slide = av > 0.01 * np.percentile(av, 99)
    if not slide.any():
        slide = av > 0.0
    level = float(np.median(np.abs(y[slide])))
    if asymmetric:
        pos, neg = slide & (v > 0), slide & (v < 0)
        lp = float(np.median(y[pos])) if pos.any() else level
        ln = float(-np.median(y[neg])) if neg.any() else level
        lp, ln = (lp if lp > 0 else level), (ln if ln > 0 else level)
    else:
        lp = ln = level
    peak = float(np.percentile(np.abs(y[slide]), 95))
    ws_lo = float(np.percentile(av[slide], 10))
    ws_mid = float(np.median(av[slide]))
    dt = float(np.median(np.diff(t)))
    grid = [peak / (ws_lo * dt * k) for k in (1.0, 10.0, 100.0, 1000.0)]
    starts = [[lp, 1.3 * lp, ws_lo, s0, ln, 1.3 * ln] for s0 in grid]
    s_mid = math.sqrt(grid[1] * grid[2])
    starts.append([0.02 * lp, lp, ws_mid, s_mid, 0.02 * ln, ln])
    starts.append([0.02 * peak, peak, ws_mid, s_mid, 0.02 * peak, peak])
    return starts


def linear_start(prob: LuGreFit, p6) -> np.ndarray:
    """x at the nonlinear start p6 with σ1, σ2 (and the offset) by least squares at that
    start, σ1 and σ2 clipped at 0."""
    x = prob.encode(np.asarray(p6, dtype=float))
    p, _, _, _ = prob.split(x)
    prob.run(p, 0.0, 0.0, 0.0, False)
    w = prob.y - prob.res
    cols = [prob.slip.copy(), prob.v] + ([np.ones_like(w)] if prob.offset else [])
    beta, *_ = np.linalg.lstsq(np.column_stack(cols), prob.y - w, rcond=None)
    beta[:2] = np.maximum(beta[:2], 0.0)
    x[prob.nl :] = beta
    return x


def fit_one(prob: LuGreFit, x0, jac: str, method: str):
    lo, hi = prob.bounds()
    x0 = np.clip(x0, lo, hi)
    return least_squares(prob.fun, x0, jac=prob.jac if jac == "analytic" else "2-point",
                         method=method, x_scale="jac", bounds=(lo, hi), max_nfev=2000)


def fit_multistart(t, v, y, asymmetric, offset, jac="analytic", method="trf",
                   positive="bound", extra_starts=(), extra_x=()):
    """Fit from every data-derived start (and any extra starts p6, or full x vectors of a
    nested fit in extra_x as {"x": ..., "asymmetric": ...}); return the best (rms, params,
    wall [s], nfev summed, per-start rms)."""
    t0 = time.perf_counter()
    prob = LuGreFit(t, v, y, asymmetric, offset, positive)
    starts = [("data", s) for s in data_starts(prob.t, prob.v, prob.y, asymmetric)]
    starts += [("extra", s) for s in extra_starts]
    x0s = [(kind, linear_start(prob, s)) for kind, s in starts]
    for nested in extra_x:  # a nested (symmetric) optimum: levels copied to both sides
        x = np.asarray(nested, dtype=float)
        nl = 4
        p6 = np.concatenate([x[:4], x[:2]])
        if positive == "log":
            p6[2:4] = np.exp(p6[2:4])
        x0 = prob.encode(p6, x[nl : nl + 2])
        x0s.append(("nested", x0))
    best, nfev, njev, per = None, 0, 0, []
    for kind, x0 in x0s:
        try:
            out = fit_one(prob, x0, jac, method)
        except Exception as e:  # a start that fails is skipped, as hdw does
            per.append({"kind": kind, "error": str(e)[:200]})
            continue
        nfev += out.nfev
        njev += out.njev or 0
        rms = prob.rms(out.x)
        per.append({"kind": kind, "rms": rms, "nfev": out.nfev, "status": out.status})
        if best is None or rms < best[0]:
            best = (rms, out.x)
    wall = time.perf_counter() - t0
    return {"rms": best[0], "x": best[1].tolist(), "params": prob.params(best[1]),
            "wall": wall, "nfev": nfev, "njev": njev, "starts": per}
