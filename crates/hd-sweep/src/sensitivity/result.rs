//! The result table of a sensitivity analysis: one row per (parameter, metric).

use super::design::SensitivityMethod;
use serde::{Deserialize, Serialize};

/// Sensitivity of one metric to one parameter.
///
/// Sobol' rows fill `S1…ST_hi` and leave `mu`, `mu_star`, `sigma` NaN; Morris rows do the
/// opposite. NaN means "not computed or undefined", never zero. Serialised field names are
/// the Parquet column names (`S1`, `S1_lo`, …, `n_dropped`, `note`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SensitivityRow {
    /// `sobol` or `morris`.
    pub method: SensitivityMethod,
    /// Parameter name.
    pub parameter: String,
    /// Metric name.
    pub metric: String,
    /// First-order index [-] (Saltelli 2010 estimator).
    #[serde(rename = "S1")]
    pub s1: f64,
    /// Lower bound of the S1 bootstrap interval [-].
    #[serde(rename = "S1_lo")]
    pub s1_lo: f64,
    /// Upper bound of the S1 bootstrap interval [-].
    #[serde(rename = "S1_hi")]
    pub s1_hi: f64,
    /// Total index [-] (Jansen estimator).
    #[serde(rename = "ST")]
    pub st: f64,
    /// Lower bound of the ST bootstrap interval [-].
    #[serde(rename = "ST_lo")]
    pub st_lo: f64,
    /// Upper bound of the ST bootstrap interval [-].
    #[serde(rename = "ST_hi")]
    pub st_hi: f64,
    /// Mean elementary effect [metric unit per parameter range].
    pub mu: f64,
    /// Mean absolute elementary effect [metric unit per parameter range].
    pub mu_star: f64,
    /// Standard deviation of the elementary effects [metric unit per parameter range].
    pub sigma: f64,
    /// Base rows (Sobol') or trajectories (Morris) used for this metric.
    pub n_used: usize,
    /// Base rows or trajectories dropped because a run failed or was missing.
    pub n_dropped: usize,
    /// Why values are NaN, or how many rows were dropped; `None` when all is well.
    pub note: Option<String>,
}

impl SensitivityRow {
    /// A row for `method`, `parameter`, `metric` with every number NaN and no counts.
    pub fn empty(method: SensitivityMethod, parameter: &str, metric: &str) -> Self {
        Self {
            method,
            parameter: parameter.to_string(),
            metric: metric.to_string(),
            s1: f64::NAN,
            s1_lo: f64::NAN,
            s1_hi: f64::NAN,
            st: f64::NAN,
            st_lo: f64::NAN,
            st_hi: f64::NAN,
            mu: f64::NAN,
            mu_star: f64::NAN,
            sigma: f64::NAN,
            n_used: 0,
            n_dropped: 0,
            note: None,
        }
    }
}
