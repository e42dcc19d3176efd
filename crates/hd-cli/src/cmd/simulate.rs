//! `hdw simulate`: one run, written as trace.parquet, metrics.json and response.svg.

use super::common::{
    DEFAULT_MAX_OUTPUT_VALUES, check_output_size, ensure_dir, load_params, read_params_text,
    stage_json,
};
use super::control_args::ControlArgs;
use super::envelope::Envelope;
use super::model_args::ModelArgs;
use super::sim_progress::SimProgress;
use anyhow::{Context, Result};
use clap::Args;
use hd_io::atomic::Staged;
use hd_model::params_file::{
    controller_from_toml, friction_velocity_from_toml, stiffness_from_toml,
};
use hd_model::signals::Sample;
use hd_model::simulate::input_from_kind;
use hd_model::{HystLaw, Input, MetricSettings, SimConfig, SolverOptions};
use hd_model::{TRACE_COLUMNS, Trace, simulate_streaming};
use serde_json::json;
use std::path::{Path, PathBuf};

/// Runs with at most this many trace samples are plotted from every sample.
const FULL_PLOT_SAMPLES: f64 = 200_000.0;

/// Simulate one run of the motor–harmonic-drive–load system.
#[derive(Args, Debug)]
#[command(
    allow_negative_numbers = true,
    after_help = "Outputs (in --out DIR):\n  trace.parquet  t, u, i, theta_j, omega_j, theta_z, omega_z, theta, z, s, Tb, Tf, K, C0 (SI units)\n  metrics.json   every metric, the parameters used, solver statistics and wall time\n  response.svg   load angle over time and the Tb–θ loop\n(--no-trace writes metrics.json only.) The files are written under temporary names and renamed\ninto place together when the run succeeds: a failed or interrupted (Ctrl-C) run leaves DIR as it was.\nClosed loop (--controller pid) adds the trace columns ref, error, u_ff, tf_hat, tb_hat and the\nmetrics track_rms, track_max, reversal_peak, u_rms, saturation_fraction, torque_est_rms, ….\n\nExample:\n  hdw simulate --out out/demo\n  hdw simulate --stiffness maxwell-slip --set ms_n=10 --set ms_delta=3e-5 --out out/slip\n  hdw datasheet --k1 6.7e4 --k2 1.1e5 --k3 1.2e5 --t1 29 --t2 108 --hysteresis-loss 1 --out out/ds\n  hdw simulate --params out/ds/catalogue.toml --out out/catalogue   (the file says stiffness = \"catalogue\")\n  hdw simulate --variant damped --set Kbar=5e5 --input step --voltage 12 --t-end 0.1 --out out/step\n  hdw simulate --controller pid --kp 2000 --ki 20000 --kd 0 --feedback load --reference sine \\\n      --ref-amplitude 1e-3 --ref-freq 0.2 --t-end 12 --set Tc=1.5 --set Ts=2.5 --compensation friction --out out/pid\n  hdw simulate --controller pid --reference step --ref-amplitude 1e-3 --load-torque 5 --t-end 2 --out out/reg"
)]
pub struct SimulateArgs {
    /// Parameters, stiffness law, variant and solver.
    #[command(flatten)]
    pub model: ModelArgs,
    /// Input: sine, step, constant, chirp, or a CSV/Parquet file with columns t [s], u [V].
    #[arg(long, default_value = "sine", value_name = "KIND|FILE")]
    pub input: String,
    /// Voltage amplitude or level [V].
    #[arg(long, default_value_t = 24.0)]
    pub voltage: f64,
    /// Drive frequency [Hz] (sine; chirp sweeps from freq/10 to 10·freq over 1 s).
    #[arg(long, default_value_t = 50.0)]
    pub freq: f64,
    /// Simulated time [s].
    #[arg(long, default_value_t = 0.2)]
    pub t_end: f64,
    /// Trace sampling interval [s]; 0 = automatic (200 per drive cycle).
    #[arg(long, default_value_t = 0.0)]
    pub dt_out: f64,
    /// Whole cycles at the end of the run used for the periodic metrics.
    #[arg(long, default_value_t = 5)]
    pub cycles: usize,
    /// Metrics only: no trace.parquet and no response.svg (nothing is sampled, so memory
    /// does not grow with the simulated time); an earlier run's trace and plot in --out
    /// are removed, so the folder holds one run.
    #[arg(long)]
    pub no_trace: bool,
    /// Most trace values (samples × columns) a run may write; a run estimated above it is
    /// refused before it starts [–]. 0 lifts the limit.
    #[arg(long, default_value_t = DEFAULT_MAX_OUTPUT_VALUES, value_name = "N")]
    pub max_output_values: u64,
    /// Closed-loop control and load torque.
    #[command(flatten)]
    pub control: ControlArgs,
    /// Output folder.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

/// Parse the `--input` argument: a kind name or a recorded profile file.
pub fn parse_input(kind: &str, voltage: f64, freq: f64) -> Result<Input> {
    let path = Path::new(kind);
    if path.extension().is_some() {
        let profile = hd_io::read_profile(path)?;
        return Ok(Input::Recorded(profile));
    }
    Ok(input_from_kind(kind, voltage, freq)?)
}

/// Check the arguments into a run configuration.
pub fn config(args: &SimulateArgs) -> Result<SimConfig> {
    let m = &args.model;
    let params = load_params(m.params.as_deref(), &m.set)?;
    let input = parse_input(&args.input, args.voltage, args.freq)?;
    let (from_file, law_in_file, fv_in_file) = match &m.params {
        Some(path) => {
            let text = read_params_text(path)?;
            let name = path.display().to_string();
            (
                controller_from_toml(&text, &name)?,
                stiffness_from_toml(&text, &name)?,
                friction_velocity_from_toml(&text, &name)?,
            )
        }
        None => (None, None, None),
    };
    let stiffness = m.stiffness.map(HystLaw::from).or(law_in_file).unwrap_or_default();
    let cfg = SimConfig {
        params,
        variant: m.variant.into(),
        stiffness,
        input,
        t_end: args.t_end,
        dt_out: args.dt_out,
        solver: SolverOptions {
            method: m.method.into(),
            rtol: m.rtol,
            atol: m.atol,
            ..Default::default()
        },
        friction_velocity: m.friction_velocity.map(Into::into).or(fv_in_file).unwrap_or_default(),
        metrics: MetricSettings { cycles: args.cycles, ..Default::default() },
        record_trace: !args.no_trace,
        load_torque: args.control.load_torque(),
        controller: args.control.controller(from_file)?,
    };
    cfg.validate()?;
    Ok(cfg)
}

/// Run `hdw simulate`. A failed run leaves `--out` as it was: an earlier run's files
/// untouched (the outputs are staged and committed together), and no empty folder where
/// there was none (`main` removes the folders a failed command created).
pub fn run(args: SimulateArgs) -> Result<()> {
    let args = &args;
    let cfg = config(args)?;
    let expected = cfg.t_end / cfg.output_interval();
    if cfg.record_trace {
        check_output_size(expected, TRACE_COLUMNS.len(), args.max_output_values)?;
    }
    let dir = ensure_dir(&args.out)?;
    let trace_path = dir.join("trace.parquet");
    let plot_path = dir.join("response.svg");
    // Every output is staged under a temporary name and renamed into place together at
    // the end: a failed or interrupted run leaves the folder as it was.
    let mut staged = Vec::new();
    // The trace streams to its temporary in row groups while the solve runs; the plot gets
    // every sample of a short run and the per-bucket envelope of a long one.
    let (out, plot_trace) = if cfg.record_trace {
        let mut full = (expected <= FULL_PLOT_SAMPLES).then(Trace::default);
        let mut env = Envelope::new(cfg.t_end);
        let mut progress = SimProgress::new(cfg.t_end);
        let mut trace_file = Staged::new(&trace_path)?;
        let out = hd_io::stream_trace_into(&mut trace_file, None, |sink| {
            simulate_streaming(
                &cfg,
                Some(&mut |s: &Sample| {
                    sink(s);
                    progress.at(s.t);
                    match full.as_mut() {
                        Some(t) => t.push(s),
                        None => env.push(s),
                    }
                }),
            )
        })?
        .context("simulation failed")?;
        progress.finish();
        staged.push(trace_file);
        (out, Some(full.unwrap_or_else(|| env.finish())))
    } else {
        (simulate_streaming(&cfg, None).context("simulation failed")?, None)
    };
    let metrics: serde_json::Map<String, serde_json::Value> = out
        .metrics
        .to_pairs()
        .into_iter()
        .map(|(k, v)| (k.to_string(), json!(finite(v))))
        .collect();
    let notes = hd_model::metrics::notes(&cfg, &out.metrics);
    let undefined: serde_json::Map<String, serde_json::Value> =
        notes.undefined.iter().map(|(k, why)| (k.to_string(), json!(why))).collect();
    let params: serde_json::Map<String, serde_json::Value> =
        cfg.params.to_pairs().into_iter().map(|(k, v)| (k.to_string(), json!(v))).collect();
    let doc = json!({
        "variant": cfg.variant.name(),
        "stiffness": cfg.stiffness.name(),
        "input": cfg.input,
        "t_end": cfg.t_end,
        "friction_velocity": cfg.friction_velocity,
        "controller": cfg.controller,
        "load_torque": cfg.load_torque,
        "metrics": metrics,
        "undefined_metrics": undefined,
        "metric_warnings": notes.warnings,
        "parameters": params,
        "solver": {
            "method": out.stats.method,
            "rtol": cfg.solver.rtol,
            "atol": cfg.solver.atol,
            "steps": out.stats.steps,
            "rejected_steps": out.stats.rejected,
            "rhs_evaluations": out.stats.rhs_evals,
            "jacobian_evaluations": out.stats.jac_evals,
            "lu_decompositions": out.stats.lu_decomps,
            "implicit_steps": out.stats.implicit_steps,
            "method_switches": out.stats.switches,
            "wall_time_s": out.wall_time,
        },
        "tool": { "name": "hdw", "version": env!("CARGO_PKG_VERSION") },
    });
    staged.push(stage_json(&dir.join("metrics.json"), &doc)?);
    let title = match &cfg.controller {
        Some(c) => format!("{} variant, PID, {} compensation", cfg.variant, c.compensation),
        None => format!("{} variant, {}", cfg.variant, input_label(&cfg.input)),
    };
    if let Some(trace) = plot_trace.as_ref() {
        let plot = Staged::new(&plot_path)?;
        hd_plot::response_plot(plot.path(), trace, &title)?;
        staged.push(plot);
    }
    // A metrics-only run replaces an earlier run's trace and plot by nothing, so the
    // folder never holds metrics of one run beside the trace of another.
    let replaced = if cfg.record_trace { vec![] } else { vec![trace_path, plot_path] };
    hd_io::atomic::commit(staged, &replaced)?;
    if cfg.controller.is_some() {
        let m = &out.metrics;
        eprintln!(
            "closed loop: track_rms {:.4e} rad, track_max {:.4e} rad, reversal_peak {:.4e} rad, u_rms {:.4e} V, torque_est_rms {:.4e} N·m (without friction model {:.4e})",
            m.track_rms,
            m.track_max,
            m.reversal_peak,
            m.u_rms,
            m.torque_est_rms,
            m.torque_est_rms_nofric
        );
    }
    for w in &notes.warnings {
        eprintln!("warning: {w}");
    }
    // The amplitude of a periodic run; the peak (and why there is no amplitude) otherwise.
    let response = if out.metrics.thz_amp.is_finite() {
        format!("θz amplitude {} rad", hd_text::sci(out.metrics.thz_amp, 5))
    } else {
        let why = notes.undefined.iter().find(|(k, _)| *k == "thz_amp").map(|(_, w)| w.as_str());
        format!(
            "θz peak {} rad (no amplitude: {})",
            hd_text::sci(out.metrics.thz_peak, 5),
            why.unwrap_or("undefined")
        )
    };
    eprintln!(
        "{} variant, {} steps ({} rejected) in {:.1} ms; {response}; wrote {}",
        cfg.variant,
        out.stats.steps,
        out.stats.rejected,
        out.wall_time * 1e3,
        dir.display()
    );
    Ok(())
}

/// A short description of the input for plot titles.
fn input_label(input: &Input) -> String {
    match input {
        Input::Sine { amplitude, freq } => format!("{amplitude} V sine at {freq} Hz"),
        Input::Step { amplitude, t0 } => format!("{amplitude} V step at {t0} s"),
        Input::Constant { amplitude } => format!("constant {amplitude} V"),
        Input::Chirp { amplitude, f0, f1, .. } => format!("{amplitude} V chirp {f0}–{f1} Hz"),
        Input::SteppedSine { amplitude, freqs, .. } => {
            format!("{amplitude} V stepped sine, {} frequencies", freqs.len())
        }
        Input::Recorded(p) => format!("recorded input ({} samples)", p.t.len()),
    }
}

/// NaN and infinities become JSON null.
fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}
