//! A checked study and its expansion into runs.

use crate::axis::Value;
use crate::design::{Axis, Sample};
use crate::plan::RunPlan;
use crate::sensitivity::PointTag;
use crate::spec::CompareSpec;
use hd_model::SimConfig;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;
use std::sync::Arc;

/// A checked study: everything needed to expand and run it.
#[derive(Clone, Debug)]
pub struct Study {
    /// Study name.
    pub name: String,
    /// Description for the report.
    pub description: String,
    /// The study file.
    pub file: PathBuf,
    /// Its parts (one for a single-part study).
    pub parts: Vec<Part>,
    /// Metric columns to keep, in output order.
    pub keep_metrics: Vec<&'static str>,
    /// Whether to keep traces, and the decimation.
    pub traces: TraceSettings,
    /// Paper-versus-model statements for the report.
    pub compare: Vec<CompareSpec>,
}

/// Trace keeping.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TraceSettings {
    /// Keep traces.
    pub keep: bool,
    /// Keep every n-th sample.
    pub decimate: usize,
}

/// One part: a base configuration and the points to run it at.
#[derive(Clone, Debug)]
pub struct Part {
    /// Part name.
    pub name: String,
    /// Configuration before the point's values are applied.
    pub base: SimConfig,
    /// Grid axes.
    pub axes: Vec<Axis>,
    /// Sampled design: a random one (lhs, random) is combined with the grid as a product;
    /// a sensitivity design (sobol, morris) is never combined with grid axes.
    pub sample: Option<Sample>,
    /// Simulated time in drive cycles (overrides `base.t_end` per run).
    pub t_end_cycles: Option<f64>,
}

/// One run of the expanded study.
#[derive(Clone, Debug, Serialize)]
pub struct RunSpec {
    /// Stable identifier: a hash of the part name and the full configuration.
    pub run_id: String,
    /// Position in the expanded study (0-based).
    pub index: usize,
    /// Part name (shared by the part's runs).
    #[serde(serialize_with = "shared_str")]
    pub part: Arc<str>,
    /// The swept names and values.
    pub swept: Vec<(&'static str, Value)>,
    /// The configuration to simulate.
    pub config: SimConfig,
    /// The point's place in a sobol or morris design, if the part has one.
    pub design: Option<RunDesign>,
    /// Parameters of every sobol or morris design in the study, in order of appearance
    /// (the same list for every run of a study): the `u_<name>` columns of the runs table.
    #[serde(skip)]
    pub design_names: Arc<[&'static str]>,
}

/// Where a run sits in a global-sensitivity design.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunDesign {
    /// Saltelli base row and block, or Morris trajectory and step.
    pub tag: PointTag,
    /// The design's parameter names, in the order of `unit`.
    pub names: Vec<&'static str>,
    /// Unit-cube coordinates in [0, 1], one per name.
    pub unit: Vec<f64>,
}

impl RunDesign {
    /// The unit coordinate of a parameter, if the design samples it.
    pub fn unit_of(&self, name: &str) -> Option<f64> {
        self.names.iter().position(|n| *n == name).map(|k| self.unit[k])
    }
}

impl Part {
    /// Names of the parameters of the part's sobol or morris design (empty without one).
    pub fn design_names(&self) -> Vec<&'static str> {
        match &self.sample {
            Some(s) if s.design.is_some() => s.bounds.iter().map(|b| b.knob.name()).collect(),
            _ => Vec::new(),
        }
    }

    /// Names of the swept quantities, in column order.
    pub fn swept_names(&self) -> Vec<&'static str> {
        let mut names: Vec<&'static str> = self.axes.iter().map(|a| a.knob.name()).collect();
        if let Some(s) = &self.sample {
            names.extend(s.bounds.iter().map(|b| b.knob.name()));
        }
        names
    }
}

impl Study {
    /// Every run, in order; `index` counts across parts. For small studies and tests: a
    /// sweep generates its runs by index with [`RunPlan`] instead.
    ///
    /// # Panics
    /// If the study has more than [`crate::plan::MAX_RUNS`] runs.
    pub fn expand(&self) -> Vec<RunSpec> {
        let plan = RunPlan::new(self).unwrap_or_else(|e| panic!("{e}"));
        (0..plan.len()).map(|i| plan.spec(i)).collect()
    }

    /// Parameters of all sobol and morris designs, without repeats, in order of appearance.
    pub fn design_names(&self) -> Vec<&'static str> {
        let mut out: Vec<&'static str> = Vec::new();
        for n in self.parts.iter().flat_map(Part::design_names) {
            if !out.contains(&n) {
                out.push(n);
            }
        }
        out
    }

    /// Whether any part holds a sobol or morris design.
    pub fn has_sensitivity_design(&self) -> bool {
        self.parts.iter().any(|p| p.sample.as_ref().is_some_and(|s| s.design.is_some()))
    }

    /// All swept names over all parts, without repeats, in order of appearance.
    pub fn swept_names(&self) -> Vec<&'static str> {
        let mut out: Vec<&'static str> = Vec::new();
        for p in &self.parts {
            for n in p.swept_names() {
                if !out.contains(&n) {
                    out.push(n);
                }
            }
        }
        out
    }
}

/// Serialize a shared string as a plain string.
pub(crate) fn shared_str<S: serde::Serializer>(v: &Arc<str>, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(v)
}

/// 16 hex digits of the 64-bit FNV-1a hash of the part name and the configuration's JSON.
/// The JSON is hashed as it is written, never held as text.
pub fn run_id(part: &str, cfg: &SimConfig) -> String {
    let mut h = Fnv(0xcbf2_9ce4_8422_2325);
    h.feed(part.as_bytes());
    h.feed(&[0]);
    // Writing into the hash cannot fail; a configuration that cannot be written as JSON
    // hashes as what was written of it (as the text form gave the empty string's hash).
    let _ = serde_json::to_writer(&mut h, cfg);
    format!("{:016x}", h.0)
}

/// The 64-bit FNV-1a hash, fed by `io::Write`.
struct Fnv(u64);

impl Fnv {
    fn feed(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }
}

impl std::io::Write for Fnv {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.feed(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}
