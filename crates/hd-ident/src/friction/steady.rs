//! The static friction stage: `T(ω) = sign(ω)·(Tc + (Ts − Tc)·e^{−(ω/ωs)²}) + σ2·ω`,
//! linear in Tc, Ts and σ2 for a given ωs; ωs comes from the global search over ln ωs.
//! Columns and prediction are [`LuGre::steady_torque`] itself.

use crate::data::SteadyData;
use crate::error::FitError;
use crate::report::Explanation;
use crate::separable::{Basis, Separable};
use hd_model::laws::friction::{FrictionLaw, LoadFactors, LuGre};

/// Parameters of the static stage, in report order.
pub const STATIC_PARAMS: [&str; 4] = ["Tc", "Ts", "sigma2", "ws"];

/// Search range of ωs relative to the measured speeds: from a tenth of the slowest to ten
/// times the fastest |ω| (outside, the Stribeck drop is entirely above or below the data).
pub const WS_RANGE_FACTOR: f64 = 10.0;

/// Load factors fitted with a transmitted-torque column, in report order.
pub const LOAD_PARAMS: [&str; 4] = ["mu_c_fwd", "mu_s_fwd", "mu_c_back", "mu_s_back"];

/// A LuGre law with only the static parameters set (the others do not affect the steady
/// torque): levels `[Tc, Ts, Tc_neg, Ts_neg]`, load factors `mu`.
fn static_law(levels: [f64; 4], sigma2: f64, ws: f64, mu: [f64; 4]) -> LuGre {
    let [tc, ts, tc_neg, ts_neg] = levels;
    LuGre {
        sigma0: 1.0,
        sigma1: 0.0,
        sigma2,
        tc,
        ts,
        ws,
        tc_neg,
        ts_neg,
        mu: LoadFactors { c_fwd: mu[0], s_fwd: mu[1], c_back: mu[2], s_back: mu[3] },
    }
}

/// Optional terms of the static fit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SteadyOptions {
    /// Separate levels `Tc_neg`, `Ts_neg` for negative speeds.
    pub asymmetric: bool,
    /// A constant torque offset of the measurement.
    pub offset: bool,
}

/// The static friction problem on one steady-state sweep.
pub struct SteadyProblem<'a> {
    data: &'a SteadyData,
    speed_range: (f64, f64),
    opts: SteadyOptions,
}

impl<'a> SteadyProblem<'a> {
    /// Set up the symmetric problem without offset on `data`.
    pub fn new(data: &'a SteadyData) -> Self {
        Self::with_options(data, SteadyOptions::default())
    }

    /// Set up the problem on `data` with the optional terms of `opts`.
    pub fn with_options(data: &'a SteadyData, opts: SteadyOptions) -> Self {
        let speeds = data.omega().iter().map(|w| w.abs());
        let (lo, hi) = speeds.fold((f64::INFINITY, 0.0f64), |(l, h), w| (l.min(w), h.max(w)));
        Self { data, speed_range: (lo, hi), opts }
    }

    fn curve(&self, law: &LuGre) -> Vec<f64> {
        let w = self.data.omega().iter();
        match self.data.load() {
            Some(tb) => w.zip(tb).map(|(&w, &tb)| law.steady_torque_loaded(w, tb)).collect(),
            None => w.map(|&w| law.steady_torque(w)).collect(),
        }
    }

    /// Number of level and σ2/offset parameters before the load factors.
    fn base_count(&self) -> usize {
        (if self.opts.asymmetric { 5 } else { 3 }) + usize::from(self.opts.offset)
    }

    /// The law of linear parameters `beta` and Stribeck speed `q`, and the offset.
    fn law_of(&self, beta: &[f64], q: f64) -> (LuGre, f64) {
        let k = if self.opts.asymmetric { 4 } else { 2 };
        let offset = if self.opts.offset { beta[k + 1] } else { 0.0 };
        let b = self.base_count();
        let mu = if self.data.load().is_some() {
            [beta[b], beta[b + 1], beta[b + 2], beta[b + 3]]
        } else {
            [0.0; 4]
        };
        (static_law(self.levels(beta), beta[k], q, mu), offset)
    }

    /// Levels `[Tc, Ts, Tc_neg, Ts_neg]` from the linear parameters `beta`.
    fn levels(&self, beta: &[f64]) -> [f64; 4] {
        if self.opts.asymmetric {
            [beta[0], beta[1], beta[2], beta[3]]
        } else {
            [beta[0], beta[1], beta[0], beta[1]]
        }
    }
}

impl Separable for SteadyProblem<'_> {
    fn fit_name(&self) -> &'static str {
        "friction-static"
    }
    fn linear_names(&self) -> &'static [&'static str] {
        const MU: [&str; 4] = LOAD_PARAMS;
        let load = self.data.load().is_some();
        match (self.opts.asymmetric, self.opts.offset, load) {
            (false, false, false) => &["Tc", "Ts", "sigma2"],
            (false, true, false) => &["Tc", "Ts", "sigma2", "offset"],
            (true, false, false) => &["Tc", "Ts", "Tc_neg", "Ts_neg", "sigma2"],
            (true, true, false) => &["Tc", "Ts", "Tc_neg", "Ts_neg", "sigma2", "offset"],
            (false, false, true) => &["Tc", "Ts", "sigma2", MU[0], MU[1], MU[2], MU[3]],
            (false, true, true) => &["Tc", "Ts", "sigma2", "offset", MU[0], MU[1], MU[2], MU[3]],
            (true, false, true) => {
                &["Tc", "Ts", "Tc_neg", "Ts_neg", "sigma2", MU[0], MU[1], MU[2], MU[3]]
            }
            (true, true, true) => {
                &["Tc", "Ts", "Tc_neg", "Ts_neg", "sigma2", "offset", MU[0], MU[1], MU[2], MU[3]]
            }
        }
    }
    fn nonlinear_name(&self) -> &'static str {
        "ws"
    }
    fn search_range(&self) -> (f64, f64) {
        (self.speed_range.0 / WS_RANGE_FACTOR, self.speed_range.1 * WS_RANGE_FACTOR)
    }
    fn measured(&self) -> &[f64] {
        self.data.torque()
    }
    fn basis(&self, q: f64) -> Result<Basis, FitError> {
        let unit_levels: Vec<[f64; 4]> = if self.opts.asymmetric {
            vec![
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
                [0.0, 0.0, 0.0, 1.0],
            ]
        } else {
            vec![[1.0, 0.0, 1.0, 0.0], [0.0, 1.0, 0.0, 1.0]]
        };
        let mut columns: Vec<Vec<f64>> =
            unit_levels.into_iter().map(|l| self.curve(&static_law(l, 0.0, q, [0.0; 4]))).collect();
        columns.push(self.curve(&static_law([0.0; 4], 1.0, q, [0.0; 4])));
        if self.opts.offset {
            columns.push(vec![1.0; self.data.len()]);
        }
        if self.data.load().is_some() {
            // The steady torque is linear in each factor: a unit factor alone gives its column.
            for k in 0..4 {
                let mut mu = [0.0; 4];
                mu[k] = 1.0;
                columns.push(self.curve(&static_law([0.0; 4], 0.0, q, mu)));
            }
        }
        Ok(Basis { columns, offset: None })
    }
    fn predict(&self, beta: &[f64], q: f64) -> Result<Vec<f64>, FitError> {
        let (law, offset) = self.law_of(beta, q);
        Ok(self.curve(&law).into_iter().map(|v| v + offset).collect())
    }
    /// The steady torque sign(ω)·G(ω/ωs) + σ2·ω depends on ωs through ω/ωs only, so
    /// ∂T/∂ωs = −(|ω|/ωs)·∂G/∂ω, with ∂G/∂ω the law's own Stribeck slope (load-raised
    /// levels included).
    fn predict_dq(&self, beta: &[f64], q: f64) -> Option<Result<Vec<f64>, FitError>> {
        let (law, _) = self.law_of(beta, q);
        let tb = self.data.load();
        let d = self
            .data
            .omega()
            .iter()
            .enumerate()
            .map(|(i, &w)| {
                let (_, slope, _) = law.stribeck_loaded(w, tb.map_or(0.0, |t| t[i]));
                -(w.abs() / q) * slope
            })
            .collect();
        Some(Ok(d))
    }
    fn explain(&self, name: &str, _values: &[(&'static str, f64)]) -> Explanation {
        let (lo, hi) = self.speed_range;
        let (effect, remedy) = match name {
            "offset" => (
                "the torque offset".into(),
                "on a steady-state table it cannot be told from the difference between the two directions' levels; a time series through reversals, or a known zero, would fix it".into(),
            ),
            "Tc" | "Tc_neg" => (
                format!("the Coulomb level {name}"),
                format!("speeds well above ωs (here |ω| ≤ {hi:.3e} rad/s) would reveal it"),
            ),
            "Ts" | "Ts_neg" => (
                format!("the static level {name}"),
                format!("speeds well below ωs (here |ω| ≥ {lo:.3e} rad/s) would reveal it"),
            ),
            n if n.starts_with("mu_") => (
                format!("the growth {n} of a level with the transmitted torque"),
                "rows that carry a range of transmitted torques in this direction of power flow (forward: torque and speed of the same sign; back-driven: opposite signs) would reveal it".into(),
            ),
            "sigma2" => (
                "the viscous torque σ2·ω".into(),
                format!(
                    "higher speeds than |ω| ≤ {hi:.3e} rad/s would reveal it; a value consistent with 0 means no viscous friction shows in the data"
                ),
            ),
            _ => (
                "the Stribeck speed ωs".into(),
                format!(
                    "speeds spread densely from well below to well above ωs (here |ω| from {lo:.3e} to {hi:.3e} rad/s) would reveal it"
                ),
            ),
        };
        Explanation { effect, remedy }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stribeck_speed_derivative_matches_central_differences() {
        // Asymmetric levels with load factors and an offset, both directions, speeds
        // around ωs (where the derivative is largest).
        let omega: Vec<f64> = (-40..=40).filter(|k| *k != 0).map(|k| k as f64 * 2.5e-3).collect();
        let torque = vec![0.0; omega.len()];
        let tb: Vec<f64> = omega.iter().map(|w| 40.0 * (w * 90.0).sin()).collect();
        let data = SteadyData::new(omega, torque).unwrap().with_load(tb).unwrap();
        let p =
            SteadyProblem::with_options(&data, SteadyOptions { asymmetric: true, offset: true });
        // Tc, Ts, Tc_neg, Ts_neg, σ2, offset, μc_fwd, μs_fwd, μc_back, μs_back.
        let beta = [0.2, 0.35, 0.25, 0.4, 0.8, 0.01, 0.01, 0.02, 0.015, 0.03];
        let q = 0.03;
        let exact = p.predict_dq(&beta, q).unwrap().unwrap();
        let h = 1e-6 * q;
        let (up, down) = (p.predict(&beta, q + h).unwrap(), p.predict(&beta, q - h).unwrap());
        let scale = exact.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(scale > 0.1, "{scale}");
        let worst = (0..exact.len())
            .map(|i| ((up[i] - down[i]) / (2.0 * h) - exact[i]).abs() / scale)
            .fold(0.0f64, f64::max);
        // Central differences at 1e-6 of ωs agree to 3.4e-10 of the largest value.
        assert!(worst < 5e-9, "worst relative deviation {worst:e}");
    }
}
