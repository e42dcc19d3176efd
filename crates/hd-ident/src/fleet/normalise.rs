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

/// Normalise `samples` (one parameter, all units); `baseline_days` from each unit's first
/// estimate; `names` the covariates.
pub fn normalise(
    samples: &[Sample],
    names: &[String],
    baseline_days: f64,
    mode: Normalise,
) -> Normalisation {
    let n = samples.len();
    let units = samples.iter().map(|s| s.unit + 1).max().unwrap_or(0);
    let log_scale = samples.iter().filter(|s| s.value.is_finite()).all(|s| s.value > 0.0);
    let y_of = |s: &Sample| if log_scale { s.value.ln() } else { s.value };
    let s_of = |s: &Sample| {
        let se = if log_scale { s.se / s.value } else { s.se };
        if se.is_finite() { se } else { 0.0 }
    };
    let mut first = vec![f64::INFINITY; units];
    for s in samples.iter().filter(|s| s.value.is_finite()) {
        first[s.unit] = first[s.unit].min(s.day);
    }
    let usable = |s: &Sample| s.value.is_finite() && s.covariates.iter().all(|c| c.is_finite());
    let base: Vec<usize> = (0..n)
        .filter(|&i| usable(&samples[i]) && samples[i].day < first[samples[i].unit] + baseline_days)
        .collect();
    // Units with a baseline, in slot order; covariate centres and scales.
    let mut slot_of = vec![usize::MAX; units];
    let mut nslots = 0;
    for &i in &base {
        let u = samples[i].unit;
        if slot_of[u] == usize::MAX {
            slot_of[u] = nslots;
            nslots += 1;
        }
    }
    let nc = names.len();
    let mut centre = vec![0.0; nc];
    let mut scale = vec![1.0; nc];
    for c in 0..nc {
        let v: Vec<f64> = base.iter().map(|&i| samples[i].covariates[c]).collect();
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
    let yb = DVector::from_iterator(nb, base.iter().map(|&i| y_of(&samples[i])));
    let fill_row = |d: &Design, r: usize, row: &mut [f64]| {
        let i = base[r];
        d.row(slot_of[samples[i].unit], nslots, &xs(&samples[i]), row);
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
        let bic = nb as f64 * (rss.max(1e-300) / nb as f64).ln() + p as f64 * (nb as f64).ln();
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
        residual: vec![f64::NAN; n],
        variance: vec![f64::NAN; n],
        normalised: vec![f64::NAN; n],
        level: vec![f64::NAN; n],
        reason: vec![None; n],
    };
    let Some((k, _)) = best else {
        let why = format!("too few baseline estimates ({nb}) to normalise");
        out.reason.iter_mut().for_each(|r| *r = Some(why.clone()));
        return out;
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
        let mut v: Vec<f64> = base
            .iter()
            .filter(|&&i| samples[i].unit == u)
            .map(|&i| s_of(&samples[i]).powi(2))
            .collect();
        if !v.is_empty() {
            v.sort_by(f64::total_cmp);
            *slot = v[v.len() / 2];
        }
    }
    let s2_of = |s: &Sample| {
        let typical = unit_s2[s.unit];
        if typical.is_finite() { typical } else { s_of(s).powi(2) }
    };
    let s2: Vec<f64> = base.iter().map(|&i| s2_of(&samples[i])).collect();
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
    let mut row = vec![0.0; p];
    for (i, s) in samples.iter().enumerate() {
        if !s.value.is_finite() {
            out.reason[i] = Some("no estimate".into());
            continue;
        }
        if let Some(c) = s.covariates.iter().position(|c| !c.is_finite()) {
            out.reason[i] = Some(format!("covariate '{}' missing", names[c]));
            continue;
        }
        if slot_of[s.unit] == usize::MAX {
            out.reason[i] = Some("the unit has no baseline estimates with covariates".into());
            continue;
        }
        let slot = slot_of[s.unit];
        d.row(slot, nslots, &xs(s), &mut row);
        let xr = DVector::from_column_slice(&row);
        let pred = xr.dot(&beta);
        let pvar = (xr.transpose() * &cov * &xr)[(0, 0)];
        let y = y_of(s);
        let cov_part = pred - beta[slot];
        out.residual[i] = y - pred;
        out.variance[i] = s2_of(s) + tau2 + pvar.max(0.0);
        if log_scale {
            out.normalised[i] = (y - cov_part).exp();
            out.level[i] = beta[slot].exp();
        } else {
            out.normalised[i] = y - cov_part;
            out.level[i] = beta[slot];
        }
    }
    // Each unit's own scale: units differ in how well one log determines a parameter, so
    // the pooled variance is rescaled by the unit's baseline ratio r²/Var, shrunk towards 1
    // with the weight of UNIT_PRIOR estimates (the CUSUM threshold is simulated with the
    // same estimator, [`super::cusum::threshold_estimated`]).
    let own = if d.per_unit { 1 + nc * d.degree } else { 1 };
    for u in 0..units {
        let idx: Vec<usize> = base
            .iter()
            .copied()
            .filter(|&i| samples[i].unit == u && out.residual[i].is_finite())
            .collect();
        let m = idx.len();
        if m <= own {
            continue;
        }
        let q = idx.iter().map(|&i| out.residual[i].powi(2) / out.variance[i]).sum::<f64>()
            / (m - own) as f64;
        let phi = (UNIT_PRIOR + m as f64 * q) / (UNIT_PRIOR + m as f64);
        for (i, s) in samples.iter().enumerate() {
            if s.unit == u && out.variance[i].is_finite() {
                out.variance[i] *= phi;
            }
        }
    }
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
