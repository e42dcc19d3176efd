//! The dynamic friction stage: σ0 and σ1 from a time series, with Tc, Ts, ωs and σ2 held.
//!
//! The bristle state w = σ0·s runs along the measured speed by the LuGre law's exact
//! sample updates ([`super::bristle`]). The friction torque
//! `Tf = w + σ1·ṡ + σ2·v` is linear in σ1 for a given σ0 (w and ṡ do not depend on σ1),
//! so σ0 comes from the global search over ln σ0.

use super::bristle::bristle_run;
use crate::data::TransientData;
use crate::error::FitError;
use crate::report::Explanation;
use crate::separable::{Basis, Separable};
use hd_model::laws::friction::{FrictionLaw, LuGre};

/// Parameters of the dynamic stage, in report order.
pub const DYNAMIC_PARAMS: [&str; 2] = ["sigma1", "sigma0"];

/// Position of σ0 in the bristle run's gradient ([`hd_model::laws::lugre_step::SHAPE_PARAMS`]).
const SIGMA0_SLOT: usize = 3;

/// Search range of σ0 in terms of the pre-sliding displacement Ts/σ0: from ten times the
/// whole displacement range of the record (the bristles never saturate) down to a
/// hundredth of the median displacement per sample (the transition is over within a
/// sample, so a stiffer σ0 looks the same).
pub const SIGMA0_LOW_SPAN: f64 = 10.0;
/// See [`SIGMA0_LOW_SPAN`].
pub const SIGMA0_HIGH_PER_SAMPLE: f64 = 100.0;

/// The bristle state w [N·m] at every sample under `law`, starting from the first
/// measured torque `first_torque` held inside the bristles' range at the first speed
/// (a record rarely starts exactly at rest or in steady sliding: a speed derived from an
/// encoder is never exactly zero, and a start in steady state at a tiny negative speed
/// would put w at −Ts where the torque says 0). The speed is read as linear between
/// samples and each interval stepped exactly at its mean speed
/// ([`hd_model::laws::friction::LuGre::step_interval`]).
pub fn bristle_states(
    t: &[f64],
    omega: &[f64],
    law: &LuGre,
    first_torque: f64,
) -> Result<Vec<f64>, FitError> {
    Ok(bristle_run(t, omega, law, first_torque, false)?.w)
}

/// The dynamic friction problem on one time series, static parameters given.
pub struct TransientProblem<'a> {
    data: &'a TransientData,
    /// Tc, Ts, ωs, σ2 held during this stage (σ0, σ1 fields unused).
    statics: LuGre,
    median_step: f64,
}

impl<'a> TransientProblem<'a> {
    /// Set up the problem on `data` with static parameters `tc`, `ts`, `ws`, `sigma2`.
    pub fn new(data: &'a TransientData, tc: f64, ts: f64, ws: f64, sigma2: f64) -> Self {
        let (t, w) = (data.t(), data.omega());
        let mut steps: Vec<f64> =
            (1..t.len()).map(|k| 0.5 * (w[k].abs() + w[k - 1].abs()) * (t[k] - t[k - 1])).collect();
        steps.sort_by(f64::total_cmp);
        let median = steps[steps.len() / 2];
        let median_step =
            if median > 0.0 { median } else { steps.iter().sum::<f64>() / steps.len() as f64 };
        let statics = LuGre::symmetric(1.0, 0.0, sigma2, tc, ts, ws);
        Self { data, statics, median_step }
    }

    fn law(&self, sigma0: f64, sigma1: f64) -> LuGre {
        LuGre { sigma0, sigma1, ..self.statics }
    }

    /// Range of the sliding displacement x(t) = ∫v dt over the record [rad].
    fn displacement_span(&self) -> f64 {
        let (t, w) = (self.data.t(), self.data.omega());
        let (mut x, mut lo, mut hi) = (0.0f64, 0.0f64, 0.0f64);
        for k in 1..t.len() {
            x += 0.5 * (w[k] + w[k - 1]) * (t[k] - t[k - 1]);
            lo = lo.min(x);
            hi = hi.max(x);
        }
        hi - lo
    }
}

impl Separable for TransientProblem<'_> {
    fn fit_name(&self) -> &'static str {
        "friction-dynamic"
    }
    fn linear_names(&self) -> &'static [&'static str] {
        &["sigma1"]
    }
    fn nonlinear_name(&self) -> &'static str {
        "sigma0"
    }
    fn search_range(&self) -> (f64, f64) {
        let level = self.statics.max_level();
        let span = self.displacement_span().max(self.median_step);
        (level / (SIGMA0_LOW_SPAN * span), SIGMA0_HIGH_PER_SAMPLE * level / self.median_step)
    }
    fn measured(&self) -> &[f64] {
        self.data.torque()
    }
    fn fd_step(&self) -> f64 {
        1e-3
    }
    fn basis(&self, q: f64) -> Result<Basis, FitError> {
        let law = self.law(q, 0.0);
        let w = bristle_states(self.data.t(), self.data.omega(), &law, self.data.torque()[0])?;
        let (offset, s_rate): (Vec<f64>, Vec<f64>) = self
            .data
            .omega()
            .iter()
            .zip(&w)
            .map(|(&v, &wk)| {
                let e = law.eval(v, wk);
                (e.torque, e.w_rate / law.sigma0)
            })
            .unzip();
        Ok(Basis { columns: vec![s_rate], offset: Some(offset) })
    }
    fn predict(&self, beta: &[f64], q: f64) -> Result<Vec<f64>, FitError> {
        let law = self.law(q, beta[0]);
        let w = bristle_states(self.data.t(), self.data.omega(), &law, self.data.torque()[0])?;
        Ok(self.data.omega().iter().zip(&w).map(|(&v, &wk)| law.eval(v, wk).torque).collect())
    }
    /// ∂Tf/∂σ0 = ∂w/∂σ0 + σ1·∂ṡ/∂σ0, from the bristle run's carried sensitivities.
    fn predict_dq(&self, beta: &[f64], q: f64) -> Option<Result<Vec<f64>, FitError>> {
        let law = self.law(q, beta[0]);
        let (t, omega) = (self.data.t(), self.data.omega());
        Some(bristle_run(t, omega, &law, self.data.torque()[0], true).map(|run| {
            let k = SIGMA0_SLOT;
            run.d_w.iter().zip(&run.d_slip).map(|(dw, ds)| dw[k] + beta[0] * ds[k]).collect()
        }))
    }
    fn explain(&self, name: &str, values: &[(&'static str, f64)]) -> Explanation {
        let sigma0 = values.iter().find(|(n, _)| *n == "sigma0").map_or(f64::NAN, |v| v.1);
        let presliding = self.statics.ts / sigma0;
        let (effect, remedy) = match name {
            "sigma0" => (
                "the bristle stiffness σ0 (pre-sliding)".into(),
                format!(
                    "motion reversals sampled finely enough to resolve the pre-sliding displacement Ts/σ0 ≈ {presliding:.2e} rad (here the median displacement per sample is {:.2e} rad) would reveal it",
                    self.median_step
                ),
            ),
            _ => (
                "the bristle damping σ1·ṡ".into(),
                format!(
                    "fast reversals that cross the pre-sliding displacement Ts/σ0 ≈ {presliding:.2e} rad at high speed, sampled finely, would reveal it: σ1·ṡ is large only while the bristles deflect quickly"
                ),
            ),
        };
        Explanation { effect, remedy }
    }
}
