//! The result of one run: one row of `runs.parquet`.

use crate::axis::Value;
use crate::study::{RunDesign, RunSpec};
use hd_model::{Metrics, Params, SimError, SimOutput, SolverStats, Trace, Variant};
use serde::Serialize;
use std::sync::Arc;

/// Whether a run finished.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum RunStatus {
    /// The run finished and its metrics are defined where they apply.
    Ok,
    /// The run failed; `error` says why and every metric is null.
    Failed,
}

impl RunStatus {
    /// The text written to `runs.parquet`.
    pub fn as_str(self) -> &'static str {
        match self {
            RunStatus::Ok => "ok",
            RunStatus::Failed => "failed",
        }
    }
}

/// Outcome of one run.
#[derive(Clone, Debug, Serialize)]
pub struct RunRow {
    /// Stable run identifier.
    pub run_id: String,
    /// Position in the expanded study.
    pub run_index: usize,
    /// Part name (shared by the part's runs).
    #[serde(serialize_with = "crate::study::shared_str")]
    pub part: Arc<str>,
    /// Variant simulated.
    pub variant: Variant,
    /// Stiffness law of the full variant.
    pub stiffness: hd_model::HystLaw,
    /// Swept names and values.
    pub swept: Vec<(&'static str, Value)>,
    /// Every parameter used.
    pub params: Params,
    /// Input amplitude [V] (NaN for recorded inputs).
    pub voltage: f64,
    /// Drive frequency [Hz]: the input's open loop, the reference's closed loop (NaN if
    /// not periodic).
    pub freq: f64,
    /// The controller of a closed-loop run.
    pub controller: Option<hd_model::ControllerConfig>,
    /// Metrics (all NaN for a failed run).
    pub metrics: Metrics,
    /// Whether the run finished.
    pub status: RunStatus,
    /// The error of a failed run.
    pub error: Option<String>,
    /// Solver work (zeros for a failed run).
    pub stats: SolverStats,
    /// Wall time of the integration [s].
    pub wall_time: f64,
    /// The trace, if kept.
    #[serde(skip)]
    pub trace: Option<Trace>,
    /// Place in a sobol or morris design (tag and unit coordinates), if any.
    pub design: Option<RunDesign>,
    /// The study's design parameters (the `u_<name>` columns; empty without a design).
    #[serde(skip)]
    pub design_names: Arc<[&'static str]>,
}

impl RunRow {
    /// Build the row of a run from its outcome.
    pub fn new(spec: &RunSpec, outcome: Result<SimOutput, SimError>, decimate: usize) -> RunRow {
        let cfg = &spec.config;
        let (voltage, freq) = match &cfg.input {
            hd_model::Input::Sine { amplitude, freq } => (*amplitude, *freq),
            hd_model::Input::Step { amplitude, .. }
            | hd_model::Input::Constant { amplitude }
            | hd_model::Input::Chirp { amplitude, .. }
            | hd_model::Input::SteppedSine { amplitude, .. } => (*amplitude, f64::NAN),
            hd_model::Input::Recorded(_) => (f64::NAN, f64::NAN),
        };
        // Closed loop: the drive frequency is the reference's.
        let freq =
            if cfg.controller.is_some() { cfg.drive_frequency().unwrap_or(f64::NAN) } else { freq };
        let base = RunRow {
            run_id: spec.run_id.clone(),
            run_index: spec.index,
            part: spec.part.clone(),
            variant: cfg.variant,
            stiffness: cfg.stiffness,
            swept: spec.swept.clone(),
            params: cfg.params.clone(),
            voltage,
            freq,
            controller: cfg.controller.clone(),
            metrics: Metrics::undefined(),
            status: RunStatus::Ok,
            error: None,
            stats: SolverStats::default(),
            wall_time: 0.0,
            trace: None,
            design: spec.design.clone(),
            design_names: spec.design_names.clone(),
        };
        match outcome {
            Ok(out) => RunRow {
                metrics: out.metrics,
                stats: out.stats,
                wall_time: out.wall_time,
                trace: out.trace.map(|t| if decimate > 1 { t.decimate(decimate) } else { t }),
                ..base
            },
            Err(e) => RunRow { status: RunStatus::Failed, error: Some(e.to_string()), ..base },
        }
    }

    /// A failed row for a run that panicked.
    pub fn panicked(spec: &RunSpec, message: String) -> RunRow {
        let mut row = RunRow::new(spec, Err(SimError::Panic(message)), 1);
        row.status = RunStatus::Failed;
        row
    }
}
