//! One simulation run: check the configuration, assemble the system, integrate, and
//! return the trace (optional), the metrics and the solver statistics.

use crate::control::{Controller, ControllerConfig};
use crate::error::{ConfigError, SolverError};
use crate::laws::input::Input;
use crate::laws::load::LoadTorque;
use crate::metrics::{Collector, MetricSettings, Metrics};
use crate::params::Params;
use crate::signals::{Sample, Thresholds};
use crate::solver::{SolverOptions, SolverStats, Step};
use crate::state::{DIM, State};
use crate::stepper::Stepper;
use crate::system::{DriveSystem, FrictionVelocity};
use crate::trace::Trace;
use crate::variant::{HystLaw, StiffnessKind, Variant};
use serde::{Deserialize, Serialize};
use std::time::Instant;
use thiserror::Error;

/// Everything that defines a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimConfig {
    /// Physical parameters; default the seed's tables.
    pub params: Params,
    /// Model variant; default `full`.
    pub variant: Variant,
    /// Hysteretic stiffness law of the `full` variant; default `memory` (the seed's).
    pub stiffness: HystLaw,
    /// Armature voltage; default 24 V sine at 50 Hz.
    pub input: Input,
    /// Simulated time [s]; default 0.2.
    pub t_end: f64,
    /// Trace sampling interval [s]; 0 picks 200 samples per drive cycle for periodic
    /// inputs and 10 000 samples per run otherwise.
    pub dt_out: f64,
    /// Integrator settings.
    pub solver: SolverOptions,
    /// Speed seen by the friction law; default `motor` (v = ωj/N).
    pub friction_velocity: FrictionVelocity,
    /// Metric settings.
    pub metrics: MetricSettings,
    /// Whether to keep the sampled trace.
    pub record_trace: bool,
    /// External load torque on the load side; default none.
    pub load_torque: LoadTorque,
    /// Closed-loop controller (the `[controller]` table); default none, an open-loop run
    /// driven by `input`.
    pub controller: Option<ControllerConfig>,
}

impl Default for SimConfig {
    fn default() -> Self {
        Self {
            params: Params::default(),
            variant: Variant::Full,
            stiffness: HystLaw::Memory,
            input: Input::default(),
            t_end: 0.2,
            dt_out: 0.0,
            solver: SolverOptions::default(),
            friction_velocity: FrictionVelocity::Motor,
            metrics: MetricSettings::default(),
            record_trace: true,
            load_torque: LoadTorque::default(),
            controller: None,
        }
    }
}

/// Why a run failed.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SimError {
    /// The configuration was rejected before integrating.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The integrator stopped.
    #[error(transparent)]
    Solver(#[from] SolverError),
    /// The run panicked (a bug); the sweep records it and goes on.
    #[error("internal error (panic): {0}")]
    Panic(String),
}

/// The result of a run.
#[derive(Clone, Debug)]
pub struct SimOutput {
    /// Sampled signals, if requested.
    pub trace: Option<Trace>,
    /// Metrics (docs/model.md §2.10).
    pub metrics: Metrics,
    /// Solver work.
    pub stats: SolverStats,
    /// Wall-clock time of the integration [s].
    pub wall_time: f64,
    /// Final integrated state.
    pub final_state: State,
}

/// Fewest solver steps any accurate run spends on one cycle of an oscillating input [–].
const MIN_STEPS_PER_CYCLE: f64 = 4.0;

impl SimConfig {
    /// Check every setting; the error names the field and the expected value.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.params.validate()?;
        self.input.validate()?;
        self.load_torque.validate()?;
        if let Some(c) = &self.controller {
            c.validate(&self.params)?;
        }
        if self.stiffness != HystLaw::Memory && self.variant != Variant::Full {
            return Err(ConfigError::Invalid {
                field: "stiffness".to_string(),
                value: self.stiffness.name().to_string(),
                expected: format!(
                    "memory with the {} variant (the stiffness law applies to the full variant)",
                    self.variant
                ),
            });
        }
        let bad = |field: &str, value: f64, expected: &str| {
            Err(ConfigError::Invalid {
                field: field.to_string(),
                value: crate::error::num(value),
                expected: expected.to_string(),
            })
        };
        if !(self.t_end.is_finite() && self.t_end > 0.0) {
            return bad("t_end", self.t_end, "a finite time > 0 [s]");
        }
        if !(self.dt_out.is_finite() && self.dt_out >= 0.0) {
            return bad("dt_out", self.dt_out, "a finite interval >= 0 [s] (0: automatic)");
        }
        let s = &self.solver;
        if !(s.rtol.is_finite() && s.rtol >= 1e-14 && s.rtol < 1.0) {
            return bad("rtol", s.rtol, "a relative tolerance in [1e-14, 1)");
        }
        if !(s.atol.is_finite() && s.atol > 0.0) {
            return bad("atol", s.atol, "an absolute tolerance > 0");
        }
        if s.max_steps == 0 {
            return bad("max_steps", 0.0, "at least 1 step");
        }
        if s.h_max.is_nan() || s.h_max <= 0.0 {
            return bad("h_max", s.h_max, "a step bound > 0 [s]");
        }
        // Any accurate solution takes a few steps per input cycle: a drive with more cycles
        // than the step budget allows is refused now, not after max_steps wasted steps.
        let steps = MIN_STEPS_PER_CYCLE * self.input.cycles_until(self.t_end);
        if self.controller.is_none() && steps > s.max_steps as f64 {
            return Err(ConfigError::Invalid {
                field: "input".to_string(),
                value: format!(
                    "{} cycles in {} s",
                    crate::error::num(steps / MIN_STEPS_PER_CYCLE),
                    crate::error::num(self.t_end)
                ),
                expected: format!(
                    "a drive the solver can follow within max_steps = {} (at least {} steps per cycle): lower the frequency or t_end, or raise max_steps",
                    s.max_steps, MIN_STEPS_PER_CYCLE
                ),
            });
        }
        // A voltage near the largest number overflows its rate (2π·f·U) or the equations.
        for t in [0.0, self.t_end] {
            let (u, du) = self.input.value_and_rate(t);
            if !(u.is_finite() && du.is_finite()) {
                return Err(ConfigError::Invalid {
                    field: "input".to_string(),
                    value: format!(
                        "u = {}, du/dt = {} at t = {}",
                        crate::error::num(u),
                        crate::error::num(du),
                        crate::error::num(t)
                    ),
                    expected: "a voltage whose value and rate are finite [V, V/s]".to_string(),
                });
            }
        }
        if self.metrics.cycles == 0 {
            return bad("metrics.cycles", 0.0, "at least 1 cycle");
        }
        if !(self.metrics.final_fraction > 0.0 && self.metrics.final_fraction < 1.0) {
            return bad(
                "metrics.final_fraction",
                self.metrics.final_fraction,
                "a fraction in (0, 1)",
            );
        }
        Ok(())
    }

    /// Assemble the system this configuration describes.
    pub fn system(&self) -> Result<DriveSystem, ConfigError> {
        let (stiffness, friction) = self.laws();
        let mut sys = DriveSystem::new(
            &self.params,
            stiffness,
            friction,
            self.input.clone(),
            self.friction_velocity,
        )?;
        sys.load = self.load_torque.clone();
        if let Some(c) = &self.controller {
            sys.ctl = Some(Controller::new(c, &self.params, stiffness, friction)?);
        }
        Ok(sys)
    }

    /// The stiffness and friction laws of the run: the variant's, with the full
    /// variant's hysteretic law replaced by the chosen one.
    pub fn laws(&self) -> (StiffnessKind, crate::variant::FrictionKind) {
        let (stiffness, friction) = self.variant.kinds();
        let stiffness = match stiffness {
            StiffnessKind::Hysteretic => self.stiffness.kind(),
            other => other,
        };
        (stiffness, friction)
    }

    /// Times where a signal of the run jumps (input or reference, and load torque).
    pub fn breakpoints(&self) -> Vec<f64> {
        let mut b = match &self.controller {
            Some(c) => c.reference.breakpoints(),
            None => self.input.breakpoints(),
        };
        b.extend(self.load_torque.breakpoints());
        b
    }

    /// The frequency of the periodic drive [Hz]: the reference's in closed loop, the
    /// input's open loop; `None` if the drive is not periodic.
    pub fn drive_frequency(&self) -> Option<f64> {
        match &self.controller {
            Some(c) => c.reference.period().map(|p| 1.0 / p),
            None => self.input.drive_frequency(),
        }
    }

    /// The trace sampling interval actually used [s].
    pub fn output_interval(&self) -> f64 {
        if self.dt_out > 0.0 {
            return self.dt_out;
        }
        match self.drive_frequency() {
            Some(f) => (1.0 / (200.0 * f)).min(self.t_end / 100.0),
            None => self.t_end / 10_000.0,
        }
    }
}

/// Run one simulation from rest.
pub fn simulate(cfg: &SimConfig) -> Result<SimOutput, SimError> {
    let mut trace = cfg.record_trace.then(Trace::default);
    let mut out = match trace.as_mut() {
        Some(tr) => simulate_streaming(cfg, Some(&mut |s: &Sample| tr.push(s)))?,
        None => simulate_streaming(cfg, None)?,
    };
    out.trace = trace;
    Ok(out)
}

/// Run one simulation from rest, handing each trace sample (on the grid of
/// [`SimConfig::output_interval`]) to `sink` as soon as the solve passes it, so a caller
/// can write a long run without holding it (`record_trace` is ignored; the output's
/// trace is `None`). With no sink nothing is sampled.
pub fn simulate_streaming(
    cfg: &SimConfig,
    sink: Option<&mut dyn FnMut(&Sample)>,
) -> Result<SimOutput, SimError> {
    let eps = Thresholds::default();
    match sink {
        Some(f) => run_sampled(
            cfg,
            Some(&mut |sys: &DriveSystem, t: f64, y: &State| f(&sys.sample(t, y, &eps))),
        ),
        None => run_sampled(cfg, None),
    }
}

/// [`simulate_streaming`] for callers that need only the state on the output grid (a
/// load angle to compare with another solver's): `sink` gets the system, t [s] and the
/// state there, and no reported signal is evaluated.
pub fn simulate_states(cfg: &SimConfig, sink: StateSink) -> Result<SimOutput, SimError> {
    run_sampled(cfg, Some(sink))
}

/// What sees the state at each output time: the system, t [s] and the state.
type StateSink<'a> = &'a mut dyn FnMut(&DriveSystem, f64, &State);

/// The run, with the state handed to `sink` at every output time.
fn run_sampled(cfg: &SimConfig, mut sink: Option<StateSink>) -> Result<SimOutput, SimError> {
    let mut run = Stepper::new(cfg)?;
    // `auto` switches by cost; a non-stiff variant only between the explicit pairs
    // (`OdeSystem::may_be_stiff`).
    let opts = cfg.solver;
    let dt = cfg.output_interval();
    let mut last_t = 0.0;
    if let Some(f) = sink.as_mut() {
        f(&run.sys, 0.0, &run.y);
    }
    let mut collector = Collector::new(&run.sys, cfg.metrics, run.y, cfg.t_end);
    let mut next_k: u64 = 1;
    let breakpoints = cfg.breakpoints();
    let start = Instant::now();
    // Open loop and continuous control: one solve. Sampled control: one solve per
    // sampling period, the controller updating its held command in between.
    let mut observer = |sys: &DriveSystem, s: &Step<DIM>| {
        collector.on_step(sys, s);
        if let Some(f) = sink.as_mut() {
            loop {
                let tk = (next_k as f64 * dt).min(cfg.t_end);
                if tk > s.t1 || tk <= last_t {
                    break;
                }
                let y = if tk == s.t1 { *s.y1 } else { s.interpolate(tk) };
                f(sys, tk, &y);
                last_t = tk;
                next_k += 1;
            }
        }
    };
    run.advance(cfg.t_end, &breakpoints, &opts, &mut observer)?;
    let (sys, y, stats) = (&run.sys, run.y, run.stats);
    let wall_time = start.elapsed().as_secs_f64();
    let metrics = collector.finish(sys, &y);
    Ok(SimOutput { trace: None, metrics, stats, wall_time, final_state: y })
}

/// A run's configuration as `Input` for a constant, step or sine voltage — a helper for
/// command lines and study files.
pub fn input_from_kind(kind: &str, voltage: f64, freq: f64) -> Result<Input, ConfigError> {
    match kind {
        "sine" => Ok(Input::Sine { amplitude: voltage, freq }),
        "step" => Ok(Input::Step { amplitude: voltage, t0: 0.0 }),
        "constant" => Ok(Input::Constant { amplitude: voltage }),
        "chirp" => {
            Ok(Input::Chirp { amplitude: voltage, f0: freq / 10.0, f1: freq * 10.0, duration: 1.0 })
        }
        other => Err(ConfigError::Invalid {
            field: "input".to_string(),
            value: other.to_string(),
            expected: "sine, step, constant, chirp or a CSV/Parquet file with columns t, u"
                .to_string(),
        }),
    }
}
