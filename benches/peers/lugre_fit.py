"""The fit peer of benches/fit_peers.py: scipy `least_squares` on a numba-compiled LuGre
residual, written independently of hdw from docs/model.md §2.3 and §5.

Model (the same as `hdw fit friction --transient`):

    Tf_k = w_k + σ1·ṡ_k + σ2·v_k (+ offset),   ṡ = v − |v|·w/G(v),
    G(v) = Tc + (Ts − Tc)·exp(−(v/ωs)²)  (Tc_neg, Ts_neg for v < 0),

with the bristle torque w = σ0·s stepped exactly over each sample interval at the mean
speed v̄ = (v₀ + v₁)/2 held (an interval where the speed changes sign is split at the
straight line's zero, each part at its own mean): w₁ = w_ss + (w₀ − w_ss)·e^{−λh},
w_ss = sign(v̄)·G(v̄), λ = σ0·|v̄|/G(v̄). The state starts at the first torque less the
offset and the viscous term, held inside [−G(−|v₀|), G(|v₀|)].

Parameters: x = [ln Tc, ln Ts, ln ωs, ln σ0, (ln Tc_neg, ln Ts_neg), σ1, σ2, (offset)];
σ1, σ2 ≥ 0 (least_squares with bounds: 'dogbox' or 'trf', x_scale='jac'). The Jacobian
is analytic: forward sensitivities of w carried beside it in one numba pass
(`jac="analytic"`), or scipy's forward difference of the numba residual
(`jac="2-point"`).
"""

from __future__ import annotations

import math
import time

import numba
import numpy as np
from scipy.optimize import least_squares

# Sensitivity slots of w: Tc, Ts, ωs, σ0, Tc_neg, Ts_neg, and the start's bias (offset).
NS = 7


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
    dg[kc] = 1.0 - e
    dg[ks] = e
    dg[2] = (s - c) * e * 2.0 * r * r / ws
    return c + (s - c) * e


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
    p = [Tc, Ts, ωs, σ0, Tc_neg, Ts_neg]. Returns False if a residual is not finite."""
    n = t.shape[0]
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
    """One record, symmetric or asymmetric: residual and analytic Jacobian for scipy."""

    def __init__(self, t, v, y, asymmetric: bool, offset: bool):
        self.t, self.v, self.y = (np.ascontiguousarray(a, dtype=float) for a in (t, v, y))
        self.asym, self.offset = asymmetric, offset
        self.nl = 6 if asymmetric else 4
        n = len(self.t)
        self.res = np.empty(n)
        self.slip = np.empty(n)
        self.jw = np.empty((n, NS))
        self.js = np.empty((n, NS))

    def split(self, x):
        e = np.exp(x[: self.nl])
        p = np.empty(6)
        p[:4] = e[:4]
        p[4:] = e[4:6] if self.asym else e[:2]
        s1, s2 = x[self.nl], x[self.nl + 1]
        off = x[self.nl + 2] if self.offset else 0.0
        return p, s1, s2, off

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
            cols.append(c * p[k])  # ∂/∂ln p
        if self.asym:
            cols.append(dm[:, 4] * p[4])
            cols.append(dm[:, 5] * p[5])
        cols.append(self.slip.copy())  # σ1 (w and ṡ do not depend on it)
        cols.append(self.v + dm[:, 6] * self.v[0])  # σ2: the viscous term and the start
        if self.offset:
            cols.append(1.0 + dm[:, 6])
        return -np.column_stack(cols)  # residual = data − model

    def rms(self, x):
        r = self.fun(x)
        return float(np.sqrt(np.mean(r * r)))


def linear_start(prob: LuGreFit, p6) -> np.ndarray:
    """x at the nonlinear start p6 (Tc, Ts, ωs, σ0[, Tc_neg, Ts_neg]) with σ1, σ2 (and the
    offset) by least squares at that start, σ1 and σ2 clipped at 0."""
    x = np.zeros(prob.nl + 2 + int(prob.offset))
    x[: prob.nl] = np.log(p6[: prob.nl])
    p, _, _, _ = prob.split(x)
    prob.run(p, 0.0, 0.0, 0.0, False)
    w = prob.y - prob.res
    cols = [prob.slip.copy(), prob.v] + ([np.ones_like(w)] if prob.offset else [])
    beta, *_ = np.linalg.lstsq(np.column_stack(cols), prob.y - w, rcond=None)
    beta[:2] = np.maximum(beta[:2], 0.0)
    x[prob.nl:] = beta
    return x


def fit_one(prob: LuGreFit, x0, jac: str, method: str):
    lo = np.full(len(x0), -np.inf)
    lo[prob.nl : prob.nl + 2] = 0.0
    bounds = (lo, np.full(len(x0), np.inf))
    return least_squares(prob.fun, x0, jac=prob.jac if jac == "analytic" else "2-point",
                         method=method, x_scale="jac", bounds=bounds, max_nfev=2000)


def fit_multistart(t, v, y, starts, asymmetric, offset, jac="analytic", method="dogbox"):
    """Fit from every start; return the best (rms, x, wall [s], nfev summed)."""
    t0 = time.perf_counter()
    prob = LuGreFit(t, v, y, asymmetric, offset)
    best, nfev, njev = None, 0, 0
    for s in starts:
        x0 = linear_start(prob, np.asarray(s, dtype=float))
        try:
            out = fit_one(prob, x0, jac, method)
        except Exception:  # a start that fails is skipped, as hdw does
            continue
        nfev += out.nfev
        njev += out.njev or 0
        rms = prob.rms(out.x)
        if best is None or rms < best[0]:
            best = (rms, out.x)
    wall = time.perf_counter() - t0
    return {"rms": best[0], "x": best[1].tolist(), "wall": wall, "nfev": nfev, "njev": njev}
