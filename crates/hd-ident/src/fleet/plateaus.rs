//! The steady-state friction map of a joint test run as speed plateaus (the test a rig
//! runs every shift: hold a few speeds each way, read the torque): each plateau gives one
//! point, its mean speed and mean torque once the bristles have settled, and the static
//! LuGre stage (`T(ω) = sign(ω)·(Tc + (Ts − Tc)·e^{−(ω/ωs)²}) + σ2·ω`, the law's own
//! [`SteadyProblem`]) is fitted to those points. A 10 s log at 1 kHz reduces to about 16
//! points, so the fit costs about a millisecond, not the 0.1 s of the transient fit over
//! every sample, and its standard errors come from the scatter of the points about the
//! curve (Student's t on n − 4 degrees of freedom).

use super::FleetError;
use crate::data::SteadyData;
use crate::fix::Fixed;
use crate::friction::{SteadyOptions, SteadyProblem};
use crate::report::FitReport;
use crate::separable::fit_separable;

/// How plateaus are found in a time series.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlateauOptions {
    /// Largest relative deviation of a sample's speed from its plateau's speed [–].
    pub tolerance: f64,
    /// Shortest plateau [s].
    pub min_duration: f64,
    /// Share of each plateau dropped at its start, while the bristles settle [–].
    pub settle: f64,
    /// Slowest plateau speed counted [rad/s] (below it the contact may still stick).
    pub min_speed: f64,
    /// Separate levels for negative speeds (Tc_neg, Ts_neg).
    pub asymmetric: bool,
    /// A constant torque offset of the measurement.
    pub offset: bool,
}

impl Default for PlateauOptions {
    fn default() -> Self {
        Self {
            tolerance: 0.02,
            min_duration: 0.1,
            settle: 0.3,
            min_speed: 1e-9,
            asymmetric: false,
            offset: false,
        }
    }
}

/// One plateau: where it is and what it measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plateau {
    /// First and one-past-last sample used (after the settling share).
    pub range: (usize, usize),
    /// Mean speed [rad/s].
    pub omega: f64,
    /// Mean torque [N·m].
    pub torque: f64,
    /// Standard error of the mean torque (white-noise formula) [N·m].
    pub se: f64,
}

/// The plateaus of a time series `t` [s], `omega` [rad/s], `torque` [N·m], in time order.
pub fn find_plateaus(t: &[f64], omega: &[f64], torque: &[f64], o: &PlateauOptions) -> Vec<Plateau> {
    let n = t.len().min(omega.len()).min(torque.len());
    let mut out = Vec::new();
    let mut i = 0;
    while i < n {
        let w0 = omega[i];
        if w0.abs() < o.min_speed || w0.is_nan() {
            i += 1;
            continue;
        }
        // Grow the run while the speed stays within the tolerance of its running mean.
        let (mut j, mut sum) = (i + 1, w0);
        while j < n {
            let mean = sum / (j - i) as f64;
            if (omega[j] - mean).abs() > o.tolerance * mean.abs() {
                break;
            }
            sum += omega[j];
            j += 1;
        }
        if t[j - 1] - t[i] >= o.min_duration && j - i >= 8 {
            let a = i + ((j - i) as f64 * o.settle).ceil() as usize;
            let m = (j - a) as f64;
            let w = omega[a..j].iter().sum::<f64>() / m;
            let y = torque[a..j].iter().sum::<f64>() / m;
            let var = torque[a..j].iter().map(|v| (v - y) * (v - y)).sum::<f64>() / (m - 1.0);
            out.push(Plateau { range: (a, j), omega: w, torque: y, se: (var / m).sqrt() });
            i = j;
        } else {
            i += 1;
        }
    }
    out
}

/// A plateau fit: the report of the static stage on the plateau points, and the points.
#[derive(Clone, Debug, PartialEq)]
pub struct PlateauFit {
    /// The fit's report (parameters Tc, Ts, ws, sigma2 …, with standard errors).
    pub report: FitReport,
    /// The plateau points fitted.
    pub plateaus: Vec<Plateau>,
    /// RMS residual of the plateau means over their RMS standard error [–]: about 1 when
    /// the steady law explains the points down to their noise.
    pub resid_over_noise: f64,
}

/// Fit the static friction law to the plateaus of a time series.
pub fn fit_plateaus(
    t: &[f64],
    omega: &[f64],
    torque: &[f64],
    o: &PlateauOptions,
    fixed: &Fixed,
) -> Result<PlateauFit, FleetError> {
    let plateaus = find_plateaus(t, omega, torque, o);
    let params = 4 + 2 * usize::from(o.asymmetric) + usize::from(o.offset);
    if plateaus.len() < params + 2 {
        return Err(FleetError::Plateaus(format!(
            "found {} speed plateaus (speed within {} % for at least {} s), need at least {} to fit {} parameters: is this a plateau friction test?",
            plateaus.len(),
            100.0 * o.tolerance,
            o.min_duration,
            params + 2,
            params
        )));
    }
    let w: Vec<f64> = plateaus.iter().map(|p| p.omega).collect();
    let y: Vec<f64> = plateaus.iter().map(|p| p.torque).collect();
    let data = SteadyData::new(w, y).map_err(|e| FleetError::Fit(e.into()))?;
    let problem = SteadyProblem::with_options(
        &data,
        SteadyOptions { asymmetric: o.asymmetric, offset: o.offset },
    );
    let fit = fit_separable(&problem, fixed).map_err(FleetError::Fit)?;
    let k = plateaus.len() as f64;
    let rms_se = (plateaus.iter().map(|p| p.se * p.se).sum::<f64>() / k).sqrt();
    let rms_res = (fit.residuals.iter().map(|r| r * r).sum::<f64>() / k).sqrt();
    let mut report = fit.report;
    report.fit = "friction-plateaus".into();
    report.remarks.push(format!(
        "{} plateaus: mean speed and torque after the first {:.0} % of each",
        plateaus.len(),
        100.0 * o.settle
    ));
    Ok(PlateauFit { report, plateaus, resid_over_noise: rms_res / rms_se })
}

#[cfg(test)]
mod tests {
    use super::*;
    use hd_model::laws::friction::{FrictionLaw, LuGre};

    /// Exact steady torques on plateaus (no bristle transients), with white noise from a
    /// fixed linear congruential stream: the fit must return the law within its errors.
    #[test]
    fn the_steady_law_comes_back_from_noisy_plateaus() {
        let law = LuGre::symmetric(1e5, 1.0, 0.05, 0.15, 0.25, 0.01);
        let dt = 1e-3;
        let levels: Vec<f64> =
            (0..8).flat_map(|k| [1e-3 * 10f64.powf(k as f64 * 3.0 / 7.0); 2]).collect();
        let (mut t, mut w, mut y) = (Vec::new(), Vec::new(), Vec::new());
        let mut seed: u64 = 7;
        let mut gauss = || {
            let mut s = 0.0;
            for _ in 0..12 {
                seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                s += (seed >> 11) as f64 / (1u64 << 53) as f64;
            }
            s - 6.0
        };
        for (k, v) in levels.iter().enumerate() {
            let v = if k % 2 == 0 { *v } else { -*v };
            for _ in 0..500 {
                t.push(t.len() as f64 * dt);
                w.push(v);
                y.push(law.steady_torque(v) + 2e-3 * gauss());
            }
            for s in 0..50 {
                t.push(t.len() as f64 * dt);
                w.push(v * (1.0 - s as f64 / 50.0) * 0.5);
                y.push(0.0);
            }
        }
        let fit = fit_plateaus(&t, &w, &y, &PlateauOptions::default(), &Fixed::none()).unwrap();
        assert_eq!(fit.plateaus.len(), 16);
        for (name, truth) in [("Tc", 0.15), ("Ts", 0.25), ("ws", 0.01), ("sigma2", 0.05)] {
            let e = fit.report.parameters.get(name).unwrap();
            let se = e.std_error.unwrap();
            assert!((e.value - truth).abs() < 4.0 * se, "{name}: {} ± {se} vs {truth}", e.value);
            assert!(se < 0.05 * truth, "{name}: se {se}");
        }
        assert!(
            fit.resid_over_noise > 0.3 && fit.resid_over_noise < 3.0,
            "{}",
            fit.resid_over_noise
        );
    }

    #[test]
    fn a_record_without_plateaus_is_refused_with_the_reason() {
        let t: Vec<f64> = (0..1000).map(|k| k as f64 * 1e-3).collect();
        let w: Vec<f64> = t.iter().map(|t| (10.0 * t).sin()).collect();
        let e = fit_plateaus(&t, &w, &w, &PlateauOptions::default(), &Fixed::none()).unwrap_err();
        assert!(e.to_string().contains("speed plateaus"), "{e}");
    }
}
