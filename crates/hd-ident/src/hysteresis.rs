//! The hysteresis fit: a, b, c, A, B from a torque–deflection record.
//!
//! The torque is `Tb = a·θ³ + b·θ² + c·θ + z` with `ż = A·θ̇ − B·z`, z(0) = 0
//! (docs/model.md §2.1). Since z = A·ζ where ζ is the memory of unit intensity, the torque
//! is linear in a, b, c and A for a given B; B is found by the global search over ln B.
//! The memory runs along the measured θ(t), taken as linear between samples, with the
//! exact step [`FadingMemory::step_linear`]; the cubic terms and the composed prediction
//! come from [`CubicSpring`] and [`Hysteretic`] — the laws the simulator integrates.

use crate::data::HysteresisData;
use crate::error::FitError;
use crate::fix::Fixed;
use crate::memory_profile::{MemoryProfile, SharedFactors};
use crate::report::Explanation;
use crate::separable::{Basis, Separable, SeparableFit, fit_separable};
use hd_model::laws::stiffness::{CubicSpring, FadingMemory, Hysteretic, StiffnessLaw};
use std::sync::OnceLock;

/// Parameters of the hysteresis fit, in report order.
pub const HYSTERESIS_PARAMS: [&str; 5] = ["a", "b", "c", "mem_A", "mem_B"];

/// Practical search range of B: from `B_LOW_CYCLES` memory time constants over the
/// record (below that the memory is a pure integrator of θ, indistinguishable from c·θ)
/// to `B_HIGH_PER_SAMPLE` per median sample interval (above that the memory forgets
/// within a sample and only A/B, a viscous-like term, remains visible).
pub const B_LOW_CYCLES: f64 = 0.1;
/// See [`B_LOW_CYCLES`].
pub const B_HIGH_PER_SAMPLE: f64 = 10.0;

/// The hysteresis identification problem on one record.
pub struct HysteresisProblem<'a> {
    data: &'a HysteresisData,
    offset: bool,
    /// The spring's part of the design, factorised on first use.
    profile: OnceLock<MemoryProfile>,
}

impl<'a> HysteresisProblem<'a> {
    /// Set up the problem on `data`.
    pub fn new(data: &'a HysteresisData) -> Self {
        Self { data, offset: false, profile: OnceLock::new() }
    }

    /// The spring's unit column `CubicSpring { a, b, c }` along the record.
    fn spring_column(&self, a: f64, b: f64, c: f64) -> Vec<f64> {
        let law = CubicSpring { a, b, c };
        self.data.theta().iter().map(|&th| law.torque(th)).collect()
    }

    /// The same problem with a constant torque offset of the measurement fitted too
    /// (`offset` [N·m]; a rig's torque zero is never exact).
    pub fn with_offset(mut self) -> Self {
        self.offset = true;
        self
    }

    /// The memory state along the record for memory law `m`, from z = 0.
    fn memory(&self, m: &FadingMemory) -> Vec<f64> {
        let (t, th) = (self.data.t(), self.data.theta());
        let mut z = Vec::with_capacity(t.len());
        let mut zi = 0.0;
        z.push(zi);
        for k in 1..t.len() {
            zi = m.step_linear(zi, th[k] - th[k - 1], t[k] - t[k - 1]);
            z.push(zi);
        }
        z
    }

    fn theta_max(&self) -> f64 {
        self.data.theta().iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }
}

/// The fitted torque sample by sample along a record (the memory carried between
/// calls), so predictions on long records need no column.
struct Predictor {
    law: Hysteretic,
    offset: f64,
    z: f64,
    last: Option<(f64, f64)>,
    /// The step factors of the last interval ([`FadingMemory::step_factors`]).
    factors: SharedFactors<(f64, f64)>,
}

impl Predictor {
    fn new(beta: &[f64], q: f64, offset: bool) -> Self {
        let law = Hysteretic {
            spring: CubicSpring { a: beta[0], b: beta[1], c: beta[2] },
            memory: FadingMemory { a: beta[3], b: q },
        };
        let factors = SharedFactors::new((1.0, 1.0));
        Self { law, offset: if offset { beta[4] } else { 0.0 }, z: 0.0, last: None, factors }
    }

    /// The torque at the next sample (t [s], θ [rad]) [N·m].
    fn next(&mut self, t: f64, th: f64) -> f64 {
        let rate = match self.last {
            None => 0.0,
            Some((t0, th0)) => {
                let (h, m) = (t - t0, &self.law.memory);
                let (decay, gain) = self.factors.at(h, t, |h| m.step_factors(h));
                self.z = m.step_with(self.z, th - th0, decay, gain);
                (th - th0) / h
            }
        };
        self.last = Some((t, th));
        self.law.eval(th, rate, self.z).torque + self.offset
    }
}

fn median_step(t: &[f64]) -> f64 {
    let mut d: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let mid = d.len() / 2;
    // The element a full sort would put in the middle, in linear time.
    *d.select_nth_unstable_by(mid, f64::total_cmp).1
}

impl Separable for HysteresisProblem<'_> {
    fn fit_name(&self) -> &'static str {
        "hysteresis"
    }
    fn linear_names(&self) -> &'static [&'static str] {
        if self.offset { &["a", "b", "c", "mem_A", "offset"] } else { &["a", "b", "c", "mem_A"] }
    }
    fn nonlinear_name(&self) -> &'static str {
        "mem_B"
    }
    fn search_range(&self) -> (f64, f64) {
        let t = self.data.t();
        let span = t[t.len() - 1] - t[0];
        (B_LOW_CYCLES / span, B_HIGH_PER_SAMPLE / median_step(t))
    }
    fn measured(&self) -> &[f64] {
        self.data.torque()
    }
    fn basis(&self, q: f64) -> Result<Basis, FitError> {
        let zeta = self.memory(&FadingMemory { a: 1.0, b: q });
        let mut columns = vec![
            self.spring_column(1.0, 0.0, 0.0),
            self.spring_column(0.0, 1.0, 0.0),
            self.spring_column(0.0, 0.0, 1.0),
            zeta,
        ];
        if self.offset {
            columns.push(vec![1.0; self.data.len()]);
        }
        Ok(Basis { columns, offset: None })
    }
    fn predict(&self, beta: &[f64], q: f64) -> Result<Vec<f64>, FitError> {
        // The memory runs beside the prediction (no second column held).
        let mut p = Predictor::new(beta, q, self.offset);
        let (t, th) = (self.data.t(), self.data.theta());
        Ok(t.iter().zip(th).map(|(&t, &th)| p.next(t, th)).collect())
    }
    fn streams_rows(&self) -> bool {
        true
    }
    fn stream_rows(
        &self,
        beta: &[f64],
        q: f64,
        free: &[bool],
        with_q: bool,
        f: &mut dyn FnMut(&[f64]),
    ) -> Option<Result<(), FitError>> {
        let (t, th) = (self.data.t(), self.data.theta());
        let unit = FadingMemory { a: 1.0, b: q };
        let m = FadingMemory { a: beta[3], b: q };
        let (mut zeta, mut z, mut dz) = (0.0, 0.0, 0.0);
        let mut all = [0.0; 5];
        let mut row = Vec::with_capacity(7);
        // The step factors, shared by intervals equal within the stamps' rounding.
        let mut shared = SharedFactors::new((1.0, 1.0, 0.0));
        for k in 0..t.len() {
            if k > 0 {
                let (d_theta, h) = (th[k] - th[k - 1], t[k] - t[k - 1]);
                let (decay, gain, slope) = shared.at(h, t[k], |h| m.step_grad_factors(h));
                let h_last = shared.interval();
                zeta = unit.step_with(zeta, d_theta, decay, gain);
                // ∂z₁/∂B = −h·e^{−Bh}·z₀ + A·Δθ·h·φ′(Bh), carried: ∂z/∂B ← e^{−Bh}·∂z/∂B + that.
                let d_b = -h_last * decay * z + m.a * d_theta * slope;
                dz = decay * dz + d_b;
                z = m.step_with(z, d_theta, decay, gain);
            }
            let x = th[k];
            all[..4].copy_from_slice(&[x * x * x, x * x, x, zeta]);
            all[4] = 1.0;
            row.clear();
            row.extend(all.iter().zip(free).filter(|(_, f)| **f).map(|(v, _)| *v));
            if with_q {
                row.push(dz);
            }
            f(&row);
        }
        Some(Ok(()))
    }
    fn profile(&self, q: f64, lo: &[f64], hi: &[f64]) -> Option<(f64, Vec<f64>, Vec<bool>)> {
        let d = self.data;
        let p = self.profile.get_or_init(|| MemoryProfile::new(d.theta(), d.torque(), self.offset));
        p.at(d.t(), d.theta(), d.torque(), q, lo, hi)
            .or_else(|| p.at_full(d.t(), d.theta(), d.torque(), q, lo, hi))
    }
    /// ∂Tb/∂B = ∂z/∂B, carried along the record with the memory's exact step.
    fn predict_dq(&self, beta: &[f64], q: f64) -> Option<Result<Vec<f64>, FitError>> {
        let m = FadingMemory { a: beta[3], b: q };
        let (t, th) = (self.data.t(), self.data.theta());
        let mut out = Vec::with_capacity(t.len());
        let (mut z, mut dz) = (0.0, 0.0);
        out.push(dz);
        for k in 1..t.len() {
            let (z1, d_z0, d_b) = m.step_linear_grad(z, th[k] - th[k - 1], t[k] - t[k - 1]);
            dz = d_z0 * dz + d_b;
            z = z1;
            out.push(dz);
        }
        Some(Ok(out))
    }
    fn explain(&self, name: &str, values: &[(&'static str, f64)]) -> Explanation {
        let range = format!("max |θ| = {:.2e} rad", self.theta_max());
        let b = values.iter().find(|(n, _)| *n == "mem_B").map_or(f64::NAN, |v| v.1);
        let (effect, remedy) = match name {
            "a" => (
                "a·θ³".into(),
                format!("data over a wider deflection range than {range} would reveal it"),
            ),
            "b" => (
                "b·θ²".into(),
                format!(
                    "data over a wider (or one-sided) deflection range than {range} would reveal it"
                ),
            ),
            "offset" => (
                "the torque offset".into(),
                "a record whose deflection swings symmetrically about zero would separate it from b·θ²".into(),
            ),
            "c" => (
                "c·θ".into(),
                format!("a deflection that varies more than {range} would reveal it"),
            ),
            "mem_A" => (
                "the memory torque A·ζ".into(),
                format!(
                    "deflection rates with content near the memory's corner frequency B/2π ≈ {:.3e} Hz would reveal it",
                    b / std::f64::consts::TAU
                ),
            ),
            _ => (
                "the memory decay rate B".into(),
                format!(
                    "excitation at frequencies around B/2π ≈ {:.3e} Hz, over a record of many 1/B, would reveal it",
                    b / std::f64::consts::TAU
                ),
            ),
        };
        Explanation { effect, remedy }
    }
}

/// Share of the noise above which the sampling error gets a warning.
pub const SAMPLING_WARN: f64 = 0.2;

/// Estimate of the torque error [N·m RMS] caused by reading θ as linear between samples,
/// at the fitted parameters: the same model on every other sample differs from the full
/// record by about three times that error (the reading is second order in the sample
/// interval), so the error is a third of their RMS difference on the shared samples.
pub fn sampling_error(
    data: &HysteresisData,
    beta: &[f64],
    b: f64,
    offset: bool,
) -> Result<Option<f64>, FitError> {
    if data.len() < 20 {
        return Ok(None);
    }
    // The full record and every other sample, each with its own memory, side by side.
    let (mut full, mut coarse) = (Predictor::new(beta, b, offset), Predictor::new(beta, b, offset));
    let (mut sq, mut shared) = (0.0, 0usize);
    for (k, (&t, &th)) in data.t().iter().zip(data.theta()).enumerate() {
        let f = full.next(t, th);
        if k % 2 == 0 {
            sq += (f - coarse.next(t, th)).powi(2);
            shared += 1;
        }
    }
    Ok(Some((sq / shared as f64).sqrt() / 3.0))
}

/// Fit a, b, c, A, B to `data`, holding the parameters in `fixed`. The report carries a
/// remark with the [`sampling_error`] estimate, as a warning when it exceeds
/// [`SAMPLING_WARN`] of the noise.
pub fn fit_hysteresis(data: &HysteresisData, fixed: &Fixed) -> Result<SeparableFit, FitError> {
    fit_hysteresis_with(data, fixed, false)
}

/// [`fit_hysteresis`], with a constant torque offset of the measurement fitted too when
/// `offset` is set. A deflection offset θ0 needs no parameter of its own: for the cubic
/// spring, f(θ − θ0) + T0 is again a cubic in θ plus a constant (the memory term sees
/// only θ̇), so b, c and the torque offset absorb it exactly; the report says so.
pub fn fit_hysteresis_with(
    data: &HysteresisData,
    fixed: &Fixed,
    offset: bool,
) -> Result<SeparableFit, FitError> {
    let problem = if offset {
        HysteresisProblem::new(data).with_offset()
    } else {
        HysteresisProblem::new(data)
    };
    let mut fit = fit_separable(&problem, fixed)?;
    if offset {
        fit.report.remarks.push(
            "offsets: the torque offset is fitted as `offset`; a deflection offset θ0 is absorbed exactly by b, c and the torque offset (f(θ − θ0) is again a cubic in θ, and the memory sees only θ̇), so b and c here describe the spring about the recorded zero of θ".into(),
        );
    }
    let v = |n: &str| fit.value(n).unwrap_or(0.0);
    let beta = [v("a"), v("b"), v("c"), v("mem_A"), v("offset")];
    if let Some(err) = sampling_error(data, &beta, v("mem_B"), offset)? {
        let share = err / fit.report.noise_std;
        let remark = if share > SAMPLING_WARN {
            format!(
                "warning: reading θ as linear between samples shifts the modelled torque by about {err:.2e} N·m RMS, {:.0} % of the noise; A and B may be biased beyond their standard errors: sample faster relative to the excitation",
                100.0 * share
            )
        } else {
            format!(
                "sampling check: reading θ as linear between samples shifts the modelled torque by about {err:.2e} N·m RMS, {:.1} % of the noise (negligible)",
                100.0 * share
            )
        };
        fit.report.remarks.push(remark);
    }
    Ok(fit)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The streamed Jacobian rows are the basis columns and ∂prediction/∂B, row by row.
    #[test]
    fn streamed_rows_are_the_columns() {
        let n = 2000;
        let t: Vec<f64> = (0..n).map(|k| 2e-4 * k as f64).collect();
        let th: Vec<f64> =
            t.iter().map(|&t| 1e-3 * (9.0 * t).sin() + 3e-4 * (70.0 * t).sin()).collect();
        let y: Vec<f64> = th.iter().map(|v| 5e4 * v).collect();
        let data = HysteresisData::new(t, th, y).unwrap();
        let p = HysteresisProblem::new(&data).with_offset();
        let (beta, q) = ([1e7, 3e3, 5e4, 4e4, 0.2], 250.0);
        let basis = p.basis(q).unwrap();
        let dq = p.predict_dq(&beta, q).unwrap().unwrap();
        let mut rows = Vec::new();
        p.stream_rows(&beta, q, &[true; 5], true, &mut |r| rows.push(r.to_vec())).unwrap().unwrap();
        let mut cols = basis.columns;
        cols.push(dq);
        for (j, col) in cols.iter().enumerate() {
            let scale = col.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let worst = (0..n).map(|k| (rows[k][j] - col[k]).abs()).fold(0.0, f64::max);
            assert!(worst <= 1e-12 * scale, "column {j}: {worst:e} of {scale:e}");
        }
    }
}
