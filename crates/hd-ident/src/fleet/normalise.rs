//! Covariate normalisation of one parameter's estimates across a fleet.
//!
//! Each estimate vᵢ of unit u(i) is taken on a log scale, yᵢ = ln vᵢ (when every estimate
//! is positive, so effects are relative: %/K), else as it is. Over each unit's baseline
//! (its first `baseline_days`), candidate models
//!
//! ```text
//! none            yᵢ = a_u
//! fleet-linear    yᵢ = a_u + Σ_c b_c·x_ci
//! fleet-quadratic yᵢ = a_u + Σ_c (b_c·x_ci + q_c·x_ci²)
//! unit-linear     yᵢ = a_u + Σ_c b_uc·x_ci
//! unit-quadratic  yᵢ = a_u + Σ_c (b_uc·x_ci + q_uc·x_ci²)
//! ```
//!
//! (x centred on the baseline mean) are fitted by least squares and the one of least BIC,
//! `n·ln(RSS/n) + p·ln n`, is kept. It is refitted by weighted least squares with weights
//! 1/(sᵢ² + τ²), sᵢ² the unit's median squared standard error on the y scale over its
//! baseline (a log's own standard error, from a fit with few degrees of freedom, scatters
//! about it), and τ² the scatter the
//! standard errors do not explain (day-to-day variation, model error), estimated as the
//! excess of the baseline's residual variance over the mean sᵢ². Every estimate with its
//! covariates then gets a residual rᵢ = yᵢ − ŷᵢ with variance sᵢ² + τ² + Var ŷᵢ, and a
//! normalised value: the estimate moved to the reference covariates (the baseline mean).

use nalgebra::{DMatrix, DVector};

/// One estimate of the parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    /// Unit (0-based).
    pub unit: usize,
    /// Time [days].
    pub day: f64,
    /// Estimate [parameter unit].
    pub value: f64,
    /// Standard error [parameter unit]; NaN when the fit gave none.
    pub se: f64,
    /// Covariates, in the order named; NaN when missing for this log.
    pub covariates: Vec<f64>,
}

/// Which normalisation to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Normalise {
    /// The candidate of least BIC.
    Auto,
    /// Unit means only (no covariates): what the data look like without normalisation.
    None,
}

/// One candidate model and its score on the baseline.
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    /// `none`, `fleet-linear`, `fleet-quadratic`, `unit-linear`, `unit-quadratic`.
    pub name: &'static str,
    /// Coefficients.
    pub params: usize,
    /// Residual sum of squares on the baseline (y scale).
    pub rss: f64,
    /// Bayesian information criterion.
    pub bic: f64,
}

/// The normalisation of one parameter and its residuals.
#[derive(Clone, Debug, PartialEq)]
pub struct Normalisation {
    /// The model kept.
    pub chosen: &'static str,
    /// Every candidate tried, with its score.
    pub candidates: Vec<Candidate>,
    /// Whether y = ln v (else y = v).
    pub log_scale: bool,
    /// Fleet-wide covariate coefficients of the kept model, `(name, value, std error)`,
    /// on the y scale per covariate unit (×100: % per unit on the log scale); per-unit
    /// models report the mean over units.
    pub coefficients: Vec<(String, f64, f64)>,
    /// Scatter the standard errors do not explain [y scale].
    pub tau: f64,
    /// Baseline estimates used.
    pub baseline_rows: usize,
    /// Per sample: residual on the y scale (NaN where not normalised).
    pub residual: Vec<f64>,
    /// Per sample: the residual's variance.
    pub variance: Vec<f64>,
    /// Per sample: the estimate at the reference covariates [parameter unit].
    pub normalised: Vec<f64>,
    /// Per sample: the unit's baseline level at the reference covariates [parameter unit].
    pub level: Vec<f64>,
    /// Per sample: why it has no residual, if so.
    pub reason: Vec<Option<String>>,
}

#[derive(Clone, Debug)]
struct Design {
    per_unit: bool,
    degree: usize,
}

impl Design {
    fn name(&self) -> &'static str {
        match (self.degree, self.per_unit) {
            (0, _) => "none",
            (1, false) => "fleet-linear",
            (2, false) => "fleet-quadratic",
            (1, true) => "unit-linear",
            _ => "unit-quadratic",
        }
    }
    /// Columns: unit intercepts (by position in `units`), then covariate terms.
    fn width(&self, units: usize, covs: usize) -> usize {
        units + covs * self.degree * if self.per_unit { units } else { 1 }
    }
    fn row(&self, slot: usize, units: usize, x: &[f64], out: &mut [f64]) {
        out.iter_mut().for_each(|v| *v = 0.0);
        out[slot] = 1.0;
        let mut c = units;
        for xc in x {
            for d in 1..=self.degree {
                let v = xc.powi(d as i32);
                if self.per_unit {
                    out[c + slot] = v;
                    c += units;
                } else {
                    out[c] = v;
                    c += 1;
                }
            }
        }
    }
}

/// Most coefficients of a candidate model: its normal equations hold p² numbers (a
/// per-unit model of a fleet of more units is not tried).
pub const MAX_COEFFICIENTS: usize = 1500;

/// Least squares with weights `w` over `n` rows whose design row `fill(r, row)` writes:
/// coefficients, their covariance (unscaled), weighted RSS. The normal equations are
/// accumulated a row at a time (memory p², not n·p). `None` when rank deficient.
fn wls(
    n: usize,
    p: usize,
    fill: &dyn Fn(usize, &mut [f64]),
    y: &DVector<f64>,
    w: &DVector<f64>,
) -> Option<(DVector<f64>, DMatrix<f64>, f64)> {
    let mut a = DMatrix::<f64>::zeros(p, p);
    let mut b = DVector::<f64>::zeros(p);
    let mut row = vec![0.0; p];
    for r in 0..n {
        fill(r, &mut row);
        let nz: Vec<usize> = (0..p).filter(|&j| row[j] != 0.0).collect();
        for &i in &nz {
            b[i] += w[r] * row[i] * y[r];
            for &j in &nz {
                a[(i, j)] += w[r] * row[i] * row[j];
            }
        }
    }
    let chol = a.clone().cholesky()?;
    let beta = chol.solve(&b);
    let cov = chol.inverse();
    let scale = a.diagonal().max().max(1e-300);
    if cov.iter().any(|v| !v.is_finite()) || cov.diagonal().iter().any(|&d| d * scale > 1e12) {
        return None;
    }
    let mut rss = 0.0;
    for r in 0..n {
        fill(r, &mut row);
        let fit: f64 = row.iter().zip(beta.iter()).map(|(x, b)| x * b).sum();
        rss += w[r] * (y[r] - fit).powi(2);
    }
    Some((beta, cov, rss))
}

/// Why an estimate has no residual.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reason {
    /// The estimate is missing (or was left out).
    NoEstimate,
    /// The covariate of this index is missing for the log.
    CovariateMissing(usize),
    /// The unit has no baseline estimate with covariates.
    NoBaseline,
    /// Too few baseline estimates in the fleet (this many) for any model.
    TooFew(usize),
}

impl Reason {
    /// In words; `names` the covariates.
    pub fn text(&self, names: &[String]) -> String {
        match self {
            Reason::NoEstimate => "no estimate".into(),
            Reason::CovariateMissing(c) => {
                format!("covariate '{}' missing", names.get(*c).map_or("?", String::as_str))
            }
            Reason::NoBaseline => "the unit has no baseline estimates with covariates".into(),
            Reason::TooFew(nb) => format!("too few baseline estimates ({nb}) to normalise"),
        }
    }
}

/// One estimate normalised by a [`Model`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Normalised {
    /// Residual on the y scale (NaN where not normalised).
    pub residual: f64,
    /// Its variance (before the unit's own scale, [`Model::unit_scale`]).
    pub variance: f64,
    /// The estimate at the reference covariates [parameter unit].
    pub normalised: f64,
    /// The unit's baseline level at the reference covariates [parameter unit].
    pub level: f64,
    /// Why there is no residual, if so.
    pub reason: Option<Reason>,
}

impl Normalised {
    /// No residual, for `reason`.
    pub fn missing(reason: Reason) -> Self {
        Normalised {
            residual: f64::NAN,
            variance: f64::NAN,
            normalised: f64::NAN,
            level: f64::NAN,
            reason: Some(reason),
        }
    }
}

/// A kept normalisation model: what normalises any estimate of the parameter, so the
/// estimates can be streamed unit by unit once the model is fitted on the baseline.
#[derive(Clone, Debug)]
pub struct Model {
    log_scale: bool,
    design: Design,
    nslots: usize,
    slot_of: Vec<usize>,
    centre: Vec<f64>,
    scale: Vec<f64>,
    beta: DVector<f64>,
    cov: DMatrix<f64>,
    unit_s2: Vec<f64>,
    tau2: f64,
}

/// Whether an estimate can enter the baseline: a value and every covariate.
pub fn usable(s: &Sample) -> bool {
    s.value.is_finite() && s.covariates.iter().all(|c| c.is_finite())
}

/// Which of one unit's samples form its baseline: usable and within `baseline_days` of
/// the unit's first estimate [days].
pub fn baseline_flags(unit_samples: &[Sample], baseline_days: f64) -> Vec<bool> {
    let first = unit_samples
        .iter()
        .filter(|s| s.value.is_finite())
        .fold(f64::INFINITY, |m, s| m.min(s.day));
    unit_samples.iter().map(|s| usable(s) && s.day < first + baseline_days).collect()
}

/// Fit the normalisation on the baseline estimates `base` (every unit's, in one fixed
/// order; see [`baseline_flags`]) of a fleet of `units` units. `log_scale`: whether every
/// finite estimate of the parameter (baseline or not) is positive. Returns the summary
/// (per-sample vectors empty) and the model kept, `None` with too few estimates.
pub fn fit_normalisation(
    base: &[Sample],
    units: usize,
    log_scale: bool,
    names: &[String],
    mode: Normalise,
) -> (Normalisation, Option<Model>) {
    let y_of = |s: &Sample| if log_scale { s.value.ln() } else { s.value };
    let s_of = |s: &Sample| {
        let se = if log_scale { s.se / s.value } else { s.se };
        if se.is_finite() { se } else { 0.0 }
    };
    // Units with a baseline, in slot order; covariate centres and scales.
    let mut slot_of = vec![usize::MAX; units];
    let mut nslots = 0;
    for s in base {
        if slot_of[s.unit] == usize::MAX {
            slot_of[s.unit] = nslots;
            nslots += 1;
        }
    }
    let nc = names.len();
    let mut centre = vec![0.0; nc];
    let mut scale = vec![1.0; nc];
    for c in 0..nc {
        let v: Vec<f64> = base.iter().map(|s| s.covariates[c]).collect();
        let m = v.iter().sum::<f64>() / v.len().max(1) as f64;
        let sd = (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / v.len().max(1) as f64).sqrt();
        centre[c] = m;
        scale[c] = if sd > 0.0 { sd } else { 1.0 };
    }
    let xs = |s: &Sample| -> Vec<f64> {
        s.covariates.iter().enumerate().map(|(c, v)| (v - centre[c]) / scale[c]).collect()
    };
    let mut designs = vec![Design { per_unit: false, degree: 0 }];
    if mode == Normalise::Auto && nc > 0 {
        for per_unit in [false, true] {
            for degree in [1, 2] {
                designs.push(Design { per_unit, degree });
            }
        }
    }
    let nb = base.len();
    let yb = DVector::from_iterator(nb, base.iter().map(y_of));
    let fill_row = |d: &Design, r: usize, row: &mut [f64]| {
        d.row(slot_of[base[r].unit], nslots, &xs(&base[r]), row);
    };
    let mut candidates = Vec::new();
    let mut best: Option<(usize, f64)> = None;
    for (k, d) in designs.iter().enumerate() {
        let p = d.width(nslots, nc);
        if nb < p + 2 || p > MAX_COEFFICIENTS {
            continue;
        }
        let ones = DVector::from_element(nb, 1.0);
        let Some((_, _, rss)) = wls(nb, p, &|r, row| fill_row(d, r, row), &yb, &ones) else {
            continue;
        };
        let bic = crate::criteria::bic(rss, nb, p);
        candidates.push(Candidate { name: d.name(), params: p, rss, bic });
        if best.is_none_or(|(_, b)| bic < b) {
            best = Some((k, bic));
        }
    }
    let mut out = Normalisation {
        chosen: "none",
        candidates,
        log_scale,
        coefficients: Vec::new(),
        tau: f64::NAN,
        baseline_rows: nb,
        residual: Vec::new(),
        variance: Vec::new(),
        normalised: Vec::new(),
        level: Vec::new(),
        reason: Vec::new(),
    };
    let Some((k, _)) = best else {
        return (out, None);
    };
    let d = &designs[k];
    out.chosen = d.name();
    let p = d.width(nslots, nc);
    let fill = |r: usize, row: &mut [f64]| fill_row(d, r, row);
    // Each unit's typical squared standard error (median over its baseline): the same test
    // on the same unit gives the same precision, and a log's own standard error, from a
    // fit with few degrees of freedom, scatters about it (Student's t tails in z).
    let mut unit_s2 = vec![f64::NAN; units];
    for (u, slot) in unit_s2.iter_mut().enumerate() {
        let mut v: Vec<f64> =
            base.iter().filter(|s| s.unit == u).map(|s| s_of(s).powi(2)).collect();
        if !v.is_empty() {
            v.sort_by(f64::total_cmp);
            *slot = v[v.len() / 2];
        }
    }
    let s2_of = |s: &Sample| {
        let typical = unit_s2[s.unit];
        if typical.is_finite() { typical } else { s_of(s).powi(2) }
    };
    let s2: Vec<f64> = base.iter().map(s2_of).collect();
    let ones = DVector::from_element(nb, 1.0);
    let (_, _, rss) = wls(nb, p, &fill, &yb, &ones).expect("scored above");
    let dof = (nb - p).max(1) as f64;
    let tau2 = (rss / dof - s2.iter().sum::<f64>() / nb as f64).max(0.0);
    // A floor: at least a hundredth of the mean squared standard error, so weights stay finite.
    let tau2 = tau2.max(1e-2 * s2.iter().sum::<f64>() / nb as f64).max(1e-300);
    let w = DVector::from_iterator(nb, s2.iter().map(|v| 1.0 / (v + tau2)));
    let (beta, cov, _) = wls(nb, p, &fill, &yb, &w).expect("scored above");
    out.tau = tau2.sqrt();
    for c in 0..nc {
        let mut val = 0.0;
        let mut var = 0.0;
        let per = if d.per_unit { nslots } else { 1 };
        for u in 0..per {
            let j = nslots + c * d.degree * per + u;
            if d.degree >= 1 {
                val += beta[j] / scale[c] / per as f64;
                var += cov[(j, j)] / (scale[c] * scale[c]) / (per * per) as f64;
            }
        }
        out.coefficients.push((names[c].clone(), val, var.sqrt()));
    }
    let model = Model {
        log_scale,
        design: Design { per_unit: d.per_unit, degree: d.degree },
        nslots,
        slot_of,
        centre,
        scale,
        beta,
        cov,
        unit_s2,
        tau2,
    };
    (out, Some(model))
}

impl Model {
    /// Normalise one estimate: its residual rᵢ = yᵢ − ŷᵢ, variance sᵢ² + τ² + Var ŷᵢ, the
    /// estimate at the reference covariates and the unit's level there.
    pub fn apply(&self, s: &Sample) -> Normalised {
        if !s.value.is_finite() {
            return Normalised::missing(Reason::NoEstimate);
        }
        if let Some(c) = s.covariates.iter().position(|c| !c.is_finite()) {
            return Normalised::missing(Reason::CovariateMissing(c));
        }
        let slot = self.slot_of.get(s.unit).copied().unwrap_or(usize::MAX);
        if slot == usize::MAX {
            return Normalised::missing(Reason::NoBaseline);
        }
        let (beta, cov) = (&self.beta, &self.cov);
        let mut row = vec![0.0; beta.len()];
        let xs: Vec<f64> = s
            .covariates
            .iter()
            .enumerate()
            .map(|(c, v)| (v - self.centre[c]) / self.scale[c])
            .collect();
        self.design.row(slot, self.nslots, &xs, &mut row);
        let xr = DVector::from_column_slice(&row);
        let pred = xr.dot(beta);
        let pvar = (xr.transpose() * cov * &xr)[(0, 0)];
        let (y, se) = if self.log_scale { (s.value.ln(), s.se / s.value) } else { (s.value, s.se) };
        let se = if se.is_finite() { se } else { 0.0 };
        let typical = self.unit_s2[s.unit];
        let s2 = if typical.is_finite() { typical } else { se.powi(2) };
        let cov_part = pred - beta[slot];
        let (normalised, level) = if self.log_scale {
            ((y - cov_part).exp(), beta[slot].exp())
        } else {
            (y - cov_part, beta[slot])
        };
        Normalised {
            residual: y - pred,
            variance: s2 + self.tau2 + pvar.max(0.0),
            normalised,
            level,
            reason: None,
        }
    }

    /// A unit's own scale φ_u from its baseline estimates' normalised values (any
    /// order): units differ in how well one log determines a parameter, so the pooled
    /// variance is rescaled by the unit's baseline ratio r²/Var, shrunk towards 1 with the
    /// weight of [`UNIT_PRIOR`] estimates (the CUSUM threshold is simulated with the same
    /// estimator, [`super::cusum::threshold_estimated`]). `None` with too few estimates.
    pub fn unit_scale<'a>(&self, baseline: impl Iterator<Item = &'a Normalised>) -> Option<f64> {
        let own = if self.design.per_unit { 1 + self.centre.len() * self.design.degree } else { 1 };
        let (mut m, mut sum) = (0usize, 0.0);
        for n in baseline.filter(|n| n.residual.is_finite()) {
            m += 1;
            sum += n.residual.powi(2) / n.variance;
        }
        if m <= own {
            return None;
        }
        let q = sum / (m - own) as f64;
        Some((UNIT_PRIOR + m as f64 * q) / (UNIT_PRIOR + m as f64))
    }
}

/// Normalise `samples` (one parameter, all units, in memory); `baseline_days` from each
/// unit's first estimate; `names` the covariates. The same as [`fit_normalisation`] on the
/// baseline, then [`Model::apply`] and [`Model::unit_scale`] per unit.
pub fn normalise(
    samples: &[Sample],
    names: &[String],
    baseline_days: f64,
    mode: Normalise,
) -> Normalisation {
    let n = samples.len();
    let units = samples.iter().map(|s| s.unit + 1).max().unwrap_or(0);
    let log_scale = samples.iter().filter(|s| s.value.is_finite()).all(|s| s.value > 0.0);
    let mut is_base = vec![false; n];
    for u in 0..units {
        let idx: Vec<usize> = (0..n).filter(|&i| samples[i].unit == u).collect();
        let mine: Vec<Sample> = idx.iter().map(|&i| samples[i].clone()).collect();
        for (&i, b) in idx.iter().zip(baseline_flags(&mine, baseline_days)) {
            is_base[i] = b;
        }
    }
    let base: Vec<Sample> = (0..n).filter(|&i| is_base[i]).map(|i| samples[i].clone()).collect();
    let (mut out, model) = fit_normalisation(&base, units, log_scale, names, mode);
    let rows: Vec<Normalised> = match &model {
        Some(m) => samples.iter().map(|s| m.apply(s)).collect(),
        None => vec![Normalised::missing(Reason::TooFew(base.len())); n],
    };
    let mut variance: Vec<f64> = rows.iter().map(|r| r.variance).collect();
    if let Some(m) = &model {
        for u in 0..units {
            let own = (0..n).filter(|&i| samples[i].unit == u && is_base[i]).map(|i| &rows[i]);
            if let Some(phi) = m.unit_scale(own) {
                for (i, v) in variance.iter_mut().enumerate() {
                    if samples[i].unit == u && v.is_finite() {
                        *v *= phi;
                    }
                }
            }
        }
    }
    out.residual = rows.iter().map(|r| r.residual).collect();
    out.variance = variance;
    out.normalised = rows.iter().map(|r| r.normalised).collect();
    out.level = rows.iter().map(|r| r.level).collect();
    out.reason = rows.iter().map(|r| r.reason.map(|x| x.text(names))).collect();
    out
}

/// Weight of the pooled variance in each unit's own scale, in baseline estimates.
pub const UNIT_PRIOR: f64 = 10.0;

#[cfg(test)]
mod tests {
    use super::*;

    /// Two units, values v = v_u·exp(−0.006·(T − 20)) with a small alternating scatter:
    /// the fleet-wide linear model is chosen and its slope is −0.6 %/K.
    #[test]
    fn a_shared_temperature_effect_is_found_and_removed() {
        let mut samples = Vec::new();
        for u in 0..2 {
            for d in 0..40 {
                let temp = 20.0 + 10.0 * (d as f64 * 0.7).sin();
                let wiggle = if d % 2 == 0 { 1.001 } else { 0.999 };
                let v = [0.15, 0.2][u] * (-0.006 * (temp - 20.0)).exp() * wiggle;
                samples.push(Sample {
                    unit: u,
                    day: d as f64,
                    value: v,
                    se: 1e-5,
                    covariates: vec![temp],
                });
            }
        }
        let n = normalise(&samples, &["temperature".into()], 20.0, Normalise::Auto);
        assert_eq!(n.chosen, "fleet-linear", "{:?}", n.candidates);
        let (_, b, se) = &n.coefficients[0];
        assert!((b + 0.006).abs() < 3.0 * se && *se < 1e-4, "{b} ± {se}");
        // The normalised values sit at the unit levels within the scatter.
        for (s, v) in samples.iter().zip(&n.normalised) {
            let level = [0.15, 0.2][s.unit];
            assert!((v / level - 1.0).abs() < 0.02, "{v} vs {level}");
        }
        let off = normalise(&samples, &["temperature".into()], 20.0, Normalise::None);
        assert_eq!(off.chosen, "none");
        let spread = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>() / r.len() as f64;
        assert!(spread(&off.residual) > 100.0 * spread(&n.residual));
    }
}
