//! The study file as written (serde structures with source spans). See studies/README.md
//! for the format; [`crate::parse`] checks it into a [`crate::Study`].

use hd_model::{MetricSettings, SolverOptions};
use serde::Deserialize;
use std::collections::BTreeMap;
use toml::Spanned;

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudySpec {
    /// Study name (used in reports and file names).
    pub name: Spanned<String>,
    /// One-paragraph description for the report.
    #[serde(default)]
    pub description: String,
    /// Settings shared by every part.
    #[serde(default)]
    pub base: BaseSpec,
    /// Armature-voltage input shared by every part (a part may replace it).
    pub input: Option<Spanned<InputSpec>>,
    /// Integrator settings.
    #[serde(default)]
    pub solver: SolverOptions,
    /// Closed-loop controller shared by every part (`[controller]`, with
    /// `[controller.model]` for the controller model's parameters).
    pub controller: Option<hd_model::ControllerConfig>,
    /// Metric settings and the metrics to keep.
    #[serde(default)]
    pub metrics: MetricsSpec,
    /// Whether and how to keep traces.
    #[serde(default)]
    pub traces: TraceSpec,
    /// Axes of a single-part study.
    #[serde(default)]
    pub axis: Vec<Spanned<AxisSpec>>,
    /// Random design of a single-part study.
    pub sample: Option<Spanned<SampleSpec>>,
    /// Several parts, each with its own axes (instead of top-level `axis`/`sample`).
    #[serde(default)]
    pub part: Vec<Spanned<PartSpec>>,
    /// Paper-versus-model comparisons for the report.
    #[serde(default)]
    pub compare: Vec<Spanned<CompareSpec>>,
}

/// Settings shared by every run (a part may override them).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaseSpec {
    /// Variant: linear, damped or full (default full).
    pub variant: Option<Spanned<String>>,
    /// Stiffness law of the full variant: memory (default), maxwell-slip, bouc-wen or
    /// catalogue.
    pub stiffness: Option<Spanned<String>>,
    /// Parameter file (TOML), relative to the study file.
    pub params_file: Option<Spanned<String>>,
    /// Parameter overrides by registry name.
    #[serde(default)]
    pub set: BTreeMap<Spanned<String>, Spanned<f64>>,
    /// Simulated time [s] (default 0.2).
    pub t_end: Option<Spanned<f64>>,
    /// Simulated time in drive cycles (sine input): t_end = cycles / freq per run.
    pub t_end_cycles: Option<Spanned<f64>>,
    /// Friction speed: motor or deflection.
    pub friction_velocity: Option<Spanned<String>>,
}

/// An input as written.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InputSpec {
    /// sine, step, constant, chirp, stepped_sine or recorded.
    pub kind: Spanned<String>,
    /// Amplitude or level [V].
    pub voltage: Option<f64>,
    /// Frequency [Hz] (sine).
    pub freq: Option<f64>,
    /// Step time [s] (step).
    pub t0: Option<f64>,
    /// Start and end frequency [Hz] (chirp).
    pub f0: Option<f64>,
    /// End frequency [Hz] (chirp).
    pub f1: Option<f64>,
    /// Sweep duration [s] (chirp).
    pub duration: Option<f64>,
    /// Frequencies [Hz] (stepped_sine).
    pub freqs: Option<Vec<f64>>,
    /// Time per frequency [s] (stepped_sine).
    pub dwell: Option<f64>,
    /// Recorded profile file (CSV/Parquet, columns t, u), relative to the study file.
    pub file: Option<String>,
}

/// Metric settings as written.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MetricsSpec {
    /// Metrics to keep as columns (default: all).
    pub keep: Option<Vec<Spanned<String>>>,
    /// Settings of the metric computation.
    #[serde(flatten)]
    pub settings: MetricSettingsSpec,
}

/// Optional metric settings (defaults from [`MetricSettings`]).
#[derive(Debug, Default, Deserialize)]
pub struct MetricSettingsSpec {
    /// Whole cycles used by periodic metrics.
    pub cycles: Option<usize>,
    /// Samples per cycle for the ripple fit.
    pub samples_per_cycle: Option<usize>,
    /// Samples over the run for step/limit-cycle metrics.
    pub run_samples: Option<usize>,
    /// Final-window fraction.
    pub final_fraction: Option<f64>,
    /// Settling band fraction.
    pub settle_band: Option<f64>,
    /// Window after each reversal of the reference speed for `reversal_peak` [s].
    pub reversal_window: Option<f64>,
}

impl MetricSettingsSpec {
    /// Apply to the defaults.
    pub fn resolve(&self) -> MetricSettings {
        let d = MetricSettings::default();
        MetricSettings {
            cycles: self.cycles.unwrap_or(d.cycles),
            samples_per_cycle: self.samples_per_cycle.unwrap_or(d.samples_per_cycle),
            run_samples: self.run_samples.unwrap_or(d.run_samples),
            final_fraction: self.final_fraction.unwrap_or(d.final_fraction),
            settle_band: self.settle_band.unwrap_or(d.settle_band),
            reversal_window: self.reversal_window.unwrap_or(d.reversal_window),
        }
    }
}

/// Trace keeping (opt-in).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TraceSpec {
    /// Keep traces of every run in traces.parquet.
    #[serde(default)]
    pub keep: bool,
    /// Keep every n-th output sample (default 1).
    pub decimate: Option<usize>,
    /// Output sampling interval [s] (default automatic).
    pub dt_out: Option<f64>,
}

/// One axis of a grid.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisSpec {
    /// A registry parameter, or `voltage`, `freq`, `variant`, `friction_scale`.
    pub name: Spanned<String>,
    /// Explicit values.
    pub values: Option<Vec<toml::Value>>,
    /// Evenly spaced values.
    pub linspace: Option<RangeSpec>,
    /// Logarithmically spaced values.
    pub logspace: Option<RangeSpec>,
    /// Axes with the same zip label advance together instead of forming a product.
    pub zip: Option<String>,
}

/// `{ start, stop, num }`.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RangeSpec {
    /// First value.
    pub start: f64,
    /// Last value.
    pub stop: f64,
    /// Number of values (≥ 1).
    pub num: usize,
}

/// A random, screening or variance-based design (`[sample]`).
///
/// Which fields apply depends on `method`:
/// - `lhs`, `random`: `n` points, `seed` (default 0);
/// - `sobol`: `n` base samples N, giving N·(d + 2) runs for d parameters; `seed` applies a
///   seeded digital shift to the Sobol' sequence (without it the plain sequence is used);
/// - `morris`: `trajectories` r, giving r·(d + 1) runs; `levels` p (even, default 4);
///   `seed` (default 0) draws the trajectories.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SampleSpec {
    /// lhs (Latin hypercube), random, sobol (Saltelli design) or morris (trajectories).
    pub method: Spanned<String>,
    /// Number of points (lhs, random) or of base samples (sobol).
    pub n: Option<Spanned<usize>>,
    /// Number of Morris trajectories.
    pub trajectories: Option<Spanned<usize>>,
    /// Morris grid levels (even, ≥ 2; default 4).
    pub levels: Option<Spanned<usize>>,
    /// Seed of the random generator (see the method list above).
    pub seed: Option<Spanned<u64>>,
    /// The sampled parameters with bounds.
    pub param: Vec<Spanned<BoundSpec>>,
}

/// A sampled parameter's bounds.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundSpec {
    /// Parameter (registry name, `voltage`, `freq` or `friction_scale`).
    pub name: Spanned<String>,
    /// Lower bound, in the parameter's unit.
    pub lo: Spanned<f64>,
    /// Upper bound, in the parameter's unit.
    pub hi: Spanned<f64>,
    /// Sample uniformly in log space (needs lo > 0).
    #[serde(default)]
    pub log: bool,
}

/// One part of a multi-part study.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartSpec {
    /// Part name (unique within the study).
    pub name: Spanned<String>,
    /// Variant for this part.
    pub variant: Option<Spanned<String>>,
    /// Stiffness law for this part.
    pub stiffness: Option<Spanned<String>>,
    /// Extra parameter overrides for this part.
    #[serde(default)]
    pub set: BTreeMap<Spanned<String>, Spanned<f64>>,
    /// Input replacing the study's.
    pub input: Option<Spanned<InputSpec>>,
    /// Simulated time [s] for this part.
    pub t_end: Option<Spanned<f64>>,
    /// Simulated time in drive cycles for this part (sine input).
    pub t_end_cycles: Option<Spanned<f64>>,
    /// The part's axes.
    #[serde(default)]
    pub axis: Vec<Spanned<AxisSpec>>,
    /// The part's random design.
    pub sample: Option<Spanned<SampleSpec>>,
}

/// A statement of the seed paper to check against the model in the report.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompareSpec {
    /// The part whose grid is used.
    pub part: String,
    /// The varied axis.
    pub axis: String,
    /// increase or decrease.
    pub direction: String,
    /// The metric whose change is judged.
    pub metric: String,
    /// What the paper says, in a few words.
    pub paper: String,
    /// The direction the paper implies: up, down, flat, up_or_flat or down_or_flat.
    pub expect: String,
    /// The variant whose runs are compared (needed when the part sweeps variants).
    pub variant: Option<String>,
}
