//! `hdw sensitivity`: global sensitivity analysis. For now the `--check ishigami`
//! self-check, which runs the Sobol' and Morris code on a function with known indices.

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use hd_sweep::sensitivity::{
    ISHIGAMI_BASE_SAMPLES, ISHIGAMI_NAMES, Ishigami, IshigamiCheck, IshigamiCheckConfig,
    ishigami_check,
};
use serde_json::json;

/// Global sensitivity: Sobol' indices (first order, total) and Morris screening.
#[derive(Args, Debug)]
#[command(
    after_help = "The check runs the same design and estimator code a study uses on the Ishigami function\n(a = 7, b = 0.1; x1, x2, x3 uniform on [-pi, pi]) and prints computed beside analytic indices:\nS1 ~ (0.3139, 0.4424, 0), ST ~ (0.5576, 0.4424, 0.2437). At the default N = 4096 base samples\n(20480 runs) every index is within 0.02; Morris mu* must rank x1 and x2 above x3. Exits non-zero\nwhen either fails.\n--format json prints one object with arrays S1, ST, S1_analytic, ST_analytic (order x1, x2, x3),\ntheir intervals S1_lo/S1_hi/ST_lo/ST_hi, mu_star, mu, sigma, and the sample counts.\n\nExample:\n  hdw sensitivity --check ishigami\n  hdw sensitivity --check ishigami --samples 1024 --seed 3 --format json"
)]
pub struct SensitivityArgs {
    /// Self-check on a test function with analytic indices.
    #[arg(long, value_name = "CASE", required = true)]
    pub check: Option<CheckCase>,
    /// Sobol' base samples N (runs: N·(d+2)); powers of two keep the sequence balanced.
    #[arg(long, default_value_t = ISHIGAMI_BASE_SAMPLES, value_name = "N")]
    pub samples: usize,
    /// Morris trajectories r (runs: r·(d+1)).
    #[arg(long, default_value_t = 500, value_name = "R")]
    pub trajectories: usize,
    /// Morris grid levels p (even; step Δ = p/(2(p−1)) of each range).
    #[arg(long, default_value_t = 4, value_name = "P")]
    pub levels: usize,
    /// Bootstrap resamples for the 95 % intervals (0 = none).
    #[arg(long, default_value_t = 1000)]
    pub bootstrap: usize,
    /// Seed of the Sobol' digital shift, the Morris trajectories and the bootstrap.
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

/// Run `hdw sensitivity`.
pub fn run(args: SensitivityArgs) -> Result<()> {
    let Some(CheckCase::Ishigami) = args.check else {
        bail!("nothing to do: pass --check ishigami");
    };
    let check = ishigami_check(&config(&args)).context("Ishigami self-check")?;
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
