//! A second LuGre law on the load (the `*_load` parameters, docs/model.md §2.6), beside the
//! gear's own: the steady speed under a held voltage is the root of the torque balance
//! written out here, a load held by a level above the stall torque never slides, and a law
//! that is incomplete or doubles the gear's is refused, named.

use hd_model::laws::input::Input;
use hd_model::solver::SolverOptions;
use hd_model::state::*;
use hd_model::system::FrictionVelocity;
use hd_model::{Params, SimConfig, simulate};

/// The seed drive with a load-side law (Tc_load = 3, Ts_load = 4 N·m, ωs = 0.05 rad/s,
/// σ2_load = 0.5 N·m·s/rad) and a load torque TL = 1 N·m.
fn with_load_law() -> Params {
    Params {
        tc_load: 3.0,
        ts_load: 4.0,
        ws_load: 0.05,
        sigma0_load: 5e4,
        sigma1_load: 20.0,
        sigma2_load: 0.5,
        tl: 1.0,
        ..Params::default()
    }
}

/// Written out on its own: sign(v)·(Tc + (Ts − Tc)·exp(−(v/ωs)²)) + σ2·v.
fn stribeck(v: f64, tc: f64, ts: f64, ws: f64, s2: f64) -> f64 {
    v.signum() * (tc + (ts - tc) * (-(v / ws).powi(2)).exp()) + s2 * v
}

/// The steady load speed of `p` under a held voltage `u` [V] (the end of a 3 s run at rtol
/// 1e-10), the root of the torque balance with the load-side levels `(tc, ts)` of the
/// direction it runs in, and its load-side bristle torque.
fn steady_against_balance(p: &Params, u: f64, tc: f64, ts: f64) -> (f64, f64, f64) {
    // At a steady speed ωz the gear is still (θ̇ = 0, so z = 0 and ωj = N·ωz), each bristle
    // sits at its Stribeck level, and the gear carries what the load side takes:
    // Tb = Cz·ωz + TL + Tf_load(ωz); the motor's balance is then
    // Km·(u − Ke·N·ωz)/R − Cj·N·ωz − (Tb + Tf(ωz))/N = 0.
    let balance = |wz: f64| {
        let tb = p.cz * wz + p.tl + stribeck(wz, tc, ts, p.ws_load, p.sigma2_load);
        let tf = stribeck(wz, p.tc, p.ts, p.ws, p.sigma2);
        p.km * (u - p.ke * p.n * wz) / p.r - p.cj * p.n * wz - (tb + tf) / p.n
    };
    let free_run = u / (p.ke * p.n);
    let (mut lo, mut hi) = if u > 0.0 { (1e-6, free_run) } else { (free_run, -1e-6) };
    assert!(balance(lo) > 0.0 && balance(hi) < 0.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if balance(mid) > 0.0 { lo = mid } else { hi = mid }
    }
    let expected = 0.5 * (lo + hi);
    let cfg = SimConfig {
        params: p.clone(),
        input: Input::Constant { amplitude: u },
        t_end: 3.0,
        record_trace: false,
        solver: SolverOptions { rtol: 1e-10, atol: 1e-12, ..Default::default() },
        ..SimConfig::default()
    };
    let y = simulate(&cfg).unwrap().final_state;
    (y[OMEGA_Z], expected, y[W_LOAD])
}

#[test]
fn steady_speed_is_the_root_of_the_torque_balance() {
    let (wz, expected, w_l) = steady_against_balance(&with_load_law(), 24.0, 3.0, 4.0);
    let rel = (wz - expected).abs() / expected;
    eprintln!("steady load speed {wz:.9} rad/s against {expected:.9} ({rel:.1e} off)");
    // Measured 1.3e-16.
    assert!(rel < 2e-15, "ωz = {wz}, expected {expected}");
    // The load-side bristle sits at its level: w_L = G_L(ωz).
    let level = stribeck(expected, 3.0, 4.0, 0.05, 0.0);
    assert!((w_l - level).abs() < 1e-9 * level, "w_L = {w_l}, level {level}");
}

/// A direction-dependent load-side law (`Tc_neg_load`, `Ts_neg_load`): run backwards the
/// load settles where the negative side's levels balance the drive, run forwards where the
/// positive side's do (the negative ones play no part there).
#[test]
fn a_direction_dependent_load_law_takes_each_sides_levels() {
    let p = Params { tc_neg_load: Some(1.5), ts_neg_load: Some(2.5), tl: 0.0, ..with_load_law() };
    for (u, tc, ts) in [(-24.0, 1.5, 2.5), (24.0, 3.0, 4.0)] {
        let (wz, expected, w_l) = steady_against_balance(&p, u, tc, ts);
        let rel = (wz - expected).abs() / expected.abs();
        eprintln!("u = {u} V: load speed {wz:.9} rad/s against {expected:.9} ({rel:.1e} off)");
        assert!(rel < 2e-15, "u = {u}: ωz = {wz}, expected {expected}");
        let level = stribeck(expected, tc, ts, 0.05, 0.0);
        assert!((w_l - level).abs() < 1e-9 * level.abs(), "w_L = {w_l}, level {level}");
    }
    // The same speeds differ from the symmetric law's backwards: the levels are used.
    let (sym, _, _) =
        steady_against_balance(&Params { tl: 0.0, ..with_load_law() }, -24.0, 3.0, 4.0);
    let (dir, _, _) = steady_against_balance(&p, -24.0, 1.5, 2.5);
    assert!(dir < sym, "lower levels backwards let the load run faster: {dir} vs {sym}");
}

#[test]
fn a_load_held_above_the_stall_torque_never_breaks_away() {
    // Stall torque at the load: N·Km·u/R = 208 N·m. With both levels at 500 N·m the load
    // never breaks away: once the transient has rung out it stands still, the gear's torque
    // held by the load-side bristle alone (Jz·ω̇z = Tb − w_L − σ1_L·ṡ_L − … with every
    // speed zero), far below its level.
    let p = Params { tc_load: 500.0, ts_load: 500.0, sigma1_load: 2e3, tl: 0.0, ..with_load_law() };
    let stall = p.n * p.km * 24.0 / p.r;
    let settled = |t_end: f64| {
        let cfg = SimConfig {
            params: p.clone(),
            input: Input::Constant { amplitude: 24.0 },
            t_end,
            record_trace: false,
            solver: SolverOptions { rtol: 1e-10, atol: 1e-12, ..Default::default() },
            ..SimConfig::default()
        };
        let sys = cfg.system().unwrap();
        let y = simulate(&cfg).unwrap().final_state;
        (sys.theta_z(&y), y[W_LOAD], sys.stiffness.eval(y[THETA], 0.0, y[Z], &[]).torque)
    };
    let (thz1, w1, tb1) = settled(1.0);
    let (thz2, w2, tb2) = settled(2.0);
    let drift = (thz2 - thz1).abs();
    eprintln!(
        "held load: θz {thz2:.6e} rad, drift over the last second {drift:.1e} rad; Tb {tb2:.4} N·m, w_L {w2:.4} N·m (stall {stall:.1})"
    );
    // Sliding at the free speed would move it ~0.4 rad in that second. Measured: drift
    // 6.7e-11 rad (1.3e-8 of θz, the transient's tail), Tb = w_L to the digits printed.
    assert!(thz2.abs() > 1e-4 && drift < 1.5e-7 * thz2.abs(), "drift {drift:e} rad");
    for (tb, w) in [(tb1, w1), (tb2, w2)] {
        assert!((tb - w).abs() < 1e-6 * tb.abs() && tb.abs() < 500.0, "Tb {tb}, w_L {w}");
    }
}

#[test]
fn an_incomplete_or_doubled_load_law_is_refused_by_name() {
    let run = |p: Params, fv: FrictionVelocity| {
        let cfg = SimConfig { params: p, friction_velocity: fv, ..SimConfig::default() };
        cfg.system().map(|_| ()).map_err(|e| e.to_string())
    };
    let e = run(Params { sigma0_load: 0.0, ..with_load_law() }, FrictionVelocity::Motor);
    assert!(e.as_ref().is_err_and(|m| m.starts_with("sigma0_load = 0")), "{e:?}");
    let e = run(Params { ws_load: 0.0, ..with_load_law() }, FrictionVelocity::Motor);
    assert!(e.as_ref().is_err_and(|m| m.starts_with("ws_load = 0")), "{e:?}");
    let e = run(with_load_law(), FrictionVelocity::Load);
    assert!(e.as_ref().is_err_and(|m| m.contains("friction_velocity")), "{e:?}");
    assert!(run(with_load_law(), FrictionVelocity::Deflection).is_ok());
    // Without levels the other load-side values are inert.
    assert!(run(Params { sigma0_load: 1.0, ..Params::default() }, FrictionVelocity::Load).is_ok());
}
