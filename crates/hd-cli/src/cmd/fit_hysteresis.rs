//! `hdw fit hysteresis`: one stiffness law, or every law ranked by BIC (`--law all`).

use super::common::{ensure_dir, staged_plot};
use super::fit::report_out;
use super::fit_input::{angle_factor, column_names, data_context, load, scale, source};
use super::fit_progress::FitProgress;
use anyhow::{Context, Result};
use clap::Args;
use hd_ident::stiffness::{Law, LawFit, LawOptions, compare_laws, fit_law};
use hd_ident::{DataSource, Fixed, HysteresisData};
use hd_model::{Cells, OutTable};
use hd_plot::{Series, ThinnedCurve, fit_plot, residual_plot};
use std::path::{Path, PathBuf};

/// `hdw fit hysteresis`.
#[derive(Args, Debug)]
#[command(
    allow_negative_numbers = true,
    after_help = "Laws (--law):\n  memory        f(θ) + z, ż = A·θ̇ − B·z (the seed's law; rate-dependent). For each trial B, a, b, c and A\n                follow by linear least squares; B from a grid over ln B refined by Brent's method, searched in\n                [0.1/record length, 10/median sample interval]. The memory starts at z = 0.\n  maxwell-slip  f(θ) + Σ kᵢ·eᵢ, elastoplastic elements (rate-independent). Yield deflections start log-spaced\n                over two decades up to 0.9 × half the largest excursion between reversals; a, b, c and kᵢ ≥ 0\n                by exact non-negative least squares, yield deflections refined by Levenberg–Marquardt.\n  bouc-wen      f(θ) + α·w, ẇ = A·θ̇ − β·|θ̇|·|w|^(n−1)·w − γ·θ̇·|w|^n with A = 1 (rate-independent).\n  all           every law on the same data, ranked by BIC = n·ln(RSS/n) + p·ln n.\n\n\
Outputs (in --out DIR; with --law all in DIR/<law>/ for each law):\n  fit.json         parameters (value, std_error, ci95, determined, note), correlation, rms, r2, iterations,\n                   termination, loop_energy (per block of cycles of similar amplitude: the fitted law's and\n                   the measured torque's ∮ T dθ per cycle [J])\n  fitted.parquet   t, theta, torque, fitted, residual (row for row with the input)\n  loop.svg         measured vs fitted torque–deflection loop, residuals below\n  memory.svg       the same with c·θ taken off both, so the hysteresis loops show\n  residuals.svg    residuals over time\nWith --law all, also DIR/comparison.json (best first: law, rms [N·m], aic, bic, delta_bic, parameters) and\nDIR/comparison.md.\n\n\
Examples:\n  hdw synth hysteresis --set c=6.5e4 --set B=150 --out out/hyst.csv\n  hdw fit hysteresis out/hyst.csv --out out/fit-hyst\n  hdw fit hysteresis data/hysteresis-paper-range.csv --fix a=0 --fix b=0 --out out/fit-paper\n  hdw synth hysteresis --law maxwell-slip --schedule quasi-static --out out/qs.csv\n  hdw fit hysteresis out/qs.csv --law all --out out/compare   # ranks the laws; see out/compare/comparison.md"
)]
pub struct HysteresisArgs {
    /// Data file (.csv with a header row, or .parquet).
    #[arg(value_name = "FILE")]
    pub file: PathBuf,
    /// Stiffness law: memory, maxwell-slip, bouc-wen, or all (every law, ranked by BIC).
    #[arg(long, value_name = "LAW", default_value = "memory")]
    pub law: String,
    /// Maxwell-slip: number of elements.
    #[arg(long, value_name = "N", default_value_t = hd_ident::stiffness::maxwell_slip::DEFAULT_ELEMENTS)]
    pub elements: usize,
    /// Names of the time [s], deflection [rad] and torque [N·m] columns.
    #[arg(long, value_name = "T,THETA,TORQUE", default_value = "t,theta,torque")]
    pub columns: String,
    /// Unit of the deflection column: rad, mrad, urad, deg, arcmin or arcsec.
    #[arg(long, value_name = "UNIT", default_value = "rad")]
    pub theta_unit: String,
    /// Factor from the file's time unit to seconds (e.g. 1e-3 for ms).
    #[arg(long, value_name = "K", default_value_t = 1.0, allow_hyphen_values = true)]
    pub time_scale: f64,
    /// Factor from the file's torque unit to N·m; negative flips the sign.
    #[arg(long, value_name = "K", default_value_t = 1.0, allow_hyphen_values = true)]
    pub torque_scale: f64,
    /// Fit a constant torque offset of the rig (`offset` [N·m]) with the law's parameters; a
    /// deflection offset is absorbed exactly by b, c and the torque offset (see fit.json).
    #[arg(long)]
    pub fit_offsets: bool,
    /// Hold a parameter at a value instead of fitting it, e.g. `--fix B=300` (repeatable;
    /// memory law only).
    #[arg(long = "fix", value_name = "NAME=VALUE")]
    pub fix: Vec<String>,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "out/fit-hysteresis")]
    pub out: PathBuf,
}

/// Run `hdw fit hysteresis`.
pub fn run(args: HysteresisArgs) -> Result<()> {
    let names = column_names(&args.columns, &[3], "--columns")?;
    let fixed = Fixed::parse(&args.fix).context("--fix")?;
    let to_rad = angle_factor(&args.theta_unit)?;
    let mut cols = load(&args.file, &names)?;
    let (mut torque, mut theta, mut t) =
        (cols.pop().unwrap(), cols.pop().unwrap(), cols.pop().unwrap());
    let mut log = Vec::new();
    scale(&mut t, args.time_scale, "time", "--time-scale", &mut log)?;
    scale(&mut theta, to_rad, "deflection", "--theta-unit", &mut log)?;
    scale(&mut torque, args.torque_scale, "torque", "--torque-scale", &mut log)?;
    let data = HysteresisData::new(t, theta, torque)
        .with_context(|| data_context(&args.file, &["t", "theta", "torque"], &names))?;
    let src = source("hysteresis", &args.file, &names, log);
    let opts = LawOptions { offset: args.fit_offsets, elements: args.elements, fixed };
    let dir = ensure_dir(&args.out)?;
    if args.law == "all" {
        let started = std::time::Instant::now();
        let progress =
            FitProgress::start(format!("fitting every stiffness law to {} samples", data.len()));
        let cmp = compare_laws(&data, &opts);
        progress.finish();
        let md = cmp.to_markdown(&args.file.display().to_string());
        // Every law's outputs and the comparison land together, or none does.
        hd_io::atomic::group(|| -> Result<()> {
            for fit in &cmp.fits {
                let sub = ensure_dir(&dir.join(fit.law.name()))?;
                outputs(&sub, &data, fit, &src)?;
                let cols = [data.t(), data.theta(), data.torque(), &fit.fitted, &fit.residuals];
                table_out(&sub, cols.map(<[f64]>::to_vec))?;
            }
            for (name, body) in [("comparison.json", cmp.to_json()), ("comparison.md", md.clone())]
            {
                let path = dir.join(name);
                hd_io::atomic::write_atomically(&path, |f| {
                    use std::io::Write;
                    f.write_all(body.as_bytes()).map_err(|e| hd_io::IoError::fs(&path, e))
                })?;
            }
            Ok(())
        })?;
        use std::io::Write;
        let _ = writeln!(std::io::stdout().lock(), "{md}");
        eprintln!(
            "compared {} laws on {} samples in {:.3} s; wrote {}",
            cmp.entries.len(),
            data.len(),
            started.elapsed().as_secs_f64(),
            dir.display()
        );
        return Ok(());
    }
    let law = Law::parse(&args.law).context("--law")?;
    let progress =
        FitProgress::start(format!("fitting the {} law to {} samples", law.name(), data.len()));
    let fit = fit_law(&data, law, &opts);
    progress.finish();
    let fit = fit.with_context(|| format!("fitting {}", args.file.display()))?;
    let (n, wall) = (data.len(), fit.report.wall_time_s);
    // fit.json, the plots and the table land together, or none does.
    hd_io::atomic::group(|| -> Result<()> {
        outputs(&dir, &data, &fit, &src)?;
        // The table last, from the columns themselves (no copy of a long record).
        let [t, theta, torque] = data.into_columns();
        table_out(&dir, [t, theta, torque, fit.fitted, fit.residuals])
    })?;
    eprintln!(
        "fitted the {} law to {n} samples in {wall:.3} s; wrote {}",
        law.name(),
        dir.display()
    );
    Ok(())
}

/// Most points handed to one curve of a plot: a longer record is first cut to the
/// envelope of its buckets of consecutive samples (each keeps its first, lowest, highest
/// and last point, in order), as `hdw simulate` does for long runs. The plot keeps at
/// most a few points per pixel column anyway, so the picture hardly changes, and a record
/// of millions of samples needs no copy of its columns to be drawn.
const PLOT_POINTS: usize = 200_000;

/// The points (x[k], y(k)) of one curve, cut to at most about [`PLOT_POINTS`] by
/// hd-plot's [`ThinnedCurve`] (buckets of consecutive samples, each keeping its first,
/// lowest, highest and last point).
fn curve(name: impl Into<String>, x: &[f64], y: impl Fn(usize) -> f64) -> Series {
    let n = x.len();
    if n <= PLOT_POINTS {
        return Series::new(name, x.to_vec(), (0..n).map(y).collect());
    }
    let mut thin = ThinnedCurve::new(PLOT_POINTS / 4);
    for (k, &xk) in x.iter().enumerate() {
        thin.push(xk, y(k));
    }
    let (xs, ys) = thin.points();
    Series::new(name, xs, ys)
}

/// fitted.parquet: t, theta, torque, fitted, residual (row for row with the input). The
/// frame is built one column at a time, each column's vector dropped once it is in, so a
/// long record is held about once while it is written, not three times.
fn table_out(dir: &Path, cols: [Vec<f64>; 5]) -> Result<()> {
    let names = ["t", "theta", "torque", "fitted", "residual"];
    let one = |name: &str, col: Vec<f64>| {
        let mut table = OutTable::default();
        table.push(name, Cells::F64(col));
        hd_io::parquet_out::out_table_frame(&table)
    };
    let mut cols = names.into_iter().zip(cols);
    let (name, first) = cols.next().expect("five columns");
    let mut frame = one(name, first)?;
    for (name, col) in cols {
        let part = one(name, col)?;
        frame.hstack_mut(part.columns())?;
    }
    hd_io::write_frame(&dir.join("fitted.parquet"), &mut frame)?;
    Ok(())
}

/// fit.json and the plots of one law's fit in `dir` (the table is [`table_out`]'s).
fn outputs(dir: &Path, data: &HysteresisData, fit: &LawFit, src: &DataSource) -> Result<()> {
    let mut report = fit.report.clone();
    report.data.push(src.clone());
    report_out(dir, &report)?;
    let law = fit.law.name();
    let (th, y, f) = (data.theta(), data.torque(), &fit.fitted);
    let measured = curve("measured", th, |k| y[k]);
    let fitted = curve(format!("fitted ({law})"), th, |k| f[k]);
    let title = format!("Hysteresis fit ({law}): transmitted torque against deflection");
    staged_plot(&dir.join("loop.svg"), |p| {
        fit_plot(p, &title, "θ [rad]", "Tb [N·m]", &measured, &fitted)
    })?;
    // The same loop with the linear spring c·θ taken off both, so the hysteresis shows.
    let c = fit.c;
    let measured = curve("measured − c·θ", th, |k| y[k] - c * th[k]);
    let fitted = curve(format!("fitted ({law}) − c·θ"), th, |k| f[k] - c * th[k]);
    let title = format!("Hysteresis fit ({law}): torque minus the linear spring c·θ");
    staged_plot(&dir.join("memory.svg"), |p| {
        fit_plot(p, &title, "θ [rad]", "Tb − c·θ [N·m]", &measured, &fitted)
    })?;
    let r = &fit.residuals;
    let res = curve("residual", data.t(), |k| r[k]);
    let title = format!("Hysteresis fit ({law}) residuals");
    staged_plot(&dir.join("residuals.svg"), |p| {
        residual_plot(p, &title, "t [s]", "Tb [N·m]", &res)
    })?;
    Ok(())
}
