//! The static friction stage: `T(ω) = sign(ω)·(Tc + (Ts − Tc)·e^{−(ω/ωs)²}) + σ2·ω`,
//! linear in Tc, Ts and σ2 for a given ωs; ωs comes from the global search over ln ωs.
//! Columns and prediction are [`LuGre::steady_torque`] itself.

use crate::data::SteadyData;
use crate::error::FitError;
use crate::report::Explanation;
use crate::separable::{Basis, Separable};
use hd_model::laws::friction::{FrictionLaw, LuGre};

/// Parameters of the static stage, in report order.
pub const STATIC_PARAMS: [&str; 4] = ["Tc", "Ts", "sigma2", "ws"];

/// Search range of ωs relative to the measured speeds: from a tenth of the slowest to ten
/// times the fastest |ω| (outside, the Stribeck drop is entirely above or below the data).
pub const WS_RANGE_FACTOR: f64 = 10.0;

/// A LuGre law with only the static parameters set (the others do not affect the steady
/// torque).
fn static_law(tc: f64, ts: f64, sigma2: f64, ws: f64) -> LuGre {
    LuGre { sigma0: 1.0, sigma1: 0.0, sigma2, tc, ts, ws }
}

/// The static friction problem on one steady-state sweep.
pub struct SteadyProblem<'a> {
    data: &'a SteadyData,
    speed_range: (f64, f64),
}

impl<'a> SteadyProblem<'a> {
    /// Set up the problem on `data`.
    pub fn new(data: &'a SteadyData) -> Self {
        let speeds = data.omega().iter().map(|w| w.abs());
        let (lo, hi) = speeds.fold((f64::INFINITY, 0.0f64), |(l, h), w| (l.min(w), h.max(w)));
        Self { data, speed_range: (lo, hi) }
    }

    fn curve(&self, law: &LuGre) -> Vec<f64> {
        self.data.omega().iter().map(|&w| law.steady_torque(w)).collect()
    }
}

impl Separable for SteadyProblem<'_> {
    fn fit_name(&self) -> &'static str {
        "friction-static"
    }
    fn linear_names(&self) -> &'static [&'static str] {
        &["Tc", "Ts", "sigma2"]
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
        let columns = vec![
            self.curve(&static_law(1.0, 0.0, 0.0, q)),
            self.curve(&static_law(0.0, 1.0, 0.0, q)),
            self.curve(&static_law(0.0, 0.0, 1.0, q)),
        ];
        Ok(Basis { columns, offset: None })
    }
    fn predict(&self, beta: &[f64], q: f64) -> Result<Vec<f64>, FitError> {
        Ok(self.curve(&static_law(beta[0], beta[1], beta[2], q)))
    }
    fn explain(&self, name: &str, _values: &[(&'static str, f64)]) -> Explanation {
        let (lo, hi) = self.speed_range;
        let (effect, remedy) = match name {
            "Tc" => (
                "the Coulomb level Tc".into(),
                format!("speeds well above ωs (here |ω| ≤ {hi:.3e} rad/s) would reveal it"),
            ),
            "Ts" => (
                "the static level Ts".into(),
                format!("speeds well below ωs (here |ω| ≥ {lo:.3e} rad/s) would reveal it"),
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
