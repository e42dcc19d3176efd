//! `study.json`, the record of an expanded study in its output folder: written by
//! `hdw study` (every shard writes the same plan), read back by `hdw report` to know which
//! runs the folder should hold.

use super::common::write_json;
use anyhow::{Context, Result};
use hd_sweep::{RunPlan, StudyManifest};
use std::path::{Path, PathBuf};

/// Write `DIR/study.json` ([`StudyManifest`]): the study, the tool version, the parameter
/// defaults, the run counts and, for small studies, every run's id, index, part and swept
/// values. `shard` is the slice this process runs, if any.
pub fn write_study_json(dir: &Path, plan: &RunPlan, shard: Option<(usize, usize)>) -> Result<()> {
    let manifest = StudyManifest::new(plan, shard, env!("CARGO_PKG_VERSION"));
    write_json(&dir.join("study.json"), &serde_json::to_value(manifest)?)
}

/// Read `DIR/study.json` as written by `hdw study`; the error names the file and what does
/// not match.
pub fn read_manifest(dir: &Path) -> Result<StudyManifest> {
    let path = dir.join("study.json");
    let text = std::fs::read_to_string(&path).with_context(|| {
        format!("cannot read {} (is DIR the --out folder of `hdw study`?)", path.display())
    })?;
    serde_json::from_str(&text).with_context(|| {
        format!("{}: not the study.json of a study written by hdw", path.display())
    })
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
    /// Number of planned runs (the runs themselves are generated from the study file).
    pub run_count: u64,
    /// `(run_index, run_id)` the study file must still give: every run of a small study,
    /// a spread sample of a large one.
    pub ids: Vec<(u64, String)>,
}

/// What `hdw report` needs from `DIR/study.json`.
pub fn read_study_plan(dir: &Path) -> Result<StudyPlan> {
    let m = read_manifest(dir)?;
    Ok(StudyPlan {
        file: PathBuf::from(&m.file),
        parts: m.parts.iter().map(|p| p.name.clone()).collect(),
        run_count: m.run_count,
        ids: if m.runs.is_empty() {
            m.id_sample
        } else {
            m.runs.into_iter().map(|r| (r.run_index as u64, r.run_id)).collect()
        },
    })
}
