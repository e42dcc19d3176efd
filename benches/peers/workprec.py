"""Work against precision on the seed case: hdw, NumbaLSODA and scipy LSODA.

Seed case: full model, seed parameters, 24 V sine at 50 Hz from rest, 1 s simulated. The
error of a run is max |θz − θz_ref| over 2001 uniform samples, divided by the steady θz
amplitude (hd-model's thz_amp, half the peak-to-peak over the last 5 cycles). The reference
is NumbaLSODA's DOP853 (Hairer's code, not hd-model's) at rtol 1e-13 on the Python
equations; before anything is timed, hd-model at rtol 1e-12 must agree with it to 1e-6 of
the amplitude, or the Python equations are not hd-model's and the run stops.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

import scipy_compare as sc
import seed_numba as sn
from common import at_error, best_of, ms

T_END = 1.0
N_SAMPLES = 2001
DT_OUT = T_END / (N_SAMPLES - 1)
RHS_CHECK = 1e-6  # largest allowed |hdw − Python reference| / amplitude at tight tolerance
START_UP = 0.1  # [s] the start-up from rest, reported apart from the rest of the run


def check_equations() -> None:
    """The Python seed parameters must be scipy_compare's (the shared equations)."""
    want = dict(sc.P, u_amp=sc.U_AMP, freq=sc.FREQ)
    for k in sn.FIELDS:
        if want[k] != sn.SEED[k]:
            raise SystemExit(f"seed_numba.SEED[{k!r}] = {sn.SEED[k]} but scipy_compare has "
                             f"{want[k]}: the two Python models disagree")


def reference():
    """(grid, θz_ref, amplitude, |hdw tight − ref|/amp); stops if the RHS disagree."""
    t, ref, ok = sn.solve(sn.pack(sn.SEED), T_END, N_SAMPLES, rtol=1e-13, atol=1e-16,
                          method="dop853")
    if not ok:
        raise SystemExit("reference solve (NumbaLSODA DOP853, rtol 1e-13) failed")
    tight = sc.run_rust("full", 1e-12, 1e-15, T_END, 1, DT_OUT, build=False)
    if len(tight["theta_z"]) != N_SAMPLES:
        raise SystemExit(f"bench_case returned {len(tight['theta_z'])} samples, "
                         f"expected {N_SAMPLES}")
    amp = tight["thz_amp"]
    dev = float(np.max(np.abs(tight["theta_z"] - ref)) / amp)
    if not dev <= RHS_CHECK:
        raise SystemExit(f"RHS CHECK FAILED: hd-model (rtol 1e-12, {tight['method']}) and the "
                         f"Python reference differ by {dev:.2e} of the amplitude (limit "
                         f"{RHS_CHECK:g}): benches/peers/seed_numba.py is not hd-model's model")
    return t, ref, amp, dev


def scipy_lsoda(rtol: float, t: np.ndarray, atol_factor: float = 1e-3):
    """solve_ivp LSODA with the analytic Jacobian (its faster form); returns θz."""
    rhs, jac, k0 = sc.make_full()
    atol_v = np.full(6, rtol * atol_factor)
    atol_v[2] /= k0
    sol = solve_ivp(rhs, (0.0, T_END), np.zeros(6), method="LSODA", rtol=rtol, atol=atol_v,
                    jac=jac, t_eval=t)
    if not sol.success:
        raise RuntimeError(f"solve_ivp LSODA at rtol {rtol:g}: {sol.message}")
    return sc.theta_z(sol.y)


def run(rtols, reps_hdw: int, reps_numba: int, reps_scipy: int, log=print,
        atol_factors=(1e-3,)) -> dict:
    """Time every solver at every rtol and every atol = rtol·factor; returns
    {solver: [dict(rtol, atol_factor, wall, err, …)]}. Each solver gets the same grid, so
    each one's best settings at an error bound are among the points (issue #36 item 5).

    hdw is timed by target/release/examples/bench_case (build it first): the best wall time
    of `hd_model::simulate` without a trace, with the method `auto` picks."""
    check_equations()
    t, ref, amp, dev = reference()
    log(f"reference: NumbaLSODA DOP853 rtol 1e-13 on the Python equations; hd-model at rtol "
        f"1e-12 agrees with it to {dev:.1e} of the amplitude (limit {RHS_CHECK:g}) — RHS check "
        f"passed")
    log(f"θz amplitude (hd-model thz_amp over the last 5 cycles): {amp:.6e} rad")
    row = sn.pack(sn.SEED)
    sn.solve(row, T_END, N_SAMPLES, rtol=1e-6)  # compile before timing

    start = t <= START_UP

    def errs(thz):
        """Error ÷ amplitude: over the run, over the start-up and after it; time of the max."""
        e = np.abs(np.asarray(thz) - ref) / amp
        return dict(err=float(e.max()), err_start=float(e[start].max()),
                    err_rest=float(e[~start].max()), t_max=float(t[int(e.argmax())]))

    res = {"hdw": [], "NumbaLSODA": [], "scipy LSODA": []}
    for af in atol_factors:
        for rtol in rtols:
            d = sc.run_rust("full", rtol, rtol * af, T_END, reps_hdw, DT_OUT, build=False)
            res["hdw"].append(dict(rtol=rtol, atol_factor=af, wall=d["wall_best_s"],
                                   **errs(d["theta_z"]), steps=d["steps"], method=d["method"]))
            wall, (_, thz, ok) = best_of(
                lambda: sn.solve(row, T_END, N_SAMPLES, rtol=rtol, atol=rtol * af), reps_numba)
            if not ok:
                raise RuntimeError(f"NumbaLSODA failed at rtol {rtol:g}, atol {rtol * af:g}")
            res["NumbaLSODA"].append(dict(rtol=rtol, atol_factor=af, wall=wall, **errs(thz)))
            wall, thz = best_of(lambda: scipy_lsoda(rtol, t, af), reps_scipy)
            res["scipy LSODA"].append(dict(rtol=rtol, atol_factor=af, wall=wall, **errs(thz)))
            log(f"  rtol {rtol:g}, atol rtol·{af:g}: hdw {ms(res['hdw'][-1]['wall'])}, "
                f"NumbaLSODA {ms(res['NumbaLSODA'][-1]['wall'])}, scipy {ms(wall)}")
    peak = float(np.max(np.abs(ref[start])) / amp)
    return dict(amp=amp, rhs_check=dev, start_peak=peak, runs=res)


def report(out: dict, targets=(1e-6, 1e-4), log=print) -> dict:
    """Print the work–precision table and the ratios at equal error; returns the summary."""
    res = out["runs"]
    names = list(res)
    log("\nwork–precision, seed case (full model, 24 V 50 Hz, 1 s; atol = rtol·factor, θ: "
        "atol/(c+A)); cells: best wall / error÷amplitude")
    log(f"{'rtol':>7} {'atol/rtol':>9} | " + " | ".join(f"{n:>22}" for n in names))
    for k, p0 in enumerate(res["hdw"]):
        cells = []
        for n in names:
            p = res[n][k]
            cells.append(f"{ms(p['wall']):>10} / {p['err']:9.2e}")
        log(f"{p0['rtol']:7.0e} {p0['atol_factor']:9.0e} | " + " | ".join(f"{c:>22}" for c in cells))
    steps = ", ".join(f"{p['rtol']:.0e}·{p['atol_factor']:.0e}: {p['steps']} ({p['method']})"
                      for p in res["hdw"])
    log(f"hdw steps (method): {steps}")
    log(f"\nwhere the error is: the start from rest (t ≤ {START_UP:g} s) swings θz to "
        f"{out['start_peak']:.1f}× the steady amplitude; max error ÷ amplitude over the "
        f"start-up / after it, and the time of the largest")
    for n in names:
        cells = ", ".join(f"{p['rtol']:.0e}·{p['atol_factor']:.0e}: {p['err_start']:.1e} / "
                          f"{p['err_rest']:.1e} "
                          f"@{p['t_max']:.3f} s" for p in res[n])
        log(f"  {n:12s} {cells}")
    summary = {}
    for target in targets:
        log(f"\nat error ≤ {target:g} of the amplitude (cheapest run meeting it; log–log "
            f"interpolation in brackets):")
        row = {}
        for n in names:
            cheap, interp = at_error(res[n], target)
            row[n] = dict(cheapest=cheap, interp=interp)
            c = ("none meets it" if cheap is None
                 else f"{ms(cheap[0])} (rtol {cheap[1]:.0e}, atol rtol·{cheap[2]:.0e})")
            log(f"  {n:12s} {c:28s} [{ms(interp)}]")
        h = row["hdw"]["cheapest"]
        for n in names[1:]:
            o = row[n]["cheapest"]
            if h and o:
                hi, oi = row["hdw"]["interp"], row[n]["interp"]
                ri = f"{oi / hi:.1f}×" if hi and oi else "—"
                log(f"  {n} / hdw = {o[0] / h[0]:.1f}× (interpolated {ri})")
                row[n]["ratio"] = o[0] / h[0]
        summary[target] = row
    return summary
