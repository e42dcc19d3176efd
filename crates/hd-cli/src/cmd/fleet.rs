//! `hdw fleet`: fit every log of a fleet with one template, in parallel and in bounded
//! memory, into fits.parquet (resumable, shardable), then the drift analysis and plots.

use super::fleet_fit::{FitKind, LogFit, Template, fit_log, parameter_units, rows};
use super::fleet_plan::{LogSpec, Source, plan};
use anyhow::{Context, Result, bail};
use clap::Args;
use hd_ident::Fixed;
use hd_io::fleet::{FitStore, merge_with_docs, shard_tables};
use rayon::prelude::*;
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Fit every log of a fleet, then say which unit is drifting.
#[derive(Args, Debug)]
#[command(
    allow_negative_numbers = true,
    after_help = "Logs: --manifest FILE (CSV or Parquet, one row per log: the file, the unit's identifiers, a timestamp,\n\
any covariates; relative files are relative to the manifest's folder; optional columns time_scale,\n\
speed_scale, torque_scale override the template's factors for that row) or --pattern whose {fields}\n\
become columns. Every log gets the same fit (--fit): plateaus (the static law Tc, Ts, ws, sigma2 from\n\
the speed plateaus of a joint test: mean torque per plateau after the bristles settle, about 1 ms a\n\
log), transient (all six LuGre parameters from the series, as hdw fit friction --transient, about\n\
0.15 s a log), steady (a steady-state table, as hdw fit friction --steady) or hysteresis (a stiffness\n\
law from a torque-deflection record, as hdw fit hysteresis: --law memory|maxwell-slip|bouc-wen, --elements,\n\
--theta-unit, --offset, --fix; columns t,theta,torque) or drive (hdw fit drive with --drive-config FILE,\n\
its one [[experiment]] file replaced by each log; the best law's parameters).\n\n\
A log that cannot be fitted (missing file or column, a fit that fails, a duplicate row, a timestamp\n\
that does not parse) is a failed row with its reason; the rest go on. Finished logs are committed in\n\
parts: after Ctrl-C, --resume fits only the rest. --shard K/N fits every N-th log (array jobs,\n\
deploy/slurm/hdw-fleet-shard.sbatch); then --merge stacks the shards into fits.parquet and runs the drift.\n\n\
Drift (docs/fleet.md): each parameter (log scale) regressed on --covariates over each unit's first\n\
--baseline-days, the model (none, fleet-wide or per-unit, linear or quadratic) chosen by BIC; then per\n\
unit Page's two-sided CUSUM on the residuals standardised by their standard errors plus the scatter\n\
they do not explain, its threshold set so that the whole fleet alarms falsely with probability\n\
--false-alarm. --normalise none skips the covariates (to see what they buy).\n\n\
Outputs (in --out DIR):\n  \
fits.parquet   a row per log × parameter: manifest columns, unit_id, day, status, error, parameter,\n                 \
value, std_error, ci95, determined, param_unit, resid_over_noise, fit_time_s; sorted\n                 \
by log (run_index); units in the metadata\n  \
drift.parquet  a row per log × parameter: normalised value, residual change %, z, CUSUM sums, flagged\n  \
alarms.csv     unit, parameter, first day flagged, onset, change at the end in % with its 95 % interval\n  \
drift.json     settings, each parameter's normalisation (candidates, BIC, coefficients), units\n  \
plots/         per unit and parameter: estimates ±2 SE, normalised series, alarm; overview.svg\n\n\
Example:\n  \
hdw synth fleet --robots 2 --joints 2 --days 24 --duration 4 --wear r2/j1@14 --out out/fleet-data\n  \
hdw fleet --manifest out/fleet-data/manifest.csv --covariates temperature --baseline-days 10 --out out/fleet\n  \
hdw fleet --pattern 'out/fleet-data/logs/{robot}/{joint}/{date}.csv' --baseline-days 10 --out out/fleet-pattern\n  \
hdw fleet --manifest out/fleet-data/manifest.csv --covariates temperature --shard 1/2 --out out/fleet-sh\n  \
hdw fleet --manifest out/fleet-data/manifest.csv --covariates temperature --shard 2/2 --out out/fleet-sh\n  \
hdw fleet --merge --baseline-days 10 --out out/fleet-sh"
)]
pub struct FleetArgs {
    /// Manifest of the logs (CSV or Parquet).
    #[arg(long, value_name = "FILE", conflicts_with = "pattern")]
    pub manifest: Option<PathBuf>,
    /// Path pattern of the logs, e.g. 'logs/{robot}/{joint}/{date}.csv'.
    #[arg(long, value_name = "PATTERN")]
    pub pattern: Option<String>,
    /// Manifest column naming each log's file.
    #[arg(long, value_name = "NAME", default_value = "file")]
    pub file_column: String,
    /// Columns identifying a unit, comma-separated (e.g. robot,joint).
    #[arg(long, value_name = "COLS", value_delimiter = ',', default_value = "robot,joint")]
    pub unit: Vec<String>,
    /// Column of the log's timestamp (YYYY-MM-DD[THH:MM[:SS]], YYYYMMDD, or days).
    #[arg(long, value_name = "NAME", default_value = "date")]
    pub time: String,
    /// Covariate columns (numbers), comma-separated, e.g. temperature,payload.
    #[arg(long, value_name = "COLS", value_delimiter = ',')]
    pub covariates: Vec<String>,
    /// The fit every log gets.
    #[arg(long, value_enum, default_value = "plateaus")]
    pub fit: FitKind,
    /// Columns of each log: T,OMEGA,TORQUE (steady: OMEGA,TORQUE; hysteresis: T,THETA,TORQUE).
    #[arg(long, value_name = "NAMES", value_delimiter = ',')]
    pub columns: Vec<String>,
    /// Factor from the logs' time unit to s.
    #[arg(long, value_name = "K", default_value_t = 1.0)]
    pub time_scale: f64,
    /// Factor from the logs' speed unit to rad/s.
    #[arg(long, value_name = "K", default_value_t = 1.0)]
    pub speed_scale: f64,
    /// Factor from the logs' torque unit to N·m.
    #[arg(long, value_name = "K", default_value_t = 1.0)]
    pub torque_scale: f64,
    /// Separate levels for negative speeds (Tc_neg, Ts_neg).
    #[arg(long)]
    pub asymmetric: bool,
    /// Fit a constant torque offset.
    #[arg(long)]
    pub offset: bool,
    /// Hold a parameter, e.g. `--fix sigma2=0` (repeatable).
    #[arg(long, value_name = "NAME=VALUE")]
    pub fix: Vec<String>,
    /// Plateaus: largest relative deviation of the speed within a plateau.
    #[arg(long, value_name = "REL", default_value_t = 0.02)]
    pub plateau_tolerance: f64,
    /// Plateaus: share of each plateau dropped while the bristles settle.
    #[arg(long, value_name = "REL", default_value_t = 0.3)]
    pub settle: f64,
    /// Plateaus: shortest plateau [s].
    #[arg(long, value_name = "S", default_value_t = 0.1)]
    pub min_dwell: f64,
    /// Hysteresis: stiffness law, memory, maxwell-slip or bouc-wen (as hdw fit hysteresis).
    #[arg(long, value_name = "LAW", default_value = "memory")]
    pub law: String,
    /// Hysteresis: Maxwell-slip elements.
    #[arg(long, value_name = "N", default_value_t = hd_ident::stiffness::maxwell_slip::DEFAULT_ELEMENTS)]
    pub elements: usize,
    /// Hysteresis: unit of the deflection column: rad, mrad, urad, deg, arcmin or arcsec.
    #[arg(long, value_name = "UNIT", default_value = "rad")]
    pub theta_unit: String,
    /// Drive (`--fit drive`): an `hdw fit drive` configuration with one [[experiment]],
    /// whose `file` each log replaces.
    #[arg(long, value_name = "FILE")]
    pub drive_config: Option<PathBuf>,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "out/fleet")]
    pub out: PathBuf,
    /// Continue an interrupted fleet in DIR: finished logs are not fitted again.
    #[arg(long)]
    pub resume: bool,
    /// Fit only the K-th of N slices of the logs (1-based), e.g. 3/8.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
    /// Merge the shards in --out into fits.parquet, then the drift analysis.
    #[arg(long)]
    pub merge: bool,
    /// Only the drift analysis and plots, on --out's fits.parquet (other drift settings).
    #[arg(long)]
    pub drift_only: bool,
    /// Logs per committed part (0: 48 per thread, at least 64); an interrupt loses at most
    /// one part's work.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub part_logs: usize,
    /// Worker threads (default: RAYON_NUM_THREADS where set, else all cores).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    #[command(flatten)]
    pub drift: super::fleet_drift::DriftArgs,
}

/// What fleet.json records: where the logs came from and the template.
#[derive(serde::Serialize, serde::Deserialize, PartialEq, Debug)]
struct FleetConfig {
    source: Source,
    template: Template,
    logs: usize,
    version: String,
}

fn parse_shard(s: &str) -> Result<(usize, usize)> {
    let parsed =
        s.split_once('/').and_then(|(k, n)| Some((k.trim().parse().ok()?, n.trim().parse().ok()?)));
    match parsed {
        Some((k, n)) if n >= 1 && (1..=n).contains(&k) => Ok((k, n)),
        _ => bail!("--shard {s}: expected K/N with 1 <= K <= N, e.g. 2/8"),
    }
}

fn read_config(dir: &Path) -> Result<FleetConfig> {
    let p = dir.join("fleet.json");
    let text = std::fs::read_to_string(&p).with_context(|| {
        format!(
            "{}: no fleet here (run hdw fleet --manifest … --out {} first)",
            p.display(),
            dir.display()
        )
    })?;
    serde_json::from_str(&text)
        .with_context(|| format!("{}: not a fleet.json of this version", p.display()))
}

/// Run `hdw fleet`.
pub fn run(args: FleetArgs) -> Result<()> {
    let dir = args.out.clone();
    if args.merge || args.drift_only {
        let cfg = read_config(&dir)?;
        if args.merge {
            let shards = shard_tables(&dir)?;
            if shards.is_empty() {
                bail!("{}: no fits-shard-*.parquet to merge", dir.display());
            }
            check_shards(&shards)?;
            let n = merge_with_docs(&shards, &dir.join("fits.parquet"))?;
            eprintln!(
                "merged {} shards: {n} rows in {}",
                shards.len(),
                dir.join("fits.parquet").display()
            );
        }
        return super::fleet_drift::run(&dir, &cfg.source, &args.drift);
    }
    let source = Source {
        manifest: args.manifest.clone(),
        pattern: args.pattern.clone(),
        file_column: args.file_column.clone(),
        unit: args.unit.clone(),
        time: args.time.clone(),
        covariates: args.covariates.clone(),
    };
    let columns = if args.columns.is_empty() {
        match args.fit {
            FitKind::Steady => vec!["omega".to_string(), "torque".to_string()],
            FitKind::Hysteresis => {
                vec!["t".to_string(), "theta".to_string(), "torque".to_string()]
            }
            _ => vec!["t".to_string(), "omega".to_string(), "torque".to_string()],
        }
    } else {
        args.columns.clone()
    };
    let want = if args.fit == FitKind::Steady { 2 } else { 3 };
    if columns.len() != want && args.fit != FitKind::Drive {
        bail!(
            "--columns {}: expected {want} names ({})",
            columns.join(","),
            match args.fit {
                FitKind::Steady => "OMEGA,TORQUE",
                FitKind::Hysteresis => "T,THETA,TORQUE",
                _ => "T,OMEGA,TORQUE",
            }
        );
    }
    for (name, v) in [
        ("--time-scale", args.time_scale),
        ("--speed-scale", args.speed_scale),
        ("--torque-scale", args.torque_scale),
    ] {
        if !super::fit_input::usable_factor(v) {
            bail!(
                "{name} {}: expected a finite, non-zero factor between 1e-12 and 1e12 in magnitude",
                hd_model::error::num(v)
            );
        }
    }
    if !(args.plateau_tolerance > 0.0 && args.plateau_tolerance < 0.5) {
        bail!("--plateau-tolerance {}: expected a value in (0, 0.5)", args.plateau_tolerance);
    }
    if !(0.0..0.95).contains(&args.settle) {
        bail!("--settle {}: expected a share in [0, 0.95)", args.settle);
    }
    if args.fit == FitKind::Hysteresis {
        if args.law.trim().eq_ignore_ascii_case("all") {
            bail!(
                "--law all: a fleet fits one law per log; expected memory, maxwell-slip or bouc-wen"
            );
        }
        hd_ident::stiffness::Law::parse(&args.law).context("--law")?;
        super::fit_input::angle_factor(&args.theta_unit).context("--theta-unit")?;
        if args.elements == 0 {
            bail!("--elements 0: expected at least 1 Maxwell-slip element");
        }
    }
    let drive_config = match (&args.drive_config, args.fit) {
        (Some(p), FitKind::Drive) => {
            let text = std::fs::read_to_string(p)
                .with_context(|| format!("--drive-config {}", p.display()))?;
            super::fleet_drive::with_record(&text, Path::new("log"))
                .map_err(|e| anyhow::anyhow!("--drive-config {}: {e}", p.display()))?;
            text
        }
        (None, FitKind::Drive) => {
            bail!("--fit drive: expected --drive-config FILE (an hdw fit drive configuration)")
        }
        (Some(_), _) => bail!("--drive-config: only with --fit drive"),
        (None, _) => String::new(),
    };
    let template = Template {
        kind: args.fit,
        columns,
        time_scale: args.time_scale,
        speed_scale: args.speed_scale,
        torque_scale: args.torque_scale,
        asymmetric: args.asymmetric,
        offset: args.offset,
        fix: args.fix.clone(),
        plateau_tolerance: args.plateau_tolerance,
        settle: args.settle,
        min_dwell: args.min_dwell,
        law: args.law.clone(),
        elements: args.elements,
        theta_unit: args.theta_unit.clone(),
        drive_config,
    };
    let fixed = Fixed::parse(&args.fix)?;
    let shard = args.shard.as_deref().map(parse_shard).transpose()?;
    if let Some(t) = args.threads.filter(|t| !(1..=1024).contains(t)) {
        bail!("--threads {t}: expected 1 to 1024 threads");
    }
    super::fleet_drift::check(&args.drift)?;
    let plan = plan(&source)?;
    baseline_leaves_days(&plan.logs, args.drift.baseline_days)?;
    let dir = super::common::ensure_dir(&dir)?;
    let lock_name = match shard {
        Some((k, n)) => format!(".hdw-fleet-shard-{k}-of-{n}.lock"),
        None => ".hdw-fleet.lock".to_string(),
    };
    let _lock = hd_io::lock::lock_folder(&dir.join(lock_name), "a fleet")?;
    let cfg = FleetConfig {
        source: source.clone(),
        template: template.clone(),
        logs: plan.logs.len(),
        version: env!("CARGO_PKG_VERSION").into(),
    };
    if let Ok(old) = read_config(&dir)
        && (old.source != cfg.source || old.template != cfg.template || old.logs != cfg.logs)
    {
        bail!(
            "{} holds a fleet with other logs or another fit template (fleet.json): choose another --out",
            dir.display()
        );
    }
    let mut store = FitStore::open(&dir, shard)?;
    if store.has_results()? && !args.resume {
        bail!(
            "{} already holds fits of this fleet: pass --resume to continue, or choose another --out",
            dir.display()
        );
    }
    let mut done: HashSet<usize> = HashSet::new();
    let mut stale = None;
    store.committed(&mut |ri, id| {
        let li = (ri / super::fleet_fit::ROW_SLOTS) as usize;
        // run_id = log_index#file#parameter
        let file = id.split_once('#').and_then(|(_, r)| r.rsplit_once('#')).map_or("", |(f, _)| f);
        match plan.logs.get(li) {
            Some(l) if l.file == file => {
                done.insert(li);
            }
            _ => stale = Some(format!("log {li} ({file})")),
        }
    })?;
    if let Some(s) = stale {
        bail!(
            "{} holds {s}, which the manifest does not list there: the manifest changed; choose another --out",
            dir.display()
        );
    }
    hd_io::atomic::write_atomically(&dir.join("fleet.json"), |f| {
        use std::io::Write;
        f.write_all(serde_json::to_string_pretty(&cfg).unwrap_or_default().as_bytes())
            .map_err(|e| hd_io::IoError::fs(dir.join("fleet.json"), e))
    })?;
    let (k, n) = shard.unwrap_or((1, 1));
    let todo: Vec<&LogSpec> =
        plan.logs.iter().filter(|l| l.index % n == k - 1 && !done.contains(&l.index)).collect();
    let threads = args.threads.unwrap_or_else(crate::cmd::common::default_threads);
    // Large stacks: the fits run rayon inside (the grid search), and a worker blocked
    // there may steal further logs onto its own stack.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .stack_size(64 << 20)
        .build()
        .context("thread pool")?;
    eprintln!(
        "fleet: {} logs{}, {} already fitted, {} to fit ({:?}) on {threads} threads → {}",
        plan.logs.len(),
        shard.map(|(k, n)| format!(" (shard {k}/{n})")).unwrap_or_default(),
        done.len(),
        todo.len(),
        template.kind,
        dir.display()
    );
    let bar = super::study::progress_bar(todo.len() as u64, "logs");
    let start = Instant::now();
    let mut failed = 0usize;
    let extra = [
        ("hdw.parameter_units", parameter_units()),
        ("hdw.fleet", serde_json::to_string(&cfg).unwrap_or_default()),
    ];
    let extra_ref: Vec<(&str, String)> = extra.iter().map(|(k, v)| (*k, v.clone())).collect();
    // Parts of a few seconds' work each: an interrupt loses at most one part.
    let part = if args.part_logs > 0 { args.part_logs } else { (threads * 48).max(64) };
    for chunk in todo.chunks(part) {
        let fits: Vec<LogFit> = pool.install(|| {
            chunk
                .par_iter()
                .map(|l| {
                    let f = fit_log(l, &template, &fixed);
                    bar.inc(1);
                    f
                })
                .collect()
        });
        failed += fits.iter().filter(|f| f.outcome.is_err()).count();
        bar.set_message(format!("{failed} failed"));
        store.commit(&rows(&plan, chunk, &fits), &extra_ref)?;
    }
    bar.finish();
    release_free_memory();
    let total = store.finish()?;
    let secs = start.elapsed().as_secs_f64();
    eprintln!(
        "{} logs in {secs:.2} s ({:.1} logs/s), {failed} failed; {total} rows in {}",
        todo.len(),
        todo.len() as f64 / secs.max(1e-9),
        store.fits_path().display()
    );
    if failed > 0 {
        eprintln!(
            "failed logs: the rows with status 'failed' name the reason (hdw explore {} --filter 'status == \"failed\"')",
            store.fits_path().display()
        );
    }
    if shard.is_none() {
        release_free_memory();
        super::fleet_drift::run(&dir, &source, &args.drift)?;
    }
    Ok(())
}

/// Give the allocator's free pages back to the system between the stages: glibc keeps
/// what the fitting threads freed in their arenas, which would add to the next stage's
/// peak (the stages' live data are small and flat in the number of logs).
fn release_free_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        unsafe extern "C" {
            fn malloc_trim(pad: usize) -> i32;
        }
        // SAFETY: malloc_trim only returns free memory of glibc's heaps to the system; it
        // touches no live allocation.
        unsafe {
            malloc_trim(0);
        }
    }
}

/// Every shard of one split, none missing (the merge of an incomplete set is refused).
fn check_shards(files: &[PathBuf]) -> Result<()> {
    let mut n_of = None;
    let mut ks = Vec::new();
    for f in files {
        let name = f.file_name().and_then(|n| n.to_str()).unwrap_or("");
        let kn = name
            .strip_prefix("fits-shard-")
            .and_then(|r| r.strip_suffix(".parquet"))
            .and_then(|r| r.split_once("-of-"));
        let Some((k, n)) =
            kn.and_then(|(k, n)| Some((k.parse::<usize>().ok()?, n.parse::<usize>().ok()?)))
        else {
            bail!("{}: not a shard table name (fits-shard-K-of-N.parquet)", f.display());
        };
        if n_of.is_some_and(|m| m != n) {
            bail!(
                "{}: shards of different splits in one folder ({} and {n})",
                f.display(),
                n_of.unwrap_or(0)
            );
        }
        n_of = Some(n);
        ks.push(k);
    }
    let n = n_of.unwrap_or(0);
    let missing: Vec<String> = (1..=n).filter(|k| !ks.contains(k)).map(|k| k.to_string()).collect();
    if !missing.is_empty() {
        bail!(
            "shards {} of {n} have not finished (no fits-shard-K-of-{n}.parquet): run them first",
            missing.join(", ")
        );
    }
    Ok(())
}

/// Warn of a baseline that covers every log of every unit: the drift test then has nothing
/// to watch, and its scale and alarms come from the baseline itself (the fits stand).
fn baseline_leaves_days(logs: &[LogSpec], baseline_days: f64) -> Result<()> {
    let mut first: std::collections::HashMap<&str, f64> = std::collections::HashMap::new();
    for l in logs.iter().filter(|l| l.problem.is_none() && l.day.is_finite()) {
        let d = first.entry(l.unit.as_str()).or_insert(l.day);
        *d = d.min(l.day);
    }
    let watched = logs
        .iter()
        .filter(|l| l.problem.is_none() && l.day.is_finite())
        .any(|l| l.day >= first[l.unit.as_str()] + baseline_days);
    if watched || first.is_empty() {
        return Ok(());
    }
    let span = logs
        .iter()
        .filter(|l| l.problem.is_none() && l.day.is_finite())
        .map(|l| l.day - first[l.unit.as_str()])
        .fold(0.0f64, f64::max);
    eprintln!(
        "warning: --baseline-days {baseline_days} covers every log (each unit's logs span at most {span:.1} days from its first): the drift test has no day after the baseline to watch, so an alarm it gives is not wear; for a drift verdict give a baseline shorter than the record, e.g. --baseline-days {:.0}",
        (span / 3.0).max(1.0).round()
    );
    Ok(())
}
