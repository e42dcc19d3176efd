//! `hdw fit hysteresis|friction`: identify parameters from recorded data, with
//! uncertainty; writes fit.json, the fitted signals and plots.

use super::common::{ensure_dir, staged_plot};
use super::fit_input::{
    FrictionUnits, column_names, data_context, friction_series, load, scale, source,
};
use super::fit_progress::FitProgress;
use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use hd_ident::{
    FitReport, Fixed, FrictionOptions, JointSettings, SeparableFit, SteadyData, TransientData,
    fit_friction_settings,
};
use hd_io::atomic::Staged;
use hd_model::laws::friction::{FrictionLaw, LuGre};
use hd_plot::{Series, fit_plot, residual_plot};
use std::path::{Path, PathBuf};

/// Fit model parameters to recorded data.
#[derive(Args, Debug)]
#[command(
    allow_negative_numbers = true,
    after_help = "Each fit writes DIR/fit.json (values, standard errors, 95 % intervals, a determined flag with the\n\
reason when the data cannot fix a parameter, correlations, RMS, R², iterations, termination), the\n\
fitted signals and SVG plots, and prints a table.\n\n\
Example:\n  hdw fit hysteresis data/hysteresis-wide-range.parquet --out out/fit-wide\n  hdw fit hysteresis data/hysteresis-paper-range.csv --law all --out out/compare\n  hdw fit friction --steady data/friction-steady.csv --transient data/friction-transient.parquet --out out/fit-fric\n  hdw fit drive --config data/emps/fit.toml --out out/emps"
)]
pub struct FitArgs {
    #[command(subcommand)]
    pub what: FitWhat,
}

/// What to fit.
#[derive(Subcommand, Debug)]
pub enum FitWhat {
    /// Fit a stiffness law (memory, maxwell-slip, bouc-wen, or all ranked by BIC) to a
    /// torque–deflection record.
    Hysteresis(super::fit_hysteresis::HysteresisArgs),
    /// Fit the LuGre parameters: static (Tc, Ts, ws, sigma2) and/or dynamic (sigma0, sigma1).
    Friction(FrictionArgs),
    /// Identify a rigid or a compliant drive from its logged records.
    ///
    /// A rigid drive's mass/inertia, friction and offset come from its logged closed loop; with
    /// transmission = "compliant", the compliant drive from voltage tests or its own loop.
    ///
    /// Rigid: the configuration names the records, the drive gain, the controller and the
    /// friction law(s) (data/emps/fit.toml).
    ///
    /// Compliant (transmission = "compliant"): the simulator's drive (DC motor, hysteretic
    /// gear, load, LuGre friction) re-run under each record's voltage and fitted to the motor
    /// and load encoders and the current (data/compliant/fit.toml; in its position loop with
    /// a [controller], data/compliant/loop.toml). Its keys:
    ///   params_file                start values and the gear ratio N (an hdw simulate file)
    ///   voltage_between            "hold" (default: a digital amplifier), "linear", "cubic"
    ///   current_sampled            "after" (default: the current read just after the new
    ///                              voltage is applied) or "before" (just before it)
    ///   km_equals_ke, directional_friction, directional_load_friction, friction_velocity,
    ///   axis, substeps
    ///   [[experiment]]             name, file, time, voltage (or command and reference),
    ///                              motor, load, current, *_scale factors to SI
    ///   [controller]               kp, kv, delay, feedback, amplifier (closed-loop records)
    ///   [fit]                      outputs, noise.motor/load/current/command, free, fix,
    ///                              max_iterations, current_offset
    ///   [params], [bounds]         start values and bounds by parameter name
    /// A fit that does not reach the noise, a current whose scale the voltage and R do not
    /// explain, or a controller that does not reproduce the recorded command is in doubt:
    /// fit.json has "in_doubt": true, the reasons in "doubt" (the likely cause named:
    /// voltage_between, current_sampled, direction-dependent friction, a scale), and
    /// "in_doubt" instead of "determined" on each parameter.
    ///
    /// Compliant example:
    ///   hdw synth drive --input chirp --freq 5 --t-end 2 --out out/compliant/chirp.csv
    ///   hdw synth drive --input multisine --freq 5 --t-end 2 --seed 2 --out out/compliant/multisine.csv
    ///   hdw fit drive --config data/compliant/fit.toml --out out/compliant/fit \
    ///       --validate out/compliant/multisine.csv
    #[command(verbatim_doc_comment)]
    Drive(super::fit_drive::DriveArgs),
}

/// `hdw fit friction`.
#[derive(Args, Debug)]
#[command(
    allow_negative_numbers = true,
    after_help = "One time series (--transient alone): every LuGre parameter at once. The bristle state runs along\n\
the measured ω(t) (each sample interval at its mean speed, split where ω changes sign, from the\n\
first measured torque) by the LuGre law's exact updates, with exact sensitivities carried beside\n\
it; σ1, σ2 (and the offset) follow by linear least squares at every trial. The static levels start\n\
from quasi-steady samples picked from the series itself, σ0 from a grid over ln σ0 refined by\n\
Brent's method, then Levenberg–Marquardt (exact Jacobian) refines Tc, Ts, ωs, σ0 (and Tc_neg,\n\
Ts_neg) jointly from several starts in parallel; a refinement that stops on its iteration budget\n\
says so as a warning. A trial that gives non-finite values counts as a bad trial.\n\
Steady sweep alone (--steady): T(ω) = sign(ω)·(Tc + (Ts − Tc)·exp(−(ω/ωs)²)) + σ2·ω, linear in Tc,\n\
Ts, σ2 for a given ωs. Both files: the static stage, then σ0 and σ1 from the series with the static\n\
parameters held, the static stage's uncertainty carried into their errors.\n\
Rig files need no preprocessing: only the named columns are read (CSV, tab- or semicolon-separated,\n\
# comment lines, or Parquet); --*-scale factors convert to SI (a negative torque scale flips the\n\
sign); --position-column derives the speed from an encoder position (Savitzky–Golay).\n\n\
Outputs (in --out DIR):\n  fit.json                   parameters (value, std_error, ci95, determined, note), correlation, rms,\n                             r2, iterations, termination, data preprocessing (and each stage's report)\n  steady-fitted.parquet      omega, torque, fitted, residual          (with --steady)\n  stribeck.svg               torque in the direction of motion against log10 |ω|, measured and fitted\n  residuals-steady.svg       steady-state residuals against log10 |ω|\n  transient-fitted.parquet   t, omega, torque, fitted, residual       (with --transient)\n  transient.svg              measured vs fitted friction torque over time, residuals below\n  friction-speed.svg         measured and fitted torque against speed (the friction loop)\n  residuals-transient.svg    transient residuals over time\n\n\
Examples:\n  hdw synth friction --transient --profile joint --set Tc=0.2 --set Ts=0.35 --out out/joint.csv\n  hdw fit friction --transient out/joint.csv --out out/fit-joint\n  hdw fit friction --transient data/tribometer-reciprocating.txt \\\n      --transient-columns 'Time [s],Friction [uN]' --position-column 'Position [mm]' \\\n      --position-scale 1e-3 --torque-scale -1e-6 --asymmetric --out out/fit-tribometer\n  hdw fit friction --steady data/friction-steady.csv --transient data/friction-transient.parquet --out out/fit-fric"
)]
pub struct FrictionArgs {
    /// Steady-state sweep (.csv or .parquet): speed [rad/s] and friction torque [N·m].
    #[arg(long, value_name = "FILE")]
    pub steady: Option<PathBuf>,
    /// Names of the speed and torque columns of the steady-state file.
    #[arg(long, value_name = "OMEGA,TORQUE", default_value = "omega,torque")]
    pub steady_columns: String,
    /// Column of the steady-state file holding the torque the gear transmitted [N·m] (scaled
    /// by --torque-scale): fits the load factors mu_c_fwd, mu_s_fwd, mu_c_back, mu_s_back of
    /// the levels Tc + μc·|Tb|, Ts + μs·|Tb| (steady-state table only).
    #[arg(long, value_name = "NAME")]
    pub load_column: Option<String>,
    /// Time series (.csv or .parquet): time [s], speed [rad/s], friction torque [N·m].
    #[arg(long, value_name = "FILE")]
    pub transient: Option<PathBuf>,
    /// Names of the time, speed and torque columns of the time-series file (T,TORQUE with
    /// --position-column).
    #[arg(long, value_name = "T,OMEGA,TORQUE", default_value = "t,omega,torque")]
    pub transient_columns: String,
    /// Fit separate Coulomb and static levels for negative speeds (Tc_neg, Ts_neg; Tc, Ts then
    /// mean positive speeds) and a constant torque offset of the measurement (offset [N·m]).
    /// The symmetric law with the same offset is fitted first (the richer fit starts from it)
    /// and reported too: fit.json `nested`, and a remark comparing the two by BIC.
    #[arg(long)]
    pub asymmetric: bool,
    /// Fit a constant torque offset of the measurement (offset [N·m]), e.g. a sensor bias.
    #[arg(long)]
    pub offset: bool,
    /// Take none of the time-series fit's shortcuts: every start runs to its end, the
    /// asymmetric fit searches σ0 again, and every Coulomb level is also tried on its bound
    /// 0. Slower; the shortcuts are checked never to change the optimum on a corpus of
    /// records (docs/model.md §5), and this lets you check them on yours.
    #[arg(long)]
    pub exhaustive: bool,
    #[command(flatten)]
    pub units: FrictionUnits,
    /// Hold a parameter at a value instead of fitting it, e.g. `--fix sigma2=0` (repeatable).
    #[arg(long = "fix", value_name = "NAME=VALUE")]
    pub fix: Vec<String>,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "out/fit-friction")]
    pub out: PathBuf,
}

/// Write fit.json and print the table.
pub(crate) fn report_out(dir: &Path, report: &FitReport) -> Result<()> {
    let path = dir.join("fit.json");
    let text = report.to_json();
    hd_io::atomic::write_atomically(&path, |f| {
        use std::io::Write;
        f.write_all(text.as_bytes()).map_err(|e| hd_io::IoError::fs(&path, e))
    })?;
    // The table is a summary: a closed pipe (`| head`) is not an error.
    use std::io::Write;
    let _ = writeln!(std::io::stdout().lock(), "{}", report.table());
    // Warnings (an iteration budget reached, a sampling error that matters) also go to
    // stderr, where they are seen when the table is redirected.
    for remark in report.remarks.iter().filter(|r| r.starts_with("warning")) {
        eprintln!("{remark}");
    }
    Ok(())
}

fn fitted_columns(fit: &SeparableFit, measured: &[f64]) -> [Vec<f64>; 3] {
    [measured.to_vec(), fit.fitted.clone(), fit.residuals.clone()]
}

/// Run `hdw fit ...`.
pub fn run(args: FitArgs) -> Result<()> {
    match args.what {
        FitWhat::Hysteresis(a) => super::fit_hysteresis::run(a),
        FitWhat::Friction(a) => run_friction(a),
        FitWhat::Drive(a) => super::fit_drive::run(a),
    }
}

fn run_friction(args: FrictionArgs) -> Result<()> {
    let fixed = Fixed::parse(&args.fix).context("--fix")?;
    if args.steady.is_none() && args.transient.is_none() {
        bail!("no friction data: give --steady FILE, --transient FILE or both");
    }
    let mut sources = Vec::new();
    let u = &args.units;
    let steady = match &args.steady {
        Some(path) => {
            let mut names = column_names(&args.steady_columns, &[2], "--steady-columns")?;
            names.extend(args.load_column.clone());
            let mut cols = load(path, &names)?;
            let mut tb = if args.load_column.is_some() { cols.pop() } else { None };
            let (mut torque, mut omega) = (cols.pop().unwrap(), cols.pop().unwrap());
            let mut log = Vec::new();
            scale(&mut omega, u.speed_scale, "speed", "--speed-scale", &mut log)?;
            scale(&mut torque, u.torque_scale, "torque", "--torque-scale", &mut log)?;
            if let Some(tb) = tb.as_mut() {
                scale(tb, u.torque_scale, "transmitted torque", "--torque-scale", &mut log)?;
            }
            let roles = ["omega", "torque", "load"];
            let mut d = SteadyData::new(omega, torque)
                .with_context(|| data_context(path, &roles, &names))?;
            if let Some(tb) = tb {
                d = d.with_load(tb).with_context(|| data_context(path, &roles, &names))?;
            }
            sources.push(source("steady", path, &names, log));
            Some(d)
        }
        None => None,
    };
    if args.load_column.is_some() && args.steady.is_none() {
        bail!("--load-column needs --steady FILE (the steady-state table it belongs to)");
    }
    if u.position_column.is_some() && args.transient.is_none() {
        bail!("--position-column needs --transient FILE (the time series it belongs to)");
    }
    let transient = match &args.transient {
        Some(path) => {
            let s = friction_series(path, &args.transient_columns, u)?;
            let roles = if u.position_column.is_some() {
                ["t", "position", "torque"]
            } else {
                ["t", "omega", "torque"]
            };
            let d = TransientData::new(s.t, s.omega, s.torque)
                .with_context(|| data_context(path, &roles, &s.names))?;
            sources.push(source("transient", path, &s.names, s.log));
            Some(d)
        }
        None => None,
    };
    let opts =
        FrictionOptions { asymmetric: args.asymmetric, offset: args.offset || args.asymmetric };
    let samples =
        steady.as_ref().map_or(0, |d| d.len()) + transient.as_ref().map_or(0, |d| d.len());
    let progress = FitProgress::start(format!("fitting friction to {samples} samples"));
    let settings =
        if args.exhaustive { JointSettings::exhaustive() } else { JointSettings::default() };
    let fit = fit_friction_settings(steady.as_ref(), transient.as_ref(), &fixed, opts, settings);
    progress.finish();
    let fit = fit.context("friction fit")?;
    let dir = ensure_dir(&args.out)?;
    // Every output lands together when all are written, or none does (earlier results kept).
    hd_io::atomic::group(|| -> Result<()> {
        let mut report = fit.report.clone();
        report.data = sources;
        report_out(&dir, &report)?;
        if let (Some(d), Some(s)) = (&steady, &fit.steady) {
            steady_outputs(&dir, d, s, &fit.law)?;
        }
        if let (Some(d), Some(s)) = (&transient, &fit.transient) {
            transient_outputs(&dir, d, s)?;
        }
        Ok(())
    })?;
    eprintln!("friction fit in {:.3} s; wrote {}", fit.report.wall_time_s, dir.display());
    Ok(())
}

/// The time series' outputs: fitted table and three plots. The plots are drawn on their
/// own threads while this one writes the table (the fit has left both cores idle), and
/// join the caller's output group when done.
fn transient_outputs(dir: &Path, d: &TransientData, s: &SeparableFit) -> Result<()> {
    let [m, f, r] = fitted_columns(s, d.torque());
    let (t, w, y) = (d.t(), d.omega(), d.torque());
    // Measured and fitted torque against `x`, drawn to `file`.
    let against = |x: &'_ [f64], file: &'static str, title: &'static str, x_label: &'static str| {
        let measured = Series::new("measured", x.to_vec(), y.to_vec());
        let fitted = Series::new("fitted (LuGre)", x.to_vec(), f.clone());
        draw_staged(&dir.join(file), |p| {
            fit_plot(p, title, x_label, "Tf [N·m]", &measured, &fitted)
        })
    };
    let staged = std::thread::scope(|scope| -> Result<Vec<Staged>> {
        let transient = scope.spawn(|| {
            let title = "Friction fit: torque under the imposed speed";
            against(t, "transient.svg", title, "t [s]")
        });
        let speed = scope.spawn(|| {
            let title = "Friction fit: torque against speed";
            against(w, "friction-speed.svg", title, "ω [rad/s]")
        });
        let residuals = scope.spawn(|| {
            let res = Series::new("residual", t.to_vec(), r.clone());
            let title = "Friction fit residuals (time series)";
            draw_staged(&dir.join("residuals-transient.svg"), |p| {
                residual_plot(p, title, "t [s]", "Tf [N·m]", &res)
            })
        });
        hd_io::write_columns(
            &dir.join("transient-fitted.parquet"),
            &["t", "omega", "torque", "fitted", "residual"],
            &[t.to_vec(), w.to_vec(), m.clone(), f.clone(), r.clone()],
        )?;
        [transient, speed, residuals]
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|_| bail!("a plot thread panicked")))
            .collect()
    })?;
    for st in staged {
        hd_io::atomic::finish(st)?;
    }
    Ok(())
}

/// A plot drawn to the temporary of `dest`, not yet in place.
fn draw_staged(
    dest: &Path,
    draw: impl FnOnce(&Path) -> std::result::Result<(), hd_plot::PlotError>,
) -> Result<Staged> {
    let staged = Staged::new(dest)?;
    draw(staged.path()).with_context(|| format!("drawing {}", dest.display()))?;
    Ok(staged)
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
    staged_plot(&dir.join("stribeck.svg"), |p| fit_plot(p, title, xl, yl, &measured, &fitted))?;
    let res = Series::new("residual", speeds, r);
    let title = "Friction fit residuals (steady state)";
    staged_plot(&dir.join("residuals-steady.svg"), |p| {
        residual_plot(p, title, xl, "Tf [N·m]", &res)
    })?;
    Ok(())
}
