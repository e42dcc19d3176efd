//! A run advanced piece by piece: the assembled system and its state, integrated to any
//! later time on request, with a sampled controller updated at its sampling instants.
//! [`crate::simulate_streaming`] advances one to the end of the run in one call; a
//! co-simulation host (the FMU) advances one communication step at a time.

use crate::control::Hold;
use crate::error::{ConfigError, SolverError};
use crate::simulate::{SimConfig, SimError};
use crate::solver::OdeSystem;
use crate::solver::{SolverOptions, SolverStats, Step, solve};
use crate::state::{CMP_Q, DIM, State};
use crate::system::DriveSystem;

/// The system of a run with its state at time `t`.
#[derive(Clone, Debug)]
pub struct Stepper {
    /// The assembled system (its input, load torque and hold may be changed between
    /// calls to [`Stepper::advance`]).
    pub sys: DriveSystem,
    /// Time reached [s].
    pub t: f64,
    /// State at `t`.
    pub y: State,
    /// Solver work so far.
    pub stats: SolverStats,
    /// Sampling period of a sampled controller [s].
    period: Option<f64>,
    /// Index of the next sampling instant `k·period`.
    next_k: u64,
    /// Whether `t` is a sampling instant whose controller update is still to be done.
    due: bool,
}

impl Stepper {
    /// The run of `cfg` at rest at t = 0 (checked first); a sampled controller has
    /// computed its first command, before anything moves.
    pub fn new(cfg: &SimConfig) -> Result<Self, SimError> {
        cfg.validate()?;
        let sys = cfg.system()?;
        let run = Self::at_rest(sys, cfg.solver);
        run.check_finite_at_rest(&cfg.params)?;
        Ok(run)
    }

    /// Refuse a set of parameters whose equations overflow before anything moves (a
    /// stiffness of 1e308 over an inertia below 1): the rates and their Jacobian at the
    /// initial state must be finite, or no step can be taken.
    fn check_finite_at_rest(&self, params: &crate::Params) -> Result<(), ConfigError> {
        let (jac, rate) = self.sys.jacobian(0.0, &self.y);
        if rate.iter().chain(jac.iter()).all(|v| v.is_finite()) {
            return Ok(());
        }
        // The likeliest culprit: the parameter of largest magnitude (the first of equals: a
        // level before the negative-side level that follows it).
        let largest = params
            .to_pairs()
            .into_iter()
            .rev()
            .filter(|(_, v)| v.is_finite())
            .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()));
        let (field, value) = match largest {
            Some((name, v)) => (format!("parameter {name}"), crate::error::num(v)),
            None => ("parameters".to_string(), "the values given".to_string()),
        };
        Err(ConfigError::Invalid {
            field,
            value,
            expected: "values whose equations stay finite at rest (a rate or its derivative overflows there; the largest parameter is named)".to_string(),
        })
    }

    /// `sys` at rest at t = 0.
    pub fn at_rest(mut sys: DriveSystem, opts: SolverOptions) -> Self {
        let y = sys.rest_state();
        let period = sys.ctl.as_ref().filter(|c| c.is_sampled()).map(|c| c.cfg.period);
        if let (Some(_), Some(c)) = (period, sys.ctl.as_ref()) {
            sys.hold = c.sample(0.0, &sys.measured(&y), y[CMP_Q], &Hold::default(), true);
        }
        let stats = SolverStats { method: opts.method, ..Default::default() };
        Self { sys, t: 0.0, y, stats, period, next_k: 1, due: false }
    }

    /// Integrate from `t` to `t1` (> `t`), landing on every sampling instant of a sampled
    /// controller in between and updating its hold there. `observer` sees every accepted
    /// step with the system that took it.
    pub fn advance(
        &mut self,
        t1: f64,
        breakpoints: &[f64],
        opts: &SolverOptions,
        observer: &mut dyn FnMut(&DriveSystem, &Step<DIM>),
    ) -> Result<(), SolverError> {
        while self.t < t1 {
            // The segment's end, and whether it is a sampling instant. An instant within
            // rounding of t1 (a host's k·h against the controller's j·period) is t1.
            let (stop, instant) = match self.period {
                Some(p) => {
                    let at = self.next_k as f64 * p;
                    if at <= self.t {
                        self.next_k += 1;
                        continue;
                    }
                    if (at - t1).abs() <= 4.0 * f64::EPSILON * t1.abs() {
                        (t1, true)
                    } else {
                        (at.min(t1), at < t1)
                    }
                }
                None => (t1, false),
            };
            if self.due
                && let Some(c) = self.sys.ctl.as_ref()
            {
                let m = self.sys.measured(&self.y);
                self.sys.hold = c.sample(self.t, &m, self.y[CMP_Q], &self.sys.hold, false);
            }
            self.due = false;
            let sys = &self.sys;
            let (y1, st) =
                solve(sys, self.t, self.y, stop, breakpoints, opts, &mut |s| observer(sys, s))?;
            self.stats.accumulate(&st);
            if instant {
                self.next_k += 1;
                self.due = true;
            }
            (self.t, self.y) = (stop, y1);
        }
        Ok(())
    }
}
