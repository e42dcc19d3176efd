//! `hdw report DIR`: one report from the shards of a study. Merges every runs table of the
//! folder into `runs.parquet` (one row per run id), checks the runs against the plan in
//! `study.json`, and writes the same report (and sensitivity analysis) as `hdw study` on
//! one machine.

use super::report_check::{Check, check, list_runs, missing_note, shards_of};
use super::report_inputs::{Sources, find_sources, move_merged_shards, shard_count};
use super::study_json::{PlannedRun, StudyPlan, read_study_plan, write_study_json};
use crate::report;
use anyhow::{Result, bail};
use clap::Args;
use hd_sweep::{RunPlan, Study, load_study};
use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// Merge the shards of a study into one runs.parquet and write its report.
#[derive(Args, Debug)]
#[command(
    after_help = "DIR is the --out folder shared by the shards of one study (`hdw study FILE --out DIR --shard K/N`).\nReads DIR/study.json (the planned runs) and every runs table: runs-shard-K-of-N.parquet of finished\nshards (in DIR, or in DIR/shards/ where an earlier `hdw report` moved them) and DIR/parts/runs-*.parquet\ncommitted by shards that stopped early (a folder without shards: its runs.parquet and parts). Rows\nrepeating a run_id are dropped (the first is kept, finished shards before parts) and counted on stderr.\nThen it writes, as `hdw study` does on one machine:\n  runs.parquet    every run once, sorted by run_index\n  traces.parquet  the shards' kept traces, when the study keeps traces\n  study.json      the plan of the whole study (no shard)\n  report.md       tables and plots (*.svg); sensitivity.* for sobol/morris designs\nand moves the merged shard tables to DIR/shards/, so that DIR holds each run once (for `hdw explore\nDIR` and runs*.parquet globs). Parts of unfinished shards stay in DIR/parts/ for `--resume`.\nPlanned runs without a row are an error that lists them (index, id, part) and the shards that hold\nthem; with --allow-missing the report covers the runs present and lists the missing ones at its top.\nRows of runs that are not in study.json (another study, or a changed study file) are always an\nerror. Failed runs are reported, not an error.\n\nExample:\n  hdw study studies/seed-voltage.toml --out out/seed-voltage --shard 1/2   # on one node\n  hdw report out/seed-voltage --allow-missing       # while shard 2 is still missing\n  hdw study studies/seed-voltage.toml --out out/seed-voltage --shard 2/2   # on another, same shared folder\n  hdw report out/seed-voltage                       # out/seed-voltage/report.md, runs.parquet"
)]
pub struct ReportArgs {
    /// The study's output folder, shared by all its shards.
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// The study file, when the path recorded in DIR/study.json does not reach it from here.
    #[arg(long, value_name = "FILE")]
    pub study: Option<PathBuf>,
    /// Report on the runs present even if some planned runs are missing (listed in report.md).
    #[arg(long)]
    pub allow_missing: bool,
}

/// Run `hdw report`.
pub fn run(args: ReportArgs) -> Result<()> {
    let dir = &args.dir;
    if !dir.is_dir() {
        bail!("{}: no such folder (expected the --out folder of a study's shards)", dir.display());
    }
    let plan = read_study_plan(dir)?;
    let study = load_planned_study(dir, &plan, args.study.as_deref())?;
    let run_plan = RunPlan::new(&study)?;
    let planned = planned_runs(&run_plan);
    let sources = find_sources(dir, "runs")?;
    let inputs = sources.all();
    if inputs.is_empty() {
        bail!(
            "{}: no runs table (runs-shard-K-of-N.parquet, parts/runs-*.parquet or runs.parquet): have the shards run with --out {}?",
            dir.display(),
            dir.display()
        );
    }
    let merged = read_first_rows(&inputs)?;
    let result = check(&planned, &merged.ids, &merged.status, &merged.error);
    refuse_foreign(dir, &result, &merged)?;
    let note = missing_runs(dir, &plan, planned.len(), &result, &sources, args.allow_missing)?;
    drop(planned);
    eprintln!(
        "{} runs tables ({} shard, {} part files): {} rows, {} duplicate rows of a run_id dropped{}",
        inputs.len(),
        sources.shards.len(),
        sources.parts.len(),
        merged.rows,
        merged.rows - merged.ids.len(),
        if merged.duplicates.is_empty() {
            String::new()
        } else {
            format!(" (e.g. {})", merged.duplicates.join(", "))
        }
    );
    for f in result.failed.iter().take(super::report_check::LIST_LIMIT) {
        eprintln!(
            "failed: index {} (id {}, part {}): {}",
            f.run.index, f.run.run_id, f.run.part, f.error
        );
    }
    let runs_path = dir.join("runs.parquet");
    let n = hd_io::runs::merge_runs(&inputs, &runs_path)?;
    let traces = find_sources(dir, "traces")?;
    let traces_path = dir.join("traces.parquet");
    if !traces.shards.is_empty() || !traces.parts.is_empty() {
        hd_io::runs::concat_files(&traces.all(), &traces_path)?;
    }
    let moved = move_merged_shards(dir, &sources)? + move_merged_shards(dir, &traces)?;
    if moved > 0 {
        eprintln!("{moved} merged shard tables moved to {}", dir.join("shards").display());
    }
    write_study_json(dir, &run_plan, None)?;
    report::write_study_outputs(dir, &study, &runs_path, &traces_path, note.as_deref())?;
    eprintln!(
        "{n} of {} planned runs in {}, {} missing, {} failed",
        run_plan.len(),
        runs_path.display(),
        result.missing.len(),
        result.failed.len()
    );
    Ok(())
}

/// Every planned run's id, index and part, generated from the study file.
fn planned_runs(plan: &RunPlan) -> Vec<PlannedRun> {
    (0..plan.len())
        .map(|i| {
            let r = plan.spec(i);
            PlannedRun { run_id: r.run_id, index: r.index, part: r.part.to_string() }
        })
        .collect()
}

/// Load the study file the plan was made from (or `--study`), keep the parts that were
/// run, and check that it still gives the planned number of runs (rows whose run ids the
/// study no longer gives are refused as foreign by the check).
fn load_planned_study(dir: &Path, plan: &StudyPlan, given: Option<&Path>) -> Result<Study> {
    let file = given.unwrap_or(&plan.file);
    if !file.is_file() {
        bail!(
            "study file {} (recorded in {}) not found from {}: pass it with --study FILE",
            file.display(),
            dir.join("study.json").display(),
            std::env::current_dir().map(|d| d.display().to_string()).unwrap_or_default()
        );
    }
    let loader = |p: &Path| hd_io::read_profile(p).map_err(|e| e.to_string());
    let mut study = load_study(file, &loader)?;
    for name in &plan.parts {
        if !study.parts.iter().any(|p| &p.name == name) {
            bail!("{}: no part '{name}', which {}/study.json lists", file.display(), dir.display());
        }
    }
    study.parts.retain(|p| plan.parts.contains(&p.name));
    study.compare.retain(|c| plan.parts.contains(&c.part));
    let run_plan = RunPlan::new(&study)?;
    let count = run_plan.len();
    let differ = if count == plan.run_count {
        plan.ids.iter().filter(|(i, id)| *i >= count || run_plan.spec(*i).run_id != *id).count()
    } else {
        plan.ids.len().max(1)
    };
    if differ > 0 {
        bail!(
            "{} gives {count} runs, {}/study.json plans {} ({differ} of {} checked run ids differ): the study file changed since the sweep; pass the file it ran with as --study",
            file.display(),
            dir.display(),
            plan.run_count,
            plan.ids.len()
        );
    }
    drop(run_plan);
    Ok(study)
}

/// The rows of all runs tables, first row per run id kept (as the merge keeps them).
struct FirstRows {
    ids: Vec<Option<String>>,
    status: Vec<Option<String>>,
    error: Vec<Option<String>>,
    /// The file each kept row came from.
    files: Vec<PathBuf>,
    /// Rows read before dropping repeats.
    rows: usize,
    /// A few repeated run ids, for the message.
    duplicates: Vec<String>,
}

fn read_first_rows(inputs: &[PathBuf]) -> Result<FirstRows> {
    let mut out = FirstRows {
        ids: Vec::new(),
        status: Vec::new(),
        error: Vec::new(),
        files: Vec::new(),
        rows: 0,
        duplicates: Vec::new(),
    };
    let mut seen = HashSet::new();
    for f in inputs {
        let t = hd_io::table::read_table_columns(f, &["run_id", "status", "error"])?;
        let (Some(ids), Some(status), Some(error)) =
            (t.text("run_id"), t.text("status"), t.text("error"))
        else {
            bail!("{}: not a runs table (needs text columns run_id, status, error)", f.display());
        };
        out.rows += t.height;
        for k in 0..t.height {
            let id = ids[k].clone().unwrap_or_default();
            if !seen.insert(id.clone()) {
                if out.duplicates.len() < 3 {
                    out.duplicates.push(id);
                }
                continue;
            }
            out.ids.push(Some(id));
            out.status.push(status[k].clone());
            out.error.push(error[k].clone());
            out.files.push(f.clone());
        }
    }
    Ok(out)
}

/// Rows of runs the plan does not hold would put another study into this report.
fn refuse_foreign(dir: &Path, result: &Check, merged: &FirstRows) -> Result<()> {
    let Some(first) = result.foreign.first() else { return Ok(()) };
    let foreign: HashSet<&String> = result.foreign.iter().collect();
    let mut files: Vec<String> = merged
        .ids
        .iter()
        .zip(&merged.files)
        .filter(|(id, _)| id.as_ref().is_some_and(|id| foreign.contains(id)))
        .map(|(_, f)| f.display().to_string())
        .collect();
    files.dedup();
    bail!(
        "{} rows belong to no run of {}/study.json (first: run_id {first}), in {}: the folder mixes studies or versions of the study file; move those files away",
        result.foreign.len(),
        dir.display(),
        files.join(", ")
    )
}

/// Missing runs: an error naming them (and the shards to run again), or with
/// `--allow-missing` a warning and the note for `report.md`.
fn missing_runs(
    dir: &Path,
    plan: &StudyPlan,
    planned: usize,
    result: &Check,
    sources: &Sources,
    allow: bool,
) -> Result<Option<String>> {
    if result.missing.is_empty() {
        return Ok(None);
    }
    let rerun = match shard_count(sources) {
        Some(n) => {
            let ks: Vec<String> =
                shards_of(&result.missing, n).iter().map(|k| format!("{k}/{n}")).collect();
            let which = if ks.len() == 1 { ks[0].clone() } else { "K/N".to_string() };
            format!(
                "they belong to shard {} (run again: hdw study {} --out {} --shard {which} --resume)",
                ks.join(", "),
                plan.file.display(),
                dir.display()
            )
        }
        None => {
            format!("run again: hdw study {} --out {} --resume", plan.file.display(), dir.display())
        }
    };
    let what = format!(
        "{} of {} planned runs are missing: {}; {rerun}",
        result.missing.len(),
        planned,
        list_runs(&result.missing)
    );
    if !allow {
        bail!("{what}; or pass --allow-missing to report on the runs present");
    }
    eprintln!("warning: {what}");
    Ok(Some(missing_note(&result.missing, planned)))
}
