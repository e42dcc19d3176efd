//! Synthetic friction data: a steady-state sweep from [`LuGre::steady_torque`], and a time
//! series in which an imposed speed drives the LuGre law, its bristle state integrated by
//! hd-model's Rodas4.

use super::Synthetic;
use super::excitation::{GrowingSine, PlateauProfile};
use super::noise::{Noise, add_noise};
use crate::error::FitError;
use crate::path::{BristleAlong, Signal, state_at_samples};
use hd_model::Params;
use hd_model::laws::friction::{FrictionLaw, LuGre};
use hd_model::solver::{Method, SolverOptions};

fn setting(field: &'static str, value: impl ToString, expected: &str) -> FitError {
    FitError::Setting { field, value: value.to_string(), expected: expected.to_string() }
}

fn lugre(p: &Params) -> LuGre {
    LuGre::from_params(p)
}

/// The imposed speed at the times `t` and the LuGre torque along it, the bristle state
/// integrated from rest by hd-model's Rodas4 at tight tolerances; `what` names the speed
/// in an error.
fn torque_along<S: Signal>(
    law: &LuGre,
    speed: &S,
    t: &[f64],
    what: &str,
) -> Result<(Vec<f64>, Vec<f64>), FitError> {
    let sys = BristleAlong { law: *law, speed };
    let opts =
        SolverOptions { method: Method::Rodas4, rtol: 1e-10, atol: 1e-10, ..Default::default() };
    let w = state_at_samples(&sys, t, 0.0, &opts).map_err(|source| FitError::Solver {
        what: format!("the LuGre bristle state along {what}"),
        source,
    })?;
    Ok(t.iter()
        .zip(&w)
        .map(|(&ti, &wi)| {
            let v = speed.at(ti)[0];
            (v, law.eval(v, wi).torque)
        })
        .unzip())
}

/// A steady-state sweep: log-spaced speeds of both signs.
#[derive(Clone, Debug, PartialEq)]
pub struct SteadySweep {
    /// Slowest |ω| [rad/s]; default 1e-4.
    pub omega_min: f64,
    /// Fastest |ω| [rad/s]; default 1.
    pub omega_max: f64,
    /// Speeds per sign; default 50 (100 rows).
    pub points_per_sign: usize,
}

impl Default for SteadySweep {
    fn default() -> Self {
        Self { omega_min: 1e-4, omega_max: 1.0, points_per_sign: 50 }
    }
}

/// Columns `omega, torque`: the steady LuGre torque at the sweep's speeds (negative ones
/// first, in increasing order), plus noise.
pub fn synth_steady(p: &Params, sweep: &SteadySweep, noise: &Noise) -> Result<Synthetic, FitError> {
    p.validate()?;
    if !(sweep.omega_min > 0.0 && sweep.omega_max > sweep.omega_min && sweep.omega_max.is_finite())
    {
        return Err(setting(
            "omega range",
            format!("[{}, {}]", sweep.omega_min, sweep.omega_max),
            "0 < omega_min < omega_max [rad/s]",
        ));
    }
    if sweep.points_per_sign < 2 {
        return Err(setting("points per sign", sweep.points_per_sign, "at least 2"));
    }
    let m = sweep.points_per_sign;
    let ratio = (sweep.omega_max / sweep.omega_min).ln() / (m - 1) as f64;
    let speeds: Vec<f64> = (0..m).map(|k| sweep.omega_min * (ratio * k as f64).exp()).collect();
    let omega: Vec<f64> = speeds.iter().rev().map(|w| -w).chain(speeds.iter().copied()).collect();
    let law = lugre(p);
    let mut torque: Vec<f64> = omega.iter().map(|&w| law.steady_torque(w)).collect();
    let sd = add_noise(&mut torque, noise);
    let description = format!(
        "friction steady-state sweep: {m} log-spaced speeds per sign, |omega| from {:e} to {:e} rad/s; \
         Tc={:e}, Ts={:e}, ws={:e}, sigma2={:e}; Gaussian noise {} x RMS torque = {:.4e} N·m (seed {})",
        sweep.omega_min,
        sweep.omega_max,
        p.tc,
        p.ts,
        p.ws,
        p.sigma2,
        noise.relative,
        sd,
        noise.seed
    );
    Ok(Synthetic {
        names: vec!["omega", "torque"],
        columns: vec![omega, torque],
        noise_std: sd,
        description,
    })
}

/// The imposed speed of a transient friction experiment: a sine through zero whose
/// amplitude grows geometrically (see [`GrowingSine`]), so that the record holds pure
/// pre-sliding cycles early on, then partial slip, then full sliding reversals.
#[derive(Clone, Debug, PartialEq)]
pub struct TransientExcitation {
    /// Final speed amplitude [rad/s]; default 2.
    pub peak_speed: f64,
    /// Frequency [Hz]; default 200.
    pub frequency: f64,
    /// Whole cycles; default 6.
    pub cycles: usize,
    /// Decades of amplitude growth over the record; default 3.
    pub decades: f64,
    /// Samples per cycle (uniform sampling); default 2500.
    pub samples_per_cycle: usize,
}

impl Default for TransientExcitation {
    fn default() -> Self {
        Self { peak_speed: 2.0, frequency: 200.0, cycles: 6, decades: 3.0, samples_per_cycle: 2500 }
    }
}

/// Columns `t, omega, torque`: the LuGre torque along the imposed speed, the bristle
/// state starting at rest (w = 0 at t = 0, where ω = 0), plus noise.
pub fn synth_transient(
    p: &Params,
    exc: &TransientExcitation,
    noise: &Noise,
) -> Result<Synthetic, FitError> {
    p.validate()?;
    if !(exc.peak_speed > 0.0 && exc.peak_speed.is_finite()) {
        return Err(setting("peak speed", exc.peak_speed, "a finite value > 0 [rad/s]"));
    }
    if !(exc.frequency > 0.0 && exc.frequency.is_finite()) {
        return Err(setting("frequency", exc.frequency, "a finite value > 0 [Hz]"));
    }
    if !(exc.decades >= 0.0 && exc.decades.is_finite()) {
        return Err(setting("decades", exc.decades, "a finite value >= 0"));
    }
    if exc.cycles == 0 || exc.samples_per_cycle < 4 {
        return Err(setting(
            "cycles x samples per cycle",
            format!("{} x {}", exc.cycles, exc.samples_per_cycle),
            "at least 1 cycle of at least 4 samples",
        ));
    }
    let duration = exc.cycles as f64 / exc.frequency;
    let signal = GrowingSine {
        peak: exc.peak_speed,
        frequency: exc.frequency,
        decades: exc.decades,
        duration,
    };
    let n = exc.cycles * exc.samples_per_cycle + 1;
    let dt = duration / (n - 1) as f64;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
    let law = lugre(p);
    let (omega, mut torque) = torque_along(&law, &signal, &t, "the imposed speed")?;
    let sd = add_noise(&mut torque, noise);
    let description = format!(
        "friction time series: omega(t) = sine at {} Hz through zero, amplitude growing over {} decades to {:e} rad/s, \
         {} cycles, {} samples/cycle ({} rows); sigma0={:e}, sigma1={:e}, sigma2={:e}, Tc={:e}, Ts={:e}, ws={:e}; \
         Gaussian noise {} x RMS torque = {:.4e} N·m (seed {})",
        exc.frequency,
        exc.decades,
        exc.peak_speed,
        exc.cycles,
        exc.samples_per_cycle,
        n,
        p.sigma0,
        p.sigma1,
        p.sigma2,
        p.tc,
        p.ts,
        p.ws,
        noise.relative,
        sd,
        noise.seed
    );
    Ok(Synthetic {
        names: vec!["t", "omega", "torque"],
        columns: vec![t, omega, torque],
        noise_std: sd,
        description,
    })
}

/// Columns `t, omega, torque` of a joint friction test ([`PlateauProfile`]) sampled
/// every `dt` [s]: the LuGre torque along the imposed speed from rest, plus noise.
pub fn synth_plateaus(
    p: &Params,
    profile: &PlateauProfile,
    dt: f64,
    noise: &Noise,
) -> Result<Synthetic, FitError> {
    p.validate()?;
    let ok = |v: f64| v > 0.0 && v.is_finite();
    if !(ok(profile.omega_min) && profile.omega_max >= profile.omega_min && ok(profile.omega_max)) {
        return Err(setting(
            "speed range",
            format!("[{}, {}]", profile.omega_min, profile.omega_max),
            "0 < omega_min <= omega_max [rad/s]",
        ));
    }
    if !(ok(profile.dwell) && ok(profile.transition) && profile.levels >= 1) {
        return Err(setting(
            "levels x dwell x transition",
            format!("{} x {} x {}", profile.levels, profile.dwell, profile.transition),
            "at least 1 level, dwell and transition > 0 [s]",
        ));
    }
    let duration = profile.duration();
    if !(ok(dt) && dt < profile.transition / 4.0) {
        return Err(setting(
            "sample interval",
            dt,
            "a value > 0 and below a quarter of the transition [s]",
        ));
    }
    let n = (duration / dt).floor() as usize + 1;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
    let law = LuGre::from_params(p);
    let (omega, mut torque) = torque_along(&law, profile, &t, "the joint-test profile")?;
    let sd = add_noise(&mut torque, noise);
    let description = format!(
        "friction joint test: {} speed levels from {:e} to {:e} rad/s, each held {} s forwards then backwards, \
         raised-cosine transitions of {} s, sampled every {} s ({} rows); sigma0={:e}, sigma1={:e}, sigma2={:e}, \
         Tc={:e}, Ts={:e}, ws={:e}, Tc_neg={:e}, Ts_neg={:e}; Gaussian noise {} x RMS torque = {:.4e} N·m (seed {})",
        profile.levels,
        profile.omega_min,
        profile.omega_max,
        profile.dwell,
        profile.transition,
        dt,
        n,
        p.sigma0,
        p.sigma1,
        p.sigma2,
        p.tc,
        p.ts,
        p.ws,
        law.tc_neg,
        law.ts_neg,
        noise.relative,
        sd,
        noise.seed
    );
    Ok(Synthetic {
        names: vec!["t", "omega", "torque"],
        columns: vec![t, omega, torque],
        noise_std: sd,
        description,
    })
}
