//! `hdw sensitivity`: global sensitivity analysis of a finished study folder (Sobol'
//! indices or Morris screening of its sobol/morris design), or the `--check ishigami`
//! self-check, which runs the same code on a function with known indices.

use crate::report::sensitivity::{Analysis, Options, analyse_dir};
use anyhow::{Context, Result, bail};
use clap::{ArgGroup, Args, ValueEnum};
use hd_sweep::sensitivity::{
    ISHIGAMI_BASE_SAMPLES, ISHIGAMI_NAMES, Ishigami, IshigamiCheck, IshigamiCheckConfig,
    SensitivityMethod, SensitivityRow, SobolOptions, ishigami_check,
};
use serde_json::json;
use std::path::PathBuf;

/// Global sensitivity: Sobol' indices (first order, total) and Morris screening.
#[derive(Args, Debug)]
#[command(
    allow_negative_numbers = true,
    group(ArgGroup::new("what").args(["dir", "check"]).required(true).multiple(false)),
    after_help = "Give exactly one of DIR or --check.\n\nDIR: the output folder of `hdw study` on a study whose [sample] has method = \"sobol\" or\n\"morris\" (see docs/sensitivity.md). Reads DIR/study.json and every DIR/runs*.parquet (all shards);\nfailed runs, and runs missing from the tables, drop their whole base row (Sobol') or trajectory\n(Morris), counted as n_dropped. Writes DIR/sensitivity.parquet (part, method, parameter, metric,\nS1, S1_lo, S1_hi, ST, ST_lo, ST_hi, mu, mu_star, sigma, n_used, n_dropped, note), one bar chart\nper metric DIR/sensitivity-<metric>.svg, DIR/sensitivity.md, and the same section at the end of\nDIR/report.md. `hdw study` runs this by itself at the end of a study with such a design.\n\n--check ishigami runs the same design and estimator code on the Ishigami function (a = 7, b = 0.1;\nx1, x2, x3 uniform on [-pi, pi]) and prints computed beside analytic indices:\nS1 ~ (0.3139, 0.4424, 0), ST ~ (0.5576, 0.4424, 0.2437). At the default N = 4096 base samples\n(20480 runs) every index is within 0.02; Morris mu* must rank x1 and x2 above x3. Exits non-zero\nwhen either fails. --samples, --trajectories and --levels apply to the check only.\n\n--format json prints one object. For DIR: parts (part, method, parameters, metrics, groups, runs,\nfailed, missing), rows (as in sensitivity.parquet, NaN as null), ranking (per part and metric,\nparameters best first) and files. For the check: arrays S1, ST, S1_analytic, ST_analytic (order\nx1, x2, x3), their intervals S1_lo/S1_hi/ST_lo/ST_hi, mu_star, mu, sigma, and the sample counts.\n\nExamples:\n  hdw study studies/morris-screening.toml --out out/morris   # analyses at the end\n  hdw sensitivity out/morris --metrics thz_amp,efficiency --format json\n  hdw sensitivity out/morris --bootstrap 2000 --seed 7   # more resamples\n  hdw sensitivity --check ishigami\n  hdw sensitivity --check ishigami --samples 1024 --seed 3 --format json"
)]
pub struct SensitivityArgs {
    /// Output folder of a study with a sobol or morris design.
    #[arg(value_name = "DIR")]
    pub dir: Option<PathBuf>,
    /// Self-check on a test function with analytic indices (instead of DIR).
    #[arg(long, value_name = "CASE")]
    pub check: Option<CheckCase>,
    /// Metrics to analyse, comma-separated (default: every kept metric with a finite value).
    #[arg(long, value_name = "M1,M2", value_delimiter = ',')]
    pub metrics: Option<Vec<String>>,
    /// Sobol' base samples N of the check (runs: N·(d+2)); powers of two keep the sequence
    /// balanced.
    #[arg(long, default_value_t = ISHIGAMI_BASE_SAMPLES, value_name = "N")]
    pub samples: usize,
    /// Morris trajectories r of the check (runs: r·(d+1)).
    #[arg(long, default_value_t = 500, value_name = "R")]
    pub trajectories: usize,
    /// Morris grid levels p of the check (even; step Δ = p/(2(p−1)) of each range).
    #[arg(long, default_value_t = 4, value_name = "P")]
    pub levels: usize,
    /// Bootstrap resamples for the 95 % intervals of Sobol' indices (0 = none).
    #[arg(long, default_value_t = 1000)]
    pub bootstrap: usize,
    /// Seed of the bootstrap (and, for the check, of the Sobol' shift and Morris
    /// trajectories).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Output format.
    #[arg(long, default_value = "table")]
    pub format: FormatArg,
}

/// Test functions for `--check`.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum CheckCase {
    /// Ishigami function, a = 7, b = 0.1.
    Ishigami,
}

/// Output formats.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum FormatArg {
    /// Aligned text table.
    Table,
    /// One JSON object on stdout.
    Json,
}

/// Check the arguments into a self-check configuration.
pub fn config(args: &SensitivityArgs) -> IshigamiCheckConfig {
    IshigamiCheckConfig {
        function: Ishigami::default(),
        base_samples: args.samples,
        trajectories: args.trajectories,
        levels: args.levels,
        seed: args.seed,
        bootstrap: args.bootstrap,
    }
}

/// Most Sobol' base samples of the check [–]: N·(d+2) = 10.5 million evaluations, their
/// design about 250 MB.
pub const MAX_CHECK_SAMPLES: usize = 1 << 21;
/// Most Morris trajectories of the check [–].
pub const MAX_CHECK_TRAJECTORIES: usize = 1 << 20;
/// Most bootstrap resamples [–]: the intervals settle within a few thousand, and each
/// resample costs a pass over every base row.
pub const MAX_BOOTSTRAP: usize = 100_000;

/// Refuse counts above the stated limits before anything is allocated.
fn check_counts(args: &SensitivityArgs) -> Result<()> {
    for (flag, v, max) in [
        ("--samples", args.samples, MAX_CHECK_SAMPLES),
        ("--trajectories", args.trajectories, MAX_CHECK_TRAJECTORIES),
        ("--bootstrap", args.bootstrap, MAX_BOOTSTRAP),
    ] {
        if v > max {
            anyhow::bail!("{flag} {v}: expected at most {max}");
        }
    }
    Ok(())
}

/// Run `hdw sensitivity`.
pub fn run(args: SensitivityArgs) -> Result<()> {
    check_counts(&args)?;
    match (&args.dir, args.check) {
        (Some(dir), None) => {
            let options = Options {
                metrics: args.metrics.clone(),
                sobol: SobolOptions {
                    bootstrap: args.bootstrap,
                    seed: args.seed,
                    ..SobolOptions::default()
                },
            };
            let analysis = analyse_dir(dir, &options)
                .with_context(|| format!("sensitivity analysis of {}", dir.display()))?;
            match args.format {
                FormatArg::Table => print_study_table(&analysis),
                FormatArg::Json => {
                    println!("{}", serde_json::to_string_pretty(&study_json(&analysis))?)
                }
            }
            Ok(())
        }
        (None, Some(CheckCase::Ishigami)) => run_check(&args),
        _ => bail!("give exactly one of DIR or --check ishigami"),
    }
}

/// The Ishigami self-check.
fn run_check(args: &SensitivityArgs) -> Result<()> {
    if args.metrics.is_some() {
        bail!("--metrics applies to a study folder (DIR), not to --check");
    }
    let check = ishigami_check(&config(args)).context("Ishigami self-check")?;
    match args.format {
        FormatArg::Table => print_table(&check),
        FormatArg::Json => println!("{}", serde_json::to_string_pretty(&to_json(&check))?),
    }
    if !check.passed {
        bail!(
            "self-check failed: max |computed − analytic| = {:.4} (tolerance {}), Morris ranking {}",
            check.max_abs_error,
            check.tolerance,
            if check.morris_ranks_ok { "correct" } else { "wrong" }
        );
    }
    Ok(())
}

/// A number for JSON: NaN and infinities become null.
fn finite(x: f64) -> serde_json::Value {
    if x.is_finite() { json!(x) } else { serde_json::Value::Null }
}

/// One result row as JSON, with the column names of sensitivity.parquet.
fn row_json(part: &str, r: &SensitivityRow) -> serde_json::Value {
    json!({
        "part": part, "method": r.method.as_str(), "parameter": r.parameter, "metric": r.metric,
        "S1": finite(r.s1), "S1_lo": finite(r.s1_lo), "S1_hi": finite(r.s1_hi),
        "ST": finite(r.st), "ST_lo": finite(r.st_lo), "ST_hi": finite(r.st_hi),
        "mu": finite(r.mu), "mu_star": finite(r.mu_star), "sigma": finite(r.sigma),
        "n_used": r.n_used, "n_dropped": r.n_dropped, "note": r.note,
    })
}

/// The JSON document of a study analysis (see the command's help).
fn study_json(a: &Analysis) -> serde_json::Value {
    let parts: Vec<_> = a
        .parts
        .iter()
        .map(|p| {
            json!({
                "part": p.part, "method": p.method.as_str(), "parameters": p.parameters,
                "metrics": p.metrics, "groups": p.groups, "runs": p.runs, "failed": p.failed,
                "missing": p.missing,
            })
        })
        .collect();
    let rows: Vec<_> =
        a.parts.iter().flat_map(|p| p.rows.iter().map(|r| row_json(&p.part, r))).collect();
    let ranking: Vec<_> = a
        .parts
        .iter()
        .flat_map(|p| {
            p.metrics.iter().map(|m| {
                let ranked = p.ranked(m);
                json!({
                    "part": p.part, "metric": m,
                    "by": if p.method == SensitivityMethod::Sobol { "ST" } else { "mu_star" },
                    "order": ranked.iter().map(|r| r.parameter.as_str()).collect::<Vec<_>>(),
                    "n_used": ranked.first().map_or(0, |r| r.n_used),
                    "n_dropped": ranked.first().map_or(0, |r| r.n_dropped),
                })
            })
        })
        .collect();
    json!({
        "study": a.study,
        "parts": parts,
        "rows": rows,
        "ranking": ranking,
        "files": {
            "table": a.table.display().to_string(),
            "markdown": a.markdown.display().to_string(),
            "plots": a.plots.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
        },
        "skipped_plots": a.skipped_plots,
    })
}

/// Per part and metric, the parameters best first with their indices.
fn print_study_table(a: &Analysis) {
    let v = |x: f64| if x.is_finite() { format!("{x:.3}") } else { "–".to_string() };
    let ci = |lo: f64, hi: f64| format!("[{}, {}]", v(lo), v(hi));
    for p in &a.parts {
        println!(
            "study '{}', part '{}': {} over {} parameters, {} {}, {} runs ({} failed, {} missing)",
            a.study,
            p.part,
            p.method,
            p.parameters.len(),
            p.groups,
            p.group_word(),
            p.runs,
            p.failed,
            p.missing
        );
        for m in &p.metrics {
            let rows = p.ranked(m);
            let Some(first) = rows.first() else { continue };
            println!();
            println!(
                "{m}: {} {} used, {} dropped{}",
                first.n_used,
                p.group_word(),
                first.n_dropped,
                first.note.as_deref().map(|n| format!(" ({n})")).unwrap_or_default()
            );
            match p.method {
                SensitivityMethod::Sobol => {
                    println!(
                        "  {:<10} {:>8} {:>18} {:>8} {:>18}",
                        "", "S1", "95 % interval", "ST", "95 % interval"
                    );
                    for r in &rows {
                        println!(
                            "  {:<10} {:>8} {:>18} {:>8} {:>18}",
                            r.parameter,
                            v(r.s1),
                            ci(r.s1_lo, r.s1_hi),
                            v(r.st),
                            ci(r.st_lo, r.st_hi)
                        );
                    }
                }
                SensitivityMethod::Morris => {
                    let g =
                        |x: f64| if x.is_finite() { format!("{x:.3e}") } else { "–".to_string() };
                    println!("  {:<10} {:>11} {:>11} {:>11}", "", "mu*", "mu", "sigma");
                    for r in &rows {
                        println!(
                            "  {:<10} {:>11} {:>11} {:>11}",
                            r.parameter,
                            g(r.mu_star),
                            g(r.mu),
                            g(r.sigma)
                        );
                    }
                }
            }
        }
        println!();
    }
    println!("table: {}", a.table.display());
    println!("summary: {}", a.markdown.display());
    for p in &a.plots {
        println!("plot: {}", p.display());
    }
    for s in &a.skipped_plots {
        println!("plot skipped: {s}");
    }
}

/// The JSON document: arrays in the order x1, x2, x3; NaN becomes null.
fn to_json(c: &IshigamiCheck) -> serde_json::Value {
    let arr = |v: [f64; 3]| json!(v.map(|x| x.is_finite().then_some(x)));
    json!({
        "check": "ishigami",
        "a": c.config.function.a,
        "b": c.config.function.b,
        "parameters": ISHIGAMI_NAMES,
        "S1": arr(c.s1),
        "S1_lo": arr(c.s1_lo),
        "S1_hi": arr(c.s1_hi),
        "ST": arr(c.st),
        "ST_lo": arr(c.st_lo),
        "ST_hi": arr(c.st_hi),
        "S1_analytic": arr(c.s1_analytic),
        "ST_analytic": arr(c.st_analytic),
        "mu_star": arr(c.mu_star),
        "mu": arr(c.mu),
        "sigma": arr(c.sigma),
        "samples": c.config.base_samples,
        "sobol_runs": c.sobol_runs,
        "trajectories": c.config.trajectories,
        "levels": c.config.levels,
        "morris_runs": c.morris_runs,
        "bootstrap": c.config.bootstrap,
        "seed": c.config.seed,
        "max_abs_error": c.max_abs_error.is_finite().then_some(c.max_abs_error),
        "tolerance": c.tolerance,
        "morris_ranks_ok": c.morris_ranks_ok,
        "passed": c.passed,
    })
}

/// Computed beside analytic values, one line per parameter.
fn print_table(c: &IshigamiCheck) {
    let cfg = &c.config;
    println!(
        "Ishigami self-check (a = {}, b = {}): Sobol' N = {} ({} runs), Morris r = {}, p = {} ({} runs), seed {}",
        cfg.function.a,
        cfg.function.b,
        cfg.base_samples,
        c.sobol_runs,
        cfg.trajectories,
        cfg.levels,
        c.morris_runs,
        cfg.seed
    );
    println!();
    println!(
        "{:<5} {:>8} {:>18} {:>8}   {:>8} {:>18} {:>8}   {:>8} {:>8}",
        "", "S1", "95 % interval", "exact", "ST", "95 % interval", "exact", "mu*", "sigma"
    );
    let ci = |lo: f64, hi: f64| format!("[{lo:.3}, {hi:.3}]");
    for (i, name) in ISHIGAMI_NAMES.iter().enumerate() {
        println!(
            "{:<5} {:>8.4} {:>18} {:>8.4}   {:>8.4} {:>18} {:>8.4}   {:>8.3} {:>8.3}",
            name,
            c.s1[i],
            ci(c.s1_lo[i], c.s1_hi[i]),
            c.s1_analytic[i],
            c.st[i],
            ci(c.st_lo[i], c.st_hi[i]),
            c.st_analytic[i],
            c.mu_star[i],
            c.sigma[i]
        );
    }
    println!();
    println!(
        "max |computed - analytic| = {:.4} (tolerance {}); Morris mu* ranks x1, x2 above x3: {}",
        c.max_abs_error,
        c.tolerance,
        if c.morris_ranks_ok { "yes" } else { "no" }
    );
    println!("{}", if c.passed { "PASS" } else { "FAIL" });
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: SensitivityArgs,
    }

    #[test]
    fn cli_defaults_are_the_library_defaults() {
        let cli = Cli::parse_from(["hdw", "--check", "ishigami"]);
        assert_eq!(config(&cli.args), IshigamiCheckConfig::default());
    }

    #[test]
    fn json_has_the_documented_arrays() {
        let cli = Cli::parse_from(["hdw", "--check", "ishigami", "--samples", "64"]);
        let cfg = IshigamiCheckConfig { bootstrap: 20, trajectories: 20, ..config(&cli.args) };
        let doc = to_json(&ishigami_check(&cfg).unwrap());
        for key in ["S1", "ST", "S1_analytic", "ST_analytic", "mu_star"] {
            assert_eq!(doc[key].as_array().map(Vec::len), Some(3), "{key}");
        }
        assert_eq!(doc["samples"], 64);
    }
}
