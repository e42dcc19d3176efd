//! `hdw study`: expand a study file into runs, run them in parallel with a progress bar,
//! commit results in parts (resumable, shardable), then write the report.

use super::batching::PartSizer;
use super::common::DEFAULT_MAX_OUTPUT_VALUES;
use super::common::ensure_dir;
use super::study_json::{read_manifest, write_study_json};
use super::study_traces::{TraceFiles, check_traces_size};
use crate::report;
use anyhow::{Context, Result, bail};
use clap::Args;
use hd_io::store::RunStore;
use hd_sweep::tables::runs_table;
use hd_sweep::{RunPlan, RunRow, RunSpec, TraceSink, load_study, run_batch};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// Run a sensitivity study defined in a study file (see studies/README.md).
#[derive(Args, Debug)]
#[command(
    after_help = "Outputs (in --out DIR, default out/<study name>):\n  runs.parquet    one row per run: run_id, run_index, part, variant, status, error, every parameter,\n                  voltage, freq, swept settings, the kept metrics, solver statistics\n  traces.parquet  kept traces in long format (run_id, t, signals), when the study keeps traces\n  study.json      the expanded study, tool version and parameter defaults\n  report.md       tables and plots (*.svg) of the results\nWith --shard K/N the tables are runs-shard-K-of-N.parquet etc. and there is no report: once every shard\nhas finished, `hdw report DIR` merges them into runs.parquet and writes the report.\n\nExample:\n  hdw study studies/table4.toml --out out/table4\n  hdw study studies/table4.toml --out out/table4 --resume      # after an interruption\n  hdw study studies/table4.toml --out out/slices --shard 2/8   # one of 8 array jobs (then: hdw report out/slices)\n  hdw study studies/table4.toml --part damped-sine --threads 1 --out out/damped   # one part, one thread"
)]
pub struct StudyArgs {
    /// The study file (TOML).
    pub file: PathBuf,
    /// Output folder (default out/<study name>).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Worker threads (default: RAYON_NUM_THREADS where set, else all cores).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Continue an interrupted sweep in DIR: runs already committed are not run again.
    #[arg(long)]
    pub resume: bool,
    /// Run only the K-th of N disjoint slices of the study (1-based), e.g. 3/8.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
    /// Skip the report (tables and plots).
    #[arg(long)]
    pub no_report: bool,
    /// Run only the named part(s) of a multi-part study (repeatable).
    #[arg(long = "part", value_name = "NAME")]
    pub parts: Vec<String>,
    /// Most trace values (samples × columns, all kept traces of this run of the study
    /// together) it may write; refused before any run starts above it [–]. 0 lifts it.
    #[arg(long, default_value_t = DEFAULT_MAX_OUTPUT_VALUES, value_name = "N")]
    pub max_output_values: u64,
}

/// Most worker threads (`--threads`) [–]: far beyond any machine's cores, and each costs
/// a stack.
pub const MAX_THREADS: usize = 1024;

/// Refuse `dir` when its study.json is another study's: resuming would fail on the first
/// run and a fresh start would mix two studies.
fn refuse_other_study(dir: &Path, name: &str) -> Result<()> {
    if !dir.join("study.json").exists() {
        return Ok(());
    }
    match read_manifest(dir) {
        Ok(m) if m.name != name => bail!(
            "{} holds the results of study '{}', not '{name}': choose another --out",
            dir.display(),
            m.name
        ),
        _ => Ok(()),
    }
}

/// Parse `K/N` with 1 ≤ K ≤ N.
fn parse_shard(s: &str) -> Result<(usize, usize)> {
    let parsed =
        s.split_once('/').and_then(|(k, n)| Some((k.trim().parse().ok()?, n.trim().parse().ok()?)));
    match parsed {
        Some((k, n)) if n >= 1 && (1..=n).contains(&k) => Ok((k, n)),
        _ => bail!("--shard {s}: expected K/N with 1 <= K <= N, e.g. 2/8"),
    }
}

/// Run `hdw study`.
pub fn run(args: StudyArgs) -> Result<()> {
    let loader = |p: &Path| hd_io::read_profile(p).map_err(|e| e.to_string());
    let mut study = load_study(&args.file, &loader)?;
    if !args.parts.is_empty() {
        for name in &args.parts {
            if !study.parts.iter().any(|p| &p.name == name) {
                let known: Vec<&str> = study.parts.iter().map(|p| p.name.as_str()).collect();
                bail!(
                    "--part {name}: no such part in {} (parts: {})",
                    args.file.display(),
                    known.join(", ")
                );
            }
        }
        study.parts.retain(|p| args.parts.contains(&p.name));
        study.compare.retain(|c| args.parts.contains(&c.part));
    }
    let shard_kn = args.shard.as_deref().map(parse_shard).transpose()?;
    if let Some(t) = args.threads.filter(|t| !(1..=MAX_THREADS).contains(t)) {
        bail!("--threads {t}: expected 1 to {MAX_THREADS} threads");
    }
    // The run count comes from the axes: a study too large is refused before anything is
    // written, and nothing below holds one item per run of the study.
    let plan = RunPlan::new(&study)?;
    let (k, n) = shard_kn.map_or((1, 1), |(k, n)| (k as u64, n as u64));
    if study.traces.keep {
        check_traces_size(&plan, k, n, study.traces.decimate, args.max_output_values)?;
    }
    let dir =
        ensure_dir(&args.out.clone().unwrap_or_else(|| PathBuf::from("out").join(&study.name)))?;
    // One process per folder (and shard): a second would run every run again.
    let lock_name = match shard_kn {
        Some((k, n)) => format!(".hdw-study-shard-{k}-of-{n}.lock"),
        None => ".hdw-study.lock".to_string(),
    };
    let _lock = hd_io::lock::lock_folder(&dir.join(lock_name), "a study")?;
    refuse_other_study(&dir, &study.name)?;
    let planned = plan.shard_len(k, n);
    let mut store = RunStore::open(&dir, shard_kn)?;
    if store.has_results()? && !args.resume {
        bail!(
            "{} already holds results of this study: pass --resume to continue it, or choose another --out",
            dir.display()
        );
    }
    let done =
        if args.resume { committed(&mut store, &plan, k, n, &dir)? } else { Done::default() };
    write_study_json(&dir, &plan, shard_kn)?;

    let threads = args.threads.unwrap_or_else(crate::cmd::common::default_threads);
    let pool =
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().context("thread pool")?;
    let todo = planned - done.count;
    eprintln!(
        "study '{}': {} runs{}, {} already done, {} to run on {} threads → {}",
        study.name,
        planned,
        shard_kn.map(|(k, n)| format!(" (shard {k}/{n} of {})", plan.len())).unwrap_or_default(),
        done.count,
        todo,
        threads,
        dir.display()
    );
    let bar = progress_bar(todo, "runs");
    let failures = AtomicUsize::new(0);
    let progress = |row: &RunRow| {
        if row.status != hd_sweep::RunStatus::Ok {
            let n = failures.fetch_add(1, Ordering::Relaxed) + 1;
            bar.set_message(format!("{n} failed"));
        }
        bar.inc(1);
    };
    let start = Instant::now();
    let swept = study.swept_names();
    let mut sizer = PartSizer::new(todo, threads, study.traces.keep);
    // Runs are generated by index, one part at a time: memory holds one part of specs
    // and rows, whatever the number of runs.
    let mut pending = plan.shard_indices(k, n).filter(|&i| !done.has(i / n));
    let mut chunk: Vec<RunSpec> = Vec::with_capacity(sizer.size());
    loop {
        chunk.clear();
        chunk.extend(pending.by_ref().take(sizer.size()).map(|i| plan.spec(i)));
        if chunk.is_empty() {
            break;
        }
        let part_start = Instant::now();
        let files = TraceFiles::new(&store);
        let sink = study.traces.keep.then_some(&files as &dyn TraceSink);
        let rows = pool.install(|| run_batch(&chunk, study.traces.decimate, &progress, sink));
        sizer.record(rows.len(), part_start.elapsed().as_secs_f64());
        let written = files.finish()?;
        let paths: Vec<PathBuf> = written.iter().map(|s| s.path().to_path_buf()).collect();
        store.commit_streamed(&runs_table(&rows, &swept, &study.keep_metrics), &paths)?;
    }
    bar.finish();
    let elapsed = start.elapsed().as_secs_f64();
    let todo = todo as usize;
    let total = store.finish()?;
    let failed = failures.load(Ordering::Relaxed);
    eprintln!(
        "{} runs in {:.2} s ({:.0} runs/s), {} failed; {} rows in {}",
        todo,
        elapsed,
        todo as f64 / elapsed.max(1e-9),
        failed,
        total,
        store.runs_path().display()
    );
    if !args.no_report && shard_kn.is_none() {
        report::write_study_outputs(&dir, &study, &store.runs_path(), &store.traces_path(), None)?;
    }
    Ok(())
}

/// The runs of a shard already committed, as one bit per position in the shard.
#[derive(Default)]
struct Done {
    bits: Vec<u64>,
    count: u64,
}

impl Done {
    fn has(&self, pos: u64) -> bool {
        self.bits.get((pos / 64) as usize).is_some_and(|w| w & (1 << (pos % 64)) != 0)
    }
}

/// The committed runs of shard `k` of `n`, each checked against the run the study now
/// gives at its index (a changed study file would otherwise mix two studies in one table).
fn committed(store: &mut RunStore, plan: &RunPlan, k: u64, n: u64, dir: &Path) -> Result<Done> {
    let mut done = Done { bits: vec![0; plan.shard_len(k, n).div_ceil(64) as usize], count: 0 };
    let mut stale: Option<String> = None;
    store.committed_runs(&mut |index, id| {
        if stale.is_some() {
            return;
        }
        if index >= plan.len() || index % n != k - 1 || plan.spec(index).run_id != id {
            stale = Some(format!("run_index {index}, run_id {id}"));
            return;
        }
        let pos = index / n;
        let word = &mut done.bits[(pos / 64) as usize];
        if *word & (1 << (pos % 64)) == 0 {
            *word |= 1 << (pos % 64);
            done.count += 1;
        }
    })?;
    if let Some(run) = stale {
        bail!(
            "{} holds a run this study (or shard) does not plan ({run}): the study file changed since the sweep began; choose another --out",
            dir.display()
        );
    }
    Ok(done)
}

/// The bar of a batch of `len` items called `items` (runs, logs), with the failures so far
/// as its message; shared by `hdw study` and `hdw fleet`.
pub(crate) fn progress_bar(len: u64, items: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    let style = ProgressStyle::with_template(&format!(
        "{{elapsed_precise}} [{{bar:40}}] {{pos}}/{{len}} {items} · {{per_sec}} · ETA {{eta}} · {{msg}}"
    ))
    .unwrap_or_else(|_| ProgressStyle::default_bar())
    .progress_chars("=> ");
    bar.set_style(style);
    bar.set_message("0 failed");
    bar
}
