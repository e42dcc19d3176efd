//! `study.json`, the record of an expanded study in its output folder: written by
//! `hdw study` (every shard writes the same plan), read back by `hdw report` to know which
//! runs the folder should hold.

use super::common::write_json;
use anyhow::{Context, Result, bail};
use hd_sweep::{RunSpec, Study};
use serde_json::json;
use std::path::{Path, PathBuf};

/// Write `DIR/study.json`: the study, the tool version, the parameter defaults and every
/// run's id, index, part and swept values. `shard` is the slice this process runs, if any.
pub fn write_study_json(
    dir: &Path,
    study: &Study,
    runs: &[RunSpec],
    shard: Option<(usize, usize)>,
) -> Result<()> {
    let defaults: Vec<serde_json::Value> = hd_model::registry::REGISTRY
        .iter()
        .map(|p| json!({ "name": p.name, "unit": p.unit, "default": p.default_value(), "range": p.range_text(), "doc": p.doc }))
        .collect();
    let parts: Vec<serde_json::Value> = study
        .parts
        .iter()
        .map(|p| {
            json!({
                "name": p.name,
                "base": p.base,
                "swept": p.swept_names(),
                "axes": p.axes.iter().map(|a| json!({ "name": a.knob.name(), "values": a.values, "zip": a.zip })).collect::<Vec<_>>(),
            })
        })
        .collect();
    let run_list: Vec<serde_json::Value> = runs
        .iter()
        .map(|r| json!({ "run_id": r.run_id, "run_index": r.index, "part": r.part, "swept": r.swept }))
        .collect();
    let doc = json!({
        "name": study.name,
        "description": study.description,
        "file": study.file.display().to_string(),
        "tool": { "name": "hdw", "version": env!("CARGO_PKG_VERSION") },
        "shard": shard.map(|(k, n)| json!({ "k": k, "n": n })),
        "swept": study.swept_names(),
        "metrics": study.keep_metrics,
        "traces": study.traces,
        "parameter_defaults": defaults,
        "parts": parts,
        "runs": run_list,
    });
    write_json(&dir.join("study.json"), &doc)
}

/// One run the study plans, as `study.json` lists it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlannedRun {
    /// Stable run identifier (16 hex digits).
    pub run_id: String,
    /// Position in the expanded study, counted across parts from 0.
    pub index: usize,
    /// Part name.
    pub part: String,
}

/// What `hdw report` needs from `study.json`.
#[derive(Debug)]
pub struct StudyPlan {
    /// The study file as it was given to `hdw study`.
    pub file: PathBuf,
    /// Names of the parts that were run (all, or those chosen with `--part`), in order.
    pub parts: Vec<String>,
    /// Every planned run, in index order.
    pub runs: Vec<PlannedRun>,
}

/// Read `DIR/study.json`; errors name the file and the field that is wrong.
pub fn read_study_plan(dir: &Path) -> Result<StudyPlan> {
    let path = dir.join("study.json");
    let text = std::fs::read_to_string(&path).with_context(|| {
        format!("cannot read {} (is DIR the --out folder of `hdw study`?)", path.display())
    })?;
    let doc: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("{}: not valid JSON", path.display()))?;
    let Some(file) = doc["file"].as_str() else {
        bail!("{}: field \"file\" (the study file) is missing or not a text", path.display());
    };
    let Some(parts) = doc["parts"].as_array() else {
        bail!("{}: field \"parts\" is missing or not a list", path.display());
    };
    let parts = parts.iter().filter_map(|p| p["name"].as_str().map(str::to_string)).collect();
    let Some(list) = doc["runs"].as_array() else {
        bail!("{}: field \"runs\" is missing or not a list", path.display());
    };
    let mut runs = Vec::with_capacity(list.len());
    for (k, r) in list.iter().enumerate() {
        let (Some(id), Some(index), Some(part)) =
            (r["run_id"].as_str(), r["run_index"].as_u64(), r["part"].as_str())
        else {
            bail!(
                "{}: runs[{k}] lacks run_id (text), run_index (integer) or part (text)",
                path.display()
            );
        };
        runs.push(PlannedRun { run_id: id.to_string(), index: index as usize, part: part.into() });
    }
    Ok(StudyPlan { file: PathBuf::from(file), parts, runs })
}
