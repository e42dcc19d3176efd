//! `study.json`: the expanded study as written beside its results, and read back (typed)
//! by the sensitivity analysis and `hdw report`. It lists every run of the whole study, so
//! each shard's copy is the same apart from `shard`.

use crate::axis::Value;
use crate::study::{RunSpec, Study, TraceSettings};
use hd_model::SimConfig;
use hd_model::registry::REGISTRY;
use serde::{Deserialize, Serialize};

/// The contents of `study.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StudyManifest {
    /// Study name.
    pub name: String,
    /// Description for the report.
    pub description: String,
    /// The study file as given.
    pub file: String,
    /// The program that wrote the file.
    pub tool: Tool,
    /// The shard this folder's writer ran (`None`: the whole study).
    pub shard: Option<ShardOf>,
    /// Names swept anywhere in the study.
    pub swept: Vec<String>,
    /// Metric columns kept, in output order.
    pub metrics: Vec<String>,
    /// Trace keeping.
    pub traces: TraceSettings,
    /// Every registry parameter with its unit, default, range and description.
    pub parameter_defaults: Vec<ParameterDefault>,
    /// The parts.
    pub parts: Vec<PartManifest>,
    /// Every run of the whole study, in index order.
    pub runs: Vec<RunEntry>,
}

/// Program name and version.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tool {
    /// `hdw`.
    pub name: String,
    /// Its version.
    pub version: String,
}

/// Shard `k` of `n` (1-based).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShardOf {
    /// This shard.
    pub k: usize,
    /// Number of shards.
    pub n: usize,
}

/// One registry parameter as documented in the manifest.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParameterDefault {
    /// Canonical name.
    pub name: String,
    /// SI unit.
    pub unit: String,
    /// Default value.
    pub default: f64,
    /// Valid range, as text.
    pub range: String,
    /// Description.
    pub doc: String,
}

/// One part of the study.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PartManifest {
    /// Part name.
    pub name: String,
    /// Configuration before a point's values are applied.
    pub base: SimConfig,
    /// Names this part sweeps (axes, then sampled dimensions).
    pub swept: Vec<String>,
    /// Its grid axes.
    pub axes: Vec<AxisManifest>,
}

/// One grid axis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AxisManifest {
    /// What it sets.
    pub name: String,
    /// Its values.
    pub values: Vec<Value>,
    /// Zip label.
    pub zip: Option<String>,
}

/// One run of the study.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunEntry {
    /// Stable identifier.
    pub run_id: String,
    /// Position in the expanded study.
    pub run_index: usize,
    /// Part name.
    pub part: String,
    /// Swept names and values of this run.
    pub swept: Vec<(String, Value)>,
}

impl StudyManifest {
    /// The manifest of `study` with its expanded `runs`, written by `version` of the tool
    /// for `shard`.
    pub fn new(
        study: &Study,
        runs: &[RunSpec],
        shard: Option<(usize, usize)>,
        version: &str,
    ) -> Self {
        let owned = |v: Vec<&str>| v.into_iter().map(str::to_string).collect::<Vec<_>>();
        StudyManifest {
            name: study.name.clone(),
            description: study.description.clone(),
            file: study.file.display().to_string(),
            tool: Tool { name: "hdw".into(), version: version.into() },
            shard: shard.map(|(k, n)| ShardOf { k, n }),
            swept: owned(study.swept_names()),
            metrics: owned(study.keep_metrics.clone()),
            traces: study.traces,
            parameter_defaults: REGISTRY
                .iter()
                .map(|p| ParameterDefault {
                    name: p.name.into(),
                    unit: p.unit.into(),
                    default: p.default_value(),
                    range: p.range_text(),
                    doc: p.doc.into(),
                })
                .collect(),
            parts: study
                .parts
                .iter()
                .map(|p| PartManifest {
                    name: p.name.clone(),
                    base: p.base.clone(),
                    swept: owned(p.swept_names()),
                    axes: p
                        .axes
                        .iter()
                        .map(|a| AxisManifest {
                            name: a.knob.name().into(),
                            values: a.values.clone(),
                            zip: a.zip.clone(),
                        })
                        .collect(),
                })
                .collect(),
            runs: runs
                .iter()
                .map(|r| RunEntry {
                    run_id: r.run_id.clone(),
                    run_index: r.index,
                    part: r.part.clone(),
                    swept: r.swept.clone(),
                })
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// A study with a grid part (old letters A and B) and a Sobol' part survives the trip
    /// through JSON, canonical names and unbounded solver settings included.
    #[test]
    fn round_trips_through_json() {
        let text = r#"
name = "trip"
[base]
t_end = 0.01
[input]
kind = "sine"
voltage = 24.0
freq = 50.0
[[part]]
name = "grid"
[[part.axis]]
name = "A"
values = [1e4, 2e4]
[[part.axis]]
name = "variant"
values = ["linear", "full"]
[[part]]
name = "design"
[part.sample]
method = "sobol"
n = 4
[[part.sample.param]]
name = "B"
lo = 100
hi = 400
"#;
        let no_files = |p: &Path| Err(format!("no file {}", p.display()));
        let study = crate::parse_study(text, Path::new("trip.toml"), &no_files).unwrap();
        let runs = study.expand();
        let m = StudyManifest::new(&study, &runs, Some((1, 2)), "0.0.0");
        assert_eq!(m.parts[0].axes[0].name, "mem_A");
        assert_eq!(m.parts[1].swept, vec!["mem_B".to_string()]);
        let json = serde_json::to_string(&m).unwrap();
        let back: StudyManifest = serde_json::from_str(&json).unwrap();
        assert_eq!(back, m);
        assert_eq!(back.runs.len(), runs.len());
    }
}
