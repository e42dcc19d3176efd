//! `hdw fit hysteresis|friction`: identify parameters from recorded data, with
//! uncertainty; writes fit.json, the fitted signals and plots.

use super::common::ensure_dir;
use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use hd_ident::{
    DataSource, FitReport, Fixed, HysteresisData, SeparableFit, SteadyData, TransientData,
    fit_friction, fit_hysteresis,
};
use hd_model::laws::friction::{FrictionLaw, LuGre};
use hd_plot::{Series, fit_plot, residual_plot};
use std::path::{Path, PathBuf};

/// Fit model parameters to recorded data.
#[derive(Args, Debug)]
#[command(
    after_help = "Each fit writes DIR/fit.json (values, standard errors, 95 % intervals, a determined flag with the\n\
reason when the data cannot fix a parameter, correlations, RMS, R², iterations, termination), the\n\
fitted signals and SVG plots, and prints a table.\n\n\
Example:\n  hdw fit hysteresis data/hysteresis-wide-range.parquet --out out/fit-wide\n  hdw fit friction --steady data/friction-steady.csv --transient data/friction-transient.parquet --out out/fit-fric"
)]
pub struct FitArgs {
    #[command(subcommand)]
    pub what: FitWhat,
}

/// What to fit.
#[derive(Subcommand, Debug)]
pub enum FitWhat {
    /// Fit a, b, c, A, B to a torque–deflection record.
    Hysteresis(HysteresisArgs),
    /// Fit the LuGre parameters: static (Tc, Ts, ws, sigma2) and/or dynamic (sigma0, sigma1).
    Friction(FrictionArgs),
}

/// `hdw fit hysteresis`.
#[derive(Args, Debug)]
#[command(
    after_help = "The memory state runs along the measured θ(t) (linear between samples) from z = 0 at the first\n\
sample. For each trial B, a, b, c and A follow by linear least squares; B comes from a grid over\n\
ln B refined by Brent's method from the best grid minima. Bounds are the registry ranges; B is\n\
searched in [0.1/record length, 10/median sample interval].\n\n\
Outputs (in --out DIR):\n  fit.json       parameters (value, std_error, ci95, determined, note), correlation, rms, r2,\n                 iterations, termination\n  fitted.parquet t, theta, torque, fitted, residual\n  loop.svg       measured vs fitted torque–deflection loop, residuals below\n  memory.svg     the same with c·θ taken off both, so the memory loops show\n  residuals.svg  residuals over time\n\n\
Example:\n  hdw synth hysteresis --set c=6.5e4 --set B=150 --out out/hyst.csv\n  hdw fit hysteresis out/hyst.csv --out out/fit-hyst\n  hdw fit hysteresis data/hysteresis-paper-range.csv --fix a=0 --fix b=0 --out out/fit-paper"
)]
pub struct HysteresisArgs {
    /// Data file (.csv with a header row, or .parquet).
    #[arg(value_name = "FILE")]
    pub file: PathBuf,
    /// Names of the time [s], deflection [rad] and torque [N·m] columns.
    #[arg(long, value_name = "T,THETA,TORQUE", default_value = "t,theta,torque")]
    pub columns: String,
    /// Hold a parameter at a value instead of fitting it, e.g. `--fix B=300` (repeatable).
    #[arg(long = "fix", value_name = "NAME=VALUE")]
    pub fix: Vec<String>,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "out/fit-hysteresis")]
    pub out: PathBuf,
}

/// `hdw fit friction`.
#[derive(Args, Debug)]
#[command(
    after_help = "Static stage (--steady): T(ω) = sign(ω)·(Tc + (Ts − Tc)·exp(−(ω/ωs)²)) + σ2·ω, linear in Tc, Ts,\n\
σ2 for a given ωs; ωs from a grid over ln ωs refined by Brent's method. Dynamic stage\n\
(--transient): the LuGre bristle state runs along the measured ω(t) (linear between samples,\n\
starting in steady state at the first speed) with hd-model's Rodas4; σ1 follows by linear least\n\
squares for each trial σ0, σ0 from a grid over ln σ0 refined by Brent's method. The static\n\
parameters are held at the static stage's result or at --fix values (σ2 defaults to 0); with both\n\
files the static stage's uncertainty is carried into σ0's and σ1's errors.\n\n\
Outputs (in --out DIR):\n  fit.json                   parameters (value, std_error, ci95, determined, note), correlation, rms,\n                             r2, iterations, termination (and each stage's report)\n  steady-fitted.parquet      omega, torque, fitted, residual          (with --steady)\n  stribeck.svg               torque in the direction of motion against log10 |ω|, measured and fitted\n  residuals-steady.svg       steady-state residuals against log10 |ω|\n  transient-fitted.parquet   t, omega, torque, fitted, residual       (with --transient)\n  transient.svg              measured vs fitted friction torque over time, residuals below\n  residuals-transient.svg    transient residuals over time\n\n\
Example:\n  hdw fit friction --steady data/friction-steady.csv --transient data/friction-transient.parquet --out out/fit-fric\n  hdw fit friction --transient data/friction-transient.parquet --fix Tc=0.2 --fix Ts=0.35 --fix ws=0.02 --fix sigma2=0.05"
)]
pub struct FrictionArgs {
    /// Steady-state sweep (.csv or .parquet): speed [rad/s] and friction torque [N·m].
    #[arg(long, value_name = "FILE")]
    pub steady: Option<PathBuf>,
    /// Names of the speed and torque columns of the steady-state file.
    #[arg(long, value_name = "OMEGA,TORQUE", default_value = "omega,torque")]
    pub steady_columns: String,
    /// Time series (.csv or .parquet): time [s], speed [rad/s], friction torque [N·m].
    #[arg(long, value_name = "FILE")]
    pub transient: Option<PathBuf>,
    /// Names of the time, speed and torque columns of the time-series file.
    #[arg(long, value_name = "T,OMEGA,TORQUE", default_value = "t,omega,torque")]
    pub transient_columns: String,
    /// Hold a parameter at a value instead of fitting it, e.g. `--fix sigma2=0` (repeatable).
    #[arg(long = "fix", value_name = "NAME=VALUE")]
    pub fix: Vec<String>,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "out/fit-friction")]
    pub out: PathBuf,
}

/// Split `a,b,c` into exactly `n` non-empty column names.
fn column_names(text: &str, n: usize, flag: &str) -> Result<Vec<String>> {
    let names: Vec<String> = text.split(',').map(|s| s.trim().to_string()).collect();
    if names.len() != n || names.iter().any(String::is_empty) {
        bail!("{flag} {text}: expected {n} comma-separated column names");
    }
    Ok(names)
}

/// Read the named columns of `path`.
fn load(path: &Path, names: &[String]) -> Result<Vec<Vec<f64>>> {
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    Ok(hd_io::read_columns(path, &refs)?)
}

fn source(role: &str, path: &Path, names: &[String]) -> DataSource {
    DataSource { role: role.into(), file: path.display().to_string(), columns: names.to_vec() }
}

/// Context for a data-set error: the file and which columns played which role.
fn data_context(path: &Path, roles: &[&str], names: &[String]) -> String {
    let map: Vec<String> = roles.iter().zip(names).map(|(r, n)| format!("{r} = '{n}'")).collect();
    format!("{} (columns {})", path.display(), map.join(", "))
}

/// Write fit.json and print the table.
fn report_out(dir: &Path, report: &FitReport) -> Result<()> {
    let path = dir.join("fit.json");
    let text = report.to_json();
    hd_io::atomic::write_atomically(&path, |f| {
        use std::io::Write;
        f.write_all(text.as_bytes()).map_err(|e| hd_io::IoError::fs(&path, e))
    })?;
    // The table is a summary: a closed pipe (`| head`) is not an error.
    use std::io::Write;
    let _ = writeln!(std::io::stdout().lock(), "{}", report.table());
    Ok(())
}

fn fitted_columns(fit: &SeparableFit, measured: &[f64]) -> [Vec<f64>; 3] {
    [measured.to_vec(), fit.fitted.clone(), fit.residuals.clone()]
}

/// Run `hdw fit ...`.
pub fn run(args: FitArgs) -> Result<()> {
    match args.what {
        FitWhat::Hysteresis(a) => run_hysteresis(a),
        FitWhat::Friction(a) => run_friction(a),
    }
}

fn run_hysteresis(args: HysteresisArgs) -> Result<()> {
    let names = column_names(&args.columns, 3, "--columns")?;
    let fixed = Fixed::parse(&args.fix).context("--fix")?;
    let mut cols = load(&args.file, &names)?;
    let (torque, theta, t) = (cols.pop().unwrap(), cols.pop().unwrap(), cols.pop().unwrap());
    let data = HysteresisData::new(t, theta, torque)
        .with_context(|| data_context(&args.file, &["t", "theta", "torque"], &names))?;
    let fit = fit_hysteresis(&data, &fixed)
        .with_context(|| format!("fitting {}", args.file.display()))?;
    let dir = ensure_dir(&args.out)?;
    let mut report = fit.report.clone();
    report.data.push(source("hysteresis", &args.file, &names));
    report_out(&dir, &report)?;
    let [m, f, r] = fitted_columns(&fit, data.torque());
    hd_io::write_columns(
        &dir.join("fitted.parquet"),
        &["t", "theta", "torque", "fitted", "residual"],
        &[data.t().to_vec(), data.theta().to_vec(), m, f.clone(), r.clone()],
    )?;
    let measured = Series::new("measured", data.theta().to_vec(), data.torque().to_vec());
    let fitted = Series::new("fitted", data.theta().to_vec(), f);
    let title = "Hysteresis fit: transmitted torque against deflection";
    fit_plot(&dir.join("loop.svg"), title, "θ [rad]", "Tb [N·m]", &measured, &fitted)?;
    // The same loop with the linear spring c·θ taken off both, so the memory loops show.
    let c = fit.value("c").unwrap_or(0.0);
    let minus_c =
        |y: &[f64]| -> Vec<f64> { y.iter().zip(data.theta()).map(|(v, th)| v - c * th).collect() };
    let measured = Series::new("measured − c·θ", data.theta().to_vec(), minus_c(data.torque()));
    let fitted = Series::new("fitted − c·θ", data.theta().to_vec(), minus_c(&fitted.y));
    let title = "Hysteresis fit: torque minus the linear spring c·θ";
    fit_plot(&dir.join("memory.svg"), title, "θ [rad]", "Tb − c·θ [N·m]", &measured, &fitted)?;
    let res = Series::new("residual", data.t().to_vec(), r);
    residual_plot(
        &dir.join("residuals.svg"),
        "Hysteresis fit residuals",
        "t [s]",
        "Tb [N·m]",
        &res,
    )?;
    eprintln!(
        "fitted {} samples in {:.3} s; wrote {}",
        data.len(),
        fit.report.wall_time_s,
        dir.display()
    );
    Ok(())
}

fn run_friction(args: FrictionArgs) -> Result<()> {
    let fixed = Fixed::parse(&args.fix).context("--fix")?;
    if args.steady.is_none() && args.transient.is_none() {
        bail!("no friction data: give --steady FILE, --transient FILE or both");
    }
    let mut sources = Vec::new();
    let steady = match &args.steady {
        Some(path) => {
            let names = column_names(&args.steady_columns, 2, "--steady-columns")?;
            let mut cols = load(path, &names)?;
            let (torque, omega) = (cols.pop().unwrap(), cols.pop().unwrap());
            let d = SteadyData::new(omega, torque)
                .with_context(|| data_context(path, &["omega", "torque"], &names))?;
            sources.push(source("steady", path, &names));
            Some(d)
        }
        None => None,
    };
    let transient = match &args.transient {
        Some(path) => {
            let names = column_names(&args.transient_columns, 3, "--transient-columns")?;
            let mut cols = load(path, &names)?;
            let (torque, omega, t) =
                (cols.pop().unwrap(), cols.pop().unwrap(), cols.pop().unwrap());
            let d = TransientData::new(t, omega, torque)
                .with_context(|| data_context(path, &["t", "omega", "torque"], &names))?;
            sources.push(source("transient", path, &names));
            Some(d)
        }
        None => None,
    };
    let fit = fit_friction(steady.as_ref(), transient.as_ref(), &fixed).context("friction fit")?;
    let dir = ensure_dir(&args.out)?;
    let mut report = fit.report.clone();
    report.data = sources;
    report_out(&dir, &report)?;
    if let (Some(d), Some(s)) = (&steady, &fit.steady) {
        steady_outputs(&dir, d, s, &fit.law)?;
    }
    if let (Some(d), Some(s)) = (&transient, &fit.transient) {
        let [m, f, r] = fitted_columns(s, d.torque());
        hd_io::write_columns(
            &dir.join("transient-fitted.parquet"),
            &["t", "omega", "torque", "fitted", "residual"],
            &[d.t().to_vec(), d.omega().to_vec(), m, f.clone(), r.clone()],
        )?;
        let measured = Series::new("measured", d.t().to_vec(), d.torque().to_vec());
        let fitted = Series::new("fitted (LuGre)", d.t().to_vec(), f);
        let title = "Friction fit: torque under the imposed speed";
        fit_plot(&dir.join("transient.svg"), title, "t [s]", "Tf [N·m]", &measured, &fitted)?;
        let res = Series::new("residual", d.t().to_vec(), r);
        let title = "Friction fit residuals (time series)";
        residual_plot(&dir.join("residuals-transient.svg"), title, "t [s]", "Tf [N·m]", &res)?;
    }
    eprintln!("friction fit in {:.3} s; wrote {}", fit.report.wall_time_s, dir.display());
    Ok(())
}

/// The steady-state outputs: fitted table, Stribeck curve and residuals.
fn steady_outputs(dir: &Path, d: &SteadyData, s: &SeparableFit, law: &LuGre) -> Result<()> {
    let [m, f, r] = fitted_columns(s, d.torque());
    hd_io::write_columns(
        &dir.join("steady-fitted.parquet"),
        &["omega", "torque", "fitted", "residual"],
        &[d.omega().to_vec(), m, f, r.clone()],
    )?;
    // Both signs on one log-speed axis: torque in the direction of motion against
    // log10 |ω|, with the fitted curve on a fine log grid over the measured speeds.
    let speeds: Vec<f64> = d.omega().iter().map(|w| w.abs().log10()).collect();
    let along: Vec<f64> = d.omega().iter().zip(d.torque()).map(|(w, t)| w.signum() * t).collect();
    let (lo, hi) =
        speeds.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &u| (l.min(u), h.max(u)));
    let n = 400;
    let grid: Vec<f64> = (0..=n).map(|k| lo + (hi - lo) * k as f64 / n as f64).collect();
    let curve: Vec<f64> = grid.iter().map(|&u| law.steady_torque(10f64.powf(u))).collect();
    let measured = Series::new("measured (both signs)", speeds.clone(), along);
    let fitted = Series::new("fitted Stribeck curve", grid, curve);
    let title = "Friction fit: steady-state torque against speed";
    let (xl, yl) = ("log10 |ω| [rad/s]", "Tf·sign(ω) [N·m]");
    fit_plot(&dir.join("stribeck.svg"), title, xl, yl, &measured, &fitted)?;
    let res = Series::new("residual", speeds, r);
    let title = "Friction fit residuals (steady state)";
    residual_plot(&dir.join("residuals-steady.svg"), title, xl, "Tf [N·m]", &res)?;
    Ok(())
}
