"""The full harmonic-drive model as a numba cfunc, solved with NumbaLSODA.

The equations are those of docs/model.md and of benches/scipy_compare.py (`make_full`), in
the coordinates hd-model integrates, with one change of scale: NumbaLSODA takes a single
scalar absolute tolerance, so the gear deflection θ is carried as k0·θ (k0 = c + A, the
stiffness scale of `DriveSystem::abs_scale`). A scalar `atol` on k0·θ is then the same
as hd-model's `atol/k0` on θ, and the relative tolerance is unchanged by the scale.

    y = [θj, ωj, k0·θ, ωz, z, w]     θz = θj/N − θ,  w = σ0·s

Every parameter travels in the `data` array, so one compiled right-hand side serves any
parameter set: a sweep or a batch packs one row per run (`pack`) and calls `solve_many`.

    from seed_numba import SEED, pack, solve, thz_amp
    t, thz, ok = solve(pack(SEED), t_end=1.0, n_samples=2001, rtol=1e-8)
    amp = thz_amp(t, thz, SEED["freq"])

Importing the module compiles the right-hand side (about a second); `solve` and
`solve_many` compile on first call.
"""

from __future__ import annotations

import math

import numpy as np
from numba import cfunc, njit
from numbalsoda import dop853, lsoda, lsoda_sig

# Seed parameters (docs/model.md §1; crates/hd-model/src/params.rs defaults) and the seed
# input, a 24 V sine at 50 Hz. benches/peers.py checks them against scipy_compare.P.
SEED = dict(
    a=0.12, b=0.56, c=52_000.0, mem_a=40_000.0, mem_b=300.0,
    sigma0=1.2e5, sigma1=0.8, sigma2=0.0, tc=0.15, ts=0.25, ws=0.01,
    r=6.0, km=0.52, ke=0.52, jj=6.8e-4, jz=2.4e-2, cj=0.003, cz=0.005, n=100.0,
    u_amp=24.0, freq=50.0,
)

#: Order of the parameters in a packed row; the last slot, k0 = c + mem_a, is derived.
FIELDS = ("a", "b", "c", "mem_a", "mem_b", "sigma0", "sigma1", "sigma2", "tc", "ts", "ws",
          "r", "km", "ke", "jj", "jz", "cj", "cz", "n", "u_amp", "freq")
NDATA = len(FIELDS) + 1


def pack(params: dict | None = None, friction_scale: float = 1.0, **over) -> np.ndarray:
    """One parameter row for the cfunc: SEED, updated by `params` and keyword overrides.

    `friction_scale` multiplies the Coulomb and static torques Tc and Ts, as the `hdw study`
    knob of the same name does.
    """
    p = dict(SEED)
    p.update(params or {})
    p.update(over)
    p["tc"] *= friction_scale
    p["ts"] *= friction_scale
    row = np.empty(NDATA)
    row[:-1] = [float(p[k]) for k in FIELDS]
    row[-1] = p["c"] + p["mem_a"]
    return row


@cfunc(lsoda_sig)
def _rhs(t, u, du, p):
    a, b, c, ma, mb = p[0], p[1], p[2], p[3], p[4]
    s0, s1, s2, tc, ts, ws = p[5], p[6], p[7], p[8], p[9], p[10]
    r, km, ke, jj, jz, cj, cz, n = p[11], p[12], p[13], p[14], p[15], p[16], p[17], p[18]
    u_amp, freq, k0 = p[19], p[20], p[21]
    wj = u[1]
    th = u[2] / k0
    wz = u[3]
    z = u[4]
    w = u[5]
    i = (u_amp * math.sin(2.0 * math.pi * freq * t) - ke * wj) / r
    v = wj / n
    thd = v - wz
    tb = ((a * th + b) * th + c) * th + z
    q = v / ws
    g = tc + (ts - tc) * math.exp(-q * q)
    sd = v - abs(v) * w / g
    tf = w + s1 * sd + s2 * v
    du[0] = wj
    du[1] = (km * i - cj * wj - (tb + tf) / n) / jj
    du[2] = k0 * thd
    du[3] = (tb - cz * wz) / jz
    du[4] = ma * thd - mb * z
    du[5] = s0 * sd


#: Address of the compiled right-hand side, for callers that drive NumbaLSODA themselves.
RHS_ADDRESS = _rhs.address


@njit(cache=False)
def _solve_one(row, t_eval, rtol, atol, use_dop853):
    u0 = np.zeros(6)
    if use_dop853:
        usol, ok = dop853(RHS_ADDRESS, u0, t_eval, data=row, rtol=rtol, atol=atol,
                          mxstep=10_000_000)
    else:
        usol, ok = lsoda(RHS_ADDRESS, u0, t_eval, data=row, rtol=rtol, atol=atol,
                         mxstep=10_000_000)
    thz = usol[:, 0] / row[18] - usol[:, 2] / row[21]
    return thz, ok


@njit(cache=False)
def solve_many(rows, t_eval, rtol, atol):
    """θz on `t_eval` for each packed row of `rows` (m × NDATA), from rest, with LSODA.

    Returns (θz as an m × len(t_eval) array [rad], success flags).
    """
    m = rows.shape[0]
    out = np.empty((m, t_eval.shape[0]))
    ok = np.empty(m, dtype=np.bool_)
    for k in range(m):
        thz, good = _solve_one(rows[k], t_eval, rtol, atol, False)
        out[k, :] = thz
        ok[k] = good
    return out, ok


def grid(t_end: float, n_samples: int) -> np.ndarray:
    """The uniform sample times 0 … t_end [s]."""
    return np.linspace(0.0, t_end, n_samples)


def solve(row: np.ndarray, t_end: float = 1.0, n_samples: int = 2001, rtol: float = 1e-6,
          atol: float | None = None, method: str = "lsoda"):
    """Solve one parameter row from rest; returns (t [s], θz [rad], success).

    `atol` defaults to rtol·1e-3 (the benchmarks' convention); it applies to every state,
    and to θ as atol/k0. `method` is "lsoda" (the timed peer) or "dop853" (NumbaLSODA's
    DOP853, used as an independent reference at tight tolerance).
    """
    t = grid(t_end, n_samples)
    atol = rtol * 1e-3 if atol is None else atol
    thz, ok = _solve_one(row, t, rtol, atol, method == "dop853")
    return t, thz, bool(ok)


def thz_amp(t: np.ndarray, thz: np.ndarray, freq: float, cycles: int = 5) -> float:
    """Half the peak-to-peak of θz over the last `cycles` drive periods [rad].

    hd-model's `thz_amp` takes the same window from the continuous solution; on a sampled
    grid the extremes can be missed by up to (sample spacing × peak speed).
    """
    t0 = t[-1] - cycles / freq
    w = thz[t >= t0 - 1e-12]
    return 0.5 * float(w.max() - w.min())
