//! First-order and total Sobol' indices from the outputs of a Saltelli design, with
//! bootstrap intervals.
//!
//! With `f_A`, `f_B`, `f_ABi` the outputs at row `j` of A, B and A_B^(i), and `V` the
//! variance of all `f_A` and `f_B` values together:
//! - first order, **Saltelli 2010** estimator (Saltelli et al., "Variance based
//!   sensitivity analysis of model output. Design and estimator for the total sensitivity
//!   index", Comput. Phys. Commun. 181 (2010), Table 2 (b)):
//!   `S_i = (1/N) Σ_j f_B,j (f_ABi,j − f_A,j) / V`;
//! - total, **Jansen** estimator (Jansen, "Analysis of variance designs for model output",
//!   Comput. Phys. Commun. 117 (1999); Table 2 (f) of Saltelli 2010):
//!   `ST_i = (1/2N) Σ_j (f_A,j − f_ABi,j)² / V`.
//!
//! Outputs are centred on the mean of the usable `f_A`, `f_B` values first. Both estimators
//! are unbiased under any constant shift, but the first-order one is much less noisy for
//! outputs far from zero once centred.
//!
//! **Intervals.** Percentile bootstrap: the usable base rows are resampled with
//! replacement (ChaCha8 seeded by [`SobolOptions::seed`]), both indices are re-estimated
//! for every resample, and the equal-tailed quantiles at the chosen confidence are kept.
//!
//! **Failed runs.** A base row is usable only if every one of its `d + 2` outputs is finite;
//! otherwise the whole row is dropped (for this metric), so all indices of a metric use
//! the same rows and failures cannot bias one index more than another. Dropped rows are
//! counted; below [`SobolOptions::min_base_rows`] usable rows the indices are NaN with a note.

use super::stats::percentile_interval;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// Settings of the Sobol' estimators.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SobolOptions {
    /// Bootstrap resamples for the intervals; 0 skips them (bounds NaN). Default 1000.
    pub bootstrap: usize,
    /// Confidence level of the intervals, in (0, 1). Default 0.95.
    pub confidence: f64,
    /// Seed of the bootstrap resampling. Default 0.
    pub seed: u64,
    /// Fewest usable base rows for which indices are reported; fewer gives NaN with a
    /// note. Default 16.
    pub min_base_rows: usize,
}

impl Default for SobolOptions {
    fn default() -> Self {
        Self { bootstrap: 1000, confidence: 0.95, seed: 0, min_base_rows: 16 }
    }
}

/// Outputs of one metric over a Saltelli design, arranged by base row. NaN marks a failed
/// (or missing) run.
#[derive(Clone, Debug, PartialEq)]
pub struct SaltelliOutputs {
    /// `f_A,j`, one per base row.
    pub a: Vec<f64>,
    /// `f_B,j`, one per base row.
    pub b: Vec<f64>,
    /// `ab[i][j] = f_ABi,j`: one vector per parameter, one entry per base row.
    pub ab: Vec<Vec<f64>>,
}

impl SaltelliOutputs {
    /// Number of base rows.
    pub fn base_rows(&self) -> usize {
        self.a.len()
    }

    /// Number of parameters.
    pub fn dims(&self) -> usize {
        self.ab.len()
    }

    /// Whether every output of base row `j` is finite.
    fn row_ok(&self, j: usize) -> bool {
        self.a[j].is_finite() && self.b[j].is_finite() && self.ab.iter().all(|c| c[j].is_finite())
    }
}

/// One index with its bootstrap interval.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct IndexEstimate {
    /// Point estimate [-].
    pub value: f64,
    /// Lower interval bound [-].
    pub lo: f64,
    /// Upper interval bound [-].
    pub hi: f64,
}

impl IndexEstimate {
    const NAN: Self = Self { value: f64::NAN, lo: f64::NAN, hi: f64::NAN };
}

/// First-order and total indices of one metric, per parameter.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SobolEstimate {
    /// First-order indices `S_i`, one per parameter.
    pub s1: Vec<IndexEstimate>,
    /// Total indices `ST_i`, one per parameter.
    pub st: Vec<IndexEstimate>,
    /// Base rows used.
    pub n_used: usize,
    /// Base rows dropped because one of their runs failed.
    pub n_dropped: usize,
    /// Why indices are NaN, or other caveats; `None` when all is well.
    pub note: Option<String>,
}

/// Estimate first-order and total indices from `outputs`; see the module docs for the
/// estimators, the intervals and the handling of failed runs.
pub fn sobol_indices(outputs: &SaltelliOutputs, options: &SobolOptions) -> SobolEstimate {
    let (n, d) = (outputs.base_rows(), outputs.dims());
    let rows: Vec<usize> = (0..n).filter(|&j| outputs.row_ok(j)).collect();
    let n_dropped = n - rows.len();
    let nan = |note: String| SobolEstimate {
        s1: vec![IndexEstimate::NAN; d],
        st: vec![IndexEstimate::NAN; d],
        n_used: rows.len(),
        n_dropped,
        note: Some(note),
    };
    if rows.len() < options.min_base_rows.max(2) {
        return nan(format!(
            "only {} of {n} base rows usable (need at least {}); {n_dropped} dropped for failed runs",
            rows.len(),
            options.min_base_rows.max(2)
        ));
    }
    let centre =
        rows.iter().map(|&j| outputs.a[j] + outputs.b[j]).sum::<f64>() / (2 * rows.len()) as f64;
    let Some((s1, st)) = point_estimates(outputs, centre, &rows) else {
        return nan("output variance is zero: the metric does not vary over the design".into());
    };
    let mut boot_s1 = vec![Vec::with_capacity(options.bootstrap); d];
    let mut boot_st = vec![Vec::with_capacity(options.bootstrap); d];
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    let mut sample = vec![0usize; rows.len()];
    for _ in 0..options.bootstrap {
        for s in &mut sample {
            *s = rows[rng.random_range(0..rows.len())];
        }
        if let Some((b1, bt)) = point_estimates(outputs, centre, &sample) {
            for i in 0..d {
                boot_s1[i].push(b1[i]);
                boot_st[i].push(bt[i]);
            }
        }
    }
    let with_interval = |value: f64, samples: &mut Vec<f64>| {
        let (lo, hi) = percentile_interval(samples, options.confidence);
        IndexEstimate { value, lo, hi }
    };
    SobolEstimate {
        s1: s1.iter().zip(&mut boot_s1).map(|(&v, b)| with_interval(v, b)).collect(),
        st: st.iter().zip(&mut boot_st).map(|(&v, b)| with_interval(v, b)).collect(),
        n_used: rows.len(),
        n_dropped,
        note: (n_dropped > 0)
            .then(|| format!("{n_dropped} of {n} base rows dropped for failed runs")),
    }
}

/// `(S1, ST)` per parameter over the base rows `rows` (repeats allowed); `None` when the
/// output variance over these rows is zero.
fn point_estimates(
    o: &SaltelliOutputs,
    centre: f64,
    rows: &[usize],
) -> Option<(Vec<f64>, Vec<f64>)> {
    let m = rows.len() as f64;
    let mut sum = 0.0;
    let mut sum_sq = 0.0;
    for &j in rows {
        let (a, b) = (o.a[j] - centre, o.b[j] - centre);
        sum += a + b;
        sum_sq += a * a + b * b;
    }
    let mean = sum / (2.0 * m);
    let var = sum_sq / (2.0 * m) - mean * mean;
    if var.is_nan() || var <= 0.0 {
        return None;
    }
    let mut s1 = Vec::with_capacity(o.dims());
    let mut st = Vec::with_capacity(o.dims());
    for col in &o.ab {
        let mut first = 0.0;
        let mut total = 0.0;
        for &j in rows {
            let (a, b, ab) = (o.a[j] - centre, o.b[j] - centre, col[j] - centre);
            first += b * (ab - a);
            total += (a - ab) * (a - ab);
        }
        s1.push(first / m / var);
        st.push(0.5 * total / m / var);
    }
    Some((s1, st))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y = x0 + 2·x1 on a tiny hand-made design where the indices are exact.
    fn additive_outputs() -> SaltelliOutputs {
        let a = [[0.1, 0.7], [0.4, 0.2], [0.9, 0.5], [0.6, 0.95]];
        let b = [[0.8, 0.3], [0.05, 0.6], [0.3, 0.1], [0.7, 0.45]];
        let f = |x: [f64; 2]| x[0] + 2.0 * x[1];
        let ab = |i: usize| {
            (0..4)
                .map(|j| {
                    let mut x = a[j];
                    x[i] = b[j][i];
                    f(x)
                })
                .collect()
        };
        SaltelliOutputs {
            a: a.iter().map(|&x| f(x)).collect(),
            b: b.iter().map(|&x| f(x)).collect(),
            ab: vec![ab(0), ab(1)],
        }
    }

    #[test]
    fn drops_rows_with_failures_and_reports_them() {
        let mut o = additive_outputs();
        o.ab[1][2] = f64::NAN;
        let opts = SobolOptions { min_base_rows: 2, bootstrap: 50, ..Default::default() };
        let est = sobol_indices(&o, &opts);
        assert_eq!((est.n_used, est.n_dropped), (3, 1));
        assert!(est.note.unwrap().contains("1 of 4"));
        assert!(est.s1.iter().all(|e| e.value.is_finite()));
    }

    #[test]
    fn too_few_rows_give_nan_with_reason() {
        let est = sobol_indices(&additive_outputs(), &SobolOptions::default());
        assert!(est.s1[0].value.is_nan() && est.st[1].hi.is_nan());
        assert!(est.note.unwrap().contains("need at least 16"));
    }

    #[test]
    fn constant_output_is_reported_not_divided_by_zero() {
        let o = SaltelliOutputs { a: vec![1.0; 20], b: vec![1.0; 20], ab: vec![vec![1.0; 20]] };
        let est = sobol_indices(&o, &SobolOptions::default());
        assert!(est.s1[0].value.is_nan());
        assert!(est.note.unwrap().contains("variance is zero"));
    }
}
