//! Fit reports: every parameter's value, standard error, 95 % interval and whether the
//! data determine it (with the reason when they do not), the correlation matrix, the fit
//! quality and what the optimiser did. Serialises to the `fit.json` layout.

mod notes;
mod table;

pub use notes::{Explanation, REL_SE_LIMIT};
pub(crate) use notes::{Judgement, free_estimate};

use serde::Serialize;
use serde::ser::{SerializeMap, Serializer};

/// One parameter in a report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Estimate {
    /// Fitted (or fixed) value [registry unit].
    pub value: f64,
    /// Registry unit.
    pub unit: &'static str,
    /// Standard error [registry unit]; `null` when fixed or when the information about
    /// the parameter is singular.
    pub std_error: Option<f64>,
    /// 95 % confidence interval `[lo, hi]` (Student's t on the residual's degrees of
    /// freedom); `null` when the standard error is.
    pub ci95: Option<[f64; 2]>,
    /// Whether the data determine the parameter.
    pub determined: bool,
    /// Whether the parameter was held fixed (not fitted).
    pub fixed: bool,
    /// Why the parameter is not determined, or how it was held.
    pub note: Option<String>,
}

impl Estimate {
    /// A parameter held at `value` [`unit`] rather than fitted; `why` says how it was
    /// chosen (e.g. "fixed", "from the static stage").
    pub fn held(value: f64, unit: &'static str, why: &str) -> Self {
        Estimate {
            value,
            unit,
            std_error: None,
            ci95: None,
            determined: false,
            fixed: true,
            note: Some(format!("held at {value} {unit} ({why}), not fitted")),
        }
    }

    /// A parameter `name` on its bound `value` [`unit`] because the fit is best there: not
    /// held by the user, not determined as an interior value (no standard error at a bound).
    pub fn on_bound(name: &str, value: f64, unit: &'static str) -> Self {
        Estimate {
            fixed: false,
            note: Some(format!(
                "on its bound {value} {unit}: the fit is best with {name} held there (the data favour a smaller value than the range allows), so it has no standard error"
            )),
            ..Self::held(value, unit, "")
        }
    }
}

/// Parameters in a fixed order, serialised as a JSON object keyed by registry name.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Parameters(pub Vec<(String, Estimate)>);

impl Parameters {
    /// The estimate of `name`, if present.
    pub fn get(&self, name: &str) -> Option<&Estimate> {
        self.0.iter().find(|(n, _)| n == name).map(|(_, e)| e)
    }
    /// Names in order.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.0.iter().map(|(n, _)| n.as_str())
    }
}

impl Serialize for Parameters {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(self.0.len()))?;
        for (name, est) in &self.0 {
            map.serialize_entry(name, est)?;
        }
        map.end()
    }
}

/// Correlation matrix of the free parameters.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Correlation {
    /// Row and column names.
    pub names: Vec<String>,
    /// Entries; `null` where undefined (singular information).
    pub matrix: Vec<Vec<Option<f64>>>,
}

/// The global search over the nonlinear parameter.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SearchSummary {
    /// Parameter searched.
    pub parameter: String,
    /// Searched range `[lo, hi]` [registry unit] (logarithmic grid).
    pub range: [f64; 2],
    /// Grid points.
    pub grid_points: usize,
    /// Grid minima refined by Brent's method.
    pub starts: usize,
}

/// Where a fit's data came from (filled in by the caller that loaded it).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DataSource {
    /// Role of the data set: `hysteresis`, `steady` or `transient`.
    pub role: String,
    /// File it was read from.
    pub file: String,
    /// Columns read, in the order t/omega, theta/omega, torque as applicable.
    pub columns: Vec<String>,
    /// What was done to the columns before fitting (unit scaling, sign, speed derived
    /// from position), in order.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub preprocessing: Vec<String>,
}

/// The outcome of a fit (or of one stage of a staged fit).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FitReport {
    /// Which fit: `hysteresis`, `friction-static`, `friction-dynamic` or `friction`.
    pub fit: String,
    /// The stiffness law of a hysteresis fit: `memory`, `maxwell-slip` or `bouc-wen`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub law: Option<String>,
    /// The data sets fitted, when the caller recorded them.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub data: Vec<DataSource>,
    /// Every parameter of the fit, under its registry name.
    pub parameters: Parameters,
    /// RMS residual [output unit].
    pub rms: f64,
    /// Coefficient of determination R² [–].
    pub r2: f64,
    /// Optimiser iterations (Brent iterations over all starts).
    pub iterations: u64,
    /// Why the optimiser stopped.
    pub termination: String,
    /// Correlation matrix of the free parameters.
    pub correlation: Correlation,
    /// Samples used.
    pub samples: usize,
    /// Residual degrees of freedom n − p.
    pub dof: usize,
    /// Residual standard deviation √(RSS/(n − p)) [output unit]: the noise estimate.
    pub noise_std: f64,
    /// Model evaluations (cost function calls).
    pub evaluations: u64,
    /// The global search, when a nonlinear parameter was free.
    pub search: Option<SearchSummary>,
    /// For a staged fit, each stage's own report, in order.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub stages: Vec<FitReport>,
    /// Remarks on how the numbers were obtained (held parameters, propagated errors).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub remarks: Vec<String>,
    /// Wall time of the fit [s].
    pub wall_time_s: f64,
    /// Hysteresis fits: the loop energy per cycle of each amplitude block of the record,
    /// of the fitted law and of the measured torque.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub loop_energy: Vec<crate::stiffness::cycles::LoopBlock>,
    /// Joint friction fits: the values of the free nonlinear parameters at each start of
    /// the Levenberg–Marquardt refinement, so the fit can be reproduced elsewhere.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub refinement_starts: Vec<std::collections::BTreeMap<String, f64>>,
    /// Joint friction fits: how the refinement from each start ended (its residual sum of
    /// squares and iterations, or why it was stopped early), in `refinement_starts` order.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub refinement_ends: Vec<String>,
    /// The nested law's own fit, where a richer law started from it (the asymmetric
    /// friction fit: the symmetric law, levels equal on both sides, with the same offset),
    /// so the two laws can be compared on one record (RMS, BIC) from one run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nested: Option<Box<FitReport>>,
}

impl FitReport {
    /// Pretty JSON in the `fit.json` layout (parameters in fit order).
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a fit report always serialises")
    }

    /// The names of parameters the data do not determine (fixed ones excluded).
    pub fn undetermined(&self) -> Vec<&str> {
        self.parameters
            .0
            .iter()
            .filter(|(_, e)| !e.determined && !e.fixed)
            .map(|(n, _)| n.as_str())
            .collect()
    }
}
