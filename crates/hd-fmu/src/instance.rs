//! One FMU instance, independent of the FMI version: the configuration, the parameter
//! values and inputs the host set, and the run ([`Stepper`]) advanced one communication
//! step at a time with the inputs held over the step. Every method returns a message on
//! failure; the FMI layers turn it into a status and a log call.

use crate::variables::{Role, VR_T_LOAD, VR_TIME, VR_U, Variable, variables};
use hd_model::compliant::{FixedDrive, fixed_drive};
use hd_model::error::SolverError;
use hd_model::laws::load::LoadTorque;
use hd_model::signals::Thresholds;
use hd_model::stepper::Stepper;
use hd_model::{Input, Params, Profile, SimConfig, Trace};

/// Most solver steps (accepted and rejected) one communication step may take [–]: about
/// 2 s of work at the seed drive's rate of steps; a step that needs more fails with an
/// error instead of holding the host for minutes.
pub const STEP_BUDGET: u64 = 5_000_000;

/// Where an instance is in the FMI life cycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Instantiated (or reset): parameters and inputs may be set.
    Instantiated,
    /// Between entering and leaving initialisation mode.
    Initializing,
    /// Initialised: the host steps it.
    Stepping,
    /// Terminated by the host.
    Terminated,
    /// A step failed; only reset or free are meaningful.
    Failed,
}

/// An FMU instance.
#[derive(Clone, Debug)]
pub struct Instance {
    /// The exported configuration (start values).
    cfg: SimConfig,
    /// The variables of the model description.
    vars: Vec<Variable>,
    /// Parameter values as the host set them.
    params: Params,
    /// Held voltage [V].
    u: f64,
    /// Held load torque [N·m].
    t_load: f64,
    /// Rates of the voltage [V/s] and the load torque [N·m/s] over the next step, when the
    /// host gives them (FMI 2 input derivatives); zero holds the inputs.
    rates: [f64; 2],
    /// Host time at which the model's time is 0 [s].
    start_time: f64,
    /// The run, built when first needed.
    run: Option<Stepper>,
    /// Whether parameters changed since the run's system was built.
    params_changed: bool,
    /// Times where the exported drive's own signals jump (a closed loop's reference) [s].
    breakpoints: Vec<f64>,
    /// The solver's step size in the last communication step [s], the next one's first
    /// step (0: the solver's own choice): each communication step restarts the solver,
    /// and its starting-step estimate costs more than a short step does.
    h_hint: f64,
    /// Most solver steps one communication step may take [–].
    step_budget: u64,
    /// Fixed Runge–Kutta substeps per communication step, when the FMU was exported with
    /// them (`hdw export fmu --fixed-substeps`); None: the adaptive solver.
    fixed_substeps: Option<u32>,
    /// The drive as the fixed step integrates it, built with the run.
    fixed: Option<FixedDrive>,
    /// Life-cycle phase.
    pub phase: Phase,
}

impl Instance {
    /// A new instance of the drive `cfg` (as read from the FMU's resources).
    pub fn new(cfg: SimConfig) -> Self {
        Self {
            vars: variables(&cfg),
            params: cfg.params.clone(),
            breakpoints: cfg.breakpoints(),
            h_hint: 0.0,
            step_budget: cfg.solver.max_steps.min(STEP_BUDGET),
            cfg,
            u: 0.0,
            t_load: 0.0,
            rates: [0.0; 2],
            start_time: 0.0,
            run: None,
            params_changed: false,
            fixed_substeps: None,
            fixed: None,
            phase: Phase::Instantiated,
        }
    }

    /// The same instance integrating each communication step in `m` fixed Runge–Kutta
    /// substeps ([`hd_model::solver::fixed_step`]: what real-time and HIL hosts ask for),
    /// or by the adaptive solver (None). Refused, naming each setting, when the drive is
    /// one the fixed-step assembly cannot stand for.
    pub fn with_fixed_substeps(mut self, m: Option<u32>) -> Result<Self, String> {
        if let Some(m) = m {
            fixed_drive(&self.cfg).map_err(|e| format!("fixed_substeps = {m}: {e}"))?;
        }
        self.fixed_substeps = m;
        Ok(self)
    }

    /// Back to the state right after instantiation (start values, at rest).
    pub fn reset(&mut self) {
        let fixed = self.fixed_substeps;
        *self = Self::new(self.cfg.clone());
        self.fixed_substeps = fixed;
    }

    /// The host's start time [s] (the model's time 0).
    pub fn set_start_time(&mut self, t0: f64) -> Result<(), String> {
        if !t0.is_finite() {
            return Err(format!("start time = {t0}: expected a finite time [s]"));
        }
        self.start_time = t0;
        Ok(())
    }

    /// Lower (or raise) the solver steps one communication step may take [–] (at least 1).
    pub fn set_step_budget(&mut self, steps: u64) {
        self.step_budget = steps.max(1);
    }

    /// Enter initialisation mode.
    pub fn enter_initialization(&mut self) -> Result<(), String> {
        self.expect(&[Phase::Instantiated], "enter initialization mode")?;
        self.phase = Phase::Initializing;
        Ok(())
    }

    /// Leave initialisation mode: the parameters are checked together and the run is
    /// assembled at rest.
    pub fn exit_initialization(&mut self) -> Result<(), String> {
        self.expect(&[Phase::Initializing], "exit initialization mode")?;
        self.ensure_run()?;
        self.phase = Phase::Stepping;
        Ok(())
    }

    /// Terminate.
    pub fn terminate(&mut self) -> Result<(), String> {
        self.expect(&[Phase::Stepping, Phase::Initializing, Phase::Failed], "terminate")?;
        self.phase = Phase::Terminated;
        Ok(())
    }

    /// Host time reached [s].
    pub fn time(&self) -> f64 {
        self.start_time + self.run.as_ref().map_or(0.0, |r| r.t)
    }

    fn expect(&self, phases: &[Phase], what: &str) -> Result<(), String> {
        if phases.contains(&self.phase) {
            Ok(())
        } else {
            Err(format!("cannot {what} in phase {:?}", self.phase))
        }
    }

    fn variable(&self, vr: u32) -> Result<&Variable, String> {
        self.vars.iter().find(|v| v.vr == vr).ok_or_else(|| format!("unknown value reference {vr}"))
    }

    /// Set the variables `vrs` to `values` (inputs and parameters).
    pub fn set_reals(&mut self, vrs: &[u32], values: &[f64]) -> Result<(), String> {
        if matches!(self.phase, Phase::Terminated | Phase::Failed) {
            return Err(format!("cannot set variables in phase {:?}", self.phase));
        }
        for (&vr, &v) in vrs.iter().zip(values) {
            let var = self.variable(vr)?;
            match var.role {
                Role::Input => {
                    if !v.is_finite() {
                        return Err(format!(
                            "input '{}' = {v}: expected a finite value [{}]",
                            var.name, var.unit
                        ));
                    }
                    if vr == VR_U {
                        self.u = v;
                    } else if vr == VR_T_LOAD {
                        self.t_load = v;
                    }
                }
                Role::Parameter(info) => {
                    info.check(v).map_err(|e| e.to_string())?;
                    info.set_unchecked(&mut self.params, v);
                    self.params_changed = true;
                }
                Role::Output(_) => {
                    return Err(format!("'{}' is an output: it cannot be set", var.name));
                }
            }
        }
        Ok(())
    }

    /// Read the variables `vrs` into `values`: inputs and parameters as set, outputs from
    /// the state reached with the inputs as they are now.
    pub fn get_reals(&mut self, vrs: &[u32], values: &mut [f64]) -> Result<(), String> {
        let needs_sample = vrs
            .iter()
            .any(|&vr| self.vars.iter().any(|v| v.vr == vr && matches!(v.role, Role::Output(_))));
        let mut trace = Trace::default();
        if needs_sample {
            self.ensure_run()?;
            self.hold_inputs(0.0);
            if let Some(run) = &self.run {
                trace.push(&run.sys.sample(run.t, &run.y, &Thresholds::default()));
            }
        }
        for (&vr, slot) in vrs.iter().zip(values.iter_mut()) {
            if vr == VR_TIME {
                *slot = self.time();
                continue;
            }
            let var = self.variable(vr)?;
            *slot = match var.role {
                Role::Input if vr == VR_U => self.u,
                Role::Input => self.t_load,
                Role::Parameter(info) => info.get(&self.params),
                Role::Output(col) => col.of(&trace).first().copied().unwrap_or(f64::NAN),
            };
        }
        Ok(())
    }

    /// Advance from host time `t` [s] by `h` [s] with the inputs held.
    ///
    /// A communication point or step size that is not finite is refused before any work;
    /// a step is given at most [`STEP_BUDGET`] solver steps (fewer when the configuration's
    /// `max_steps` is lower), and one that would need more is refused at once when that is
    /// evident (a sampled controller's instants, or a bounded solver step `h_max`), or
    /// fails when the budget runs out.
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        self.expect(&[Phase::Stepping], "do a step")?;
        if !t.is_finite() {
            return Err(format!(
                "doStep at communication point t = {t}: expected a finite time [s]"
            ));
        }
        if !(h.is_finite() && h >= 0.0) {
            return Err(format!("communication step size = {h}: expected a finite step >= 0 [s]"));
        }
        let now = self.time();
        if (t - now).abs() > 1e-9 * (1.0 + t.abs()) {
            return Err(format!(
                "doStep from t = {t} s, but the FMU is at t = {now} s (steps must follow each other)"
            ));
        }
        if h == 0.0 {
            return Ok(());
        }
        let target = t + h - self.start_time;
        if !target.is_finite() {
            return Err(format!("doStep from t = {t} s by {h} s: the end time overflows [s]"));
        }
        self.ensure_run()?;
        self.hold_inputs(h);
        let rates = std::mem::take(&mut self.rates);
        if let Some(m) = self.fixed_substeps {
            return self.fixed_step(t, h, target, m, rates);
        }
        let budget = self.step_budget;
        let period = self.sampling_period();
        // The fewest solver steps the step needs: one per sampling instant, and one per
        // h_max of the span.
        let least = [period, Some(self.cfg.solver.h_max)]
            .into_iter()
            .flatten()
            .map(|p| h / p)
            .fold(0.0f64, f64::max);
        if least > budget as f64 {
            return Err(format!(
                "communication step size = {h} s needs at least {least:.3e} solver steps, more than the {budget} one step may take: use shorter communication steps"
            ));
        }
        let mut opts = self.cfg.solver;
        if opts.h_init == 0.0 && self.h_hint > 0.0 {
            opts.h_init = self.h_hint.min(h);
        }
        let Some(run) = self.run.as_mut() else {
            return Err("the run was not assembled".to_string());
        };
        let work = |r: &Stepper| r.stats.steps + r.stats.rejected;
        let (steps, work0) = (run.stats.steps, work(run));
        let over_budget = |reached: f64| {
            format!(
                "step from t = {t} s by {h} s stopped at t = {reached} s: it needs more than the {budget} solver steps one communication step may take (use shorter communication steps)"
            )
        };
        // A sampled controller's run goes one sampling interval per call (as the run
        // itself splits it), so that the budget bounds the work of the whole step; a
        // continuous drive is one solve.
        while run.t < target {
            let used = work(run) - work0;
            if used >= budget {
                self.phase = Phase::Failed;
                return Err(over_budget(self.start_time + run.t));
            }
            // An instant within rounding of the step's end is the end: stopping just short
            // of it would leave a remainder of a few ulps no solver step can take.
            let stop = match period {
                Some(p) => {
                    let k = (run.t / p).floor() + 1.0;
                    let next = if k * p > run.t { k * p } else { (k + 1.0) * p };
                    if target - next <= 1e-9 * p { target } else { next }
                }
                None => target,
            };
            opts.max_steps = budget - used;
            let before = run.t;
            let result = run.advance(stop.min(target), &self.breakpoints, &opts, &mut |_, _| {});
            if let Err(e) = result {
                self.phase = Phase::Failed;
                let reached = self.start_time + run.t;
                return Err(match e {
                    SolverError::TooManySteps { .. }
                        if opts.max_steps < self.cfg.solver.max_steps =>
                    {
                        over_budget(reached)
                    }
                    e => format!("step from t = {t} s by {h} s failed: {e}"),
                });
            }
            if run.t <= before {
                self.phase = Phase::Failed;
                return Err(format!(
                    "step from t = {t} s by {h} s made no progress at t = {before} s"
                ));
            }
        }
        // Steps after the first show the solver's own step size.
        self.h_hint = h / (run.stats.steps - steps).saturating_sub(1).max(1) as f64;
        Ok(())
    }

    /// [`Instance::do_step`] in `m` fixed substeps from host time `t` by `h` to the model's
    /// time `target` [s], the inputs ramped at `rates` (the load torque at its mean over
    /// the step). A state that is not finite after it (a substep past the method's
    /// stability) fails the instance, naming the substep.
    fn fixed_step(
        &mut self,
        t: f64,
        h: f64,
        target: f64,
        m: u32,
        rates: [f64; 2],
    ) -> Result<(), String> {
        let (Some(run), Some(fixed)) = (self.run.as_mut(), self.fixed.as_mut()) else {
            return Err("the run was not assembled".to_string());
        };
        let span = target - run.t;
        let t_load = self.t_load + 0.5 * rates[1] * span;
        fixed.advance(&mut run.y, span, m as usize, self.u, rates[0], t_load);
        use hd_model::state::{OMEGA_J, OMEGA_Z, THETA, THETA_J, W, Z};
        if ![THETA_J, OMEGA_J, THETA, OMEGA_Z, Z, W].iter().all(|&k| run.y[k].is_finite()) {
            self.phase = Phase::Failed;
            return Err(format!(
                "step from t = {t} s by {h} s failed: the state is not finite after {m} fixed substeps of {:.3e} s (past the Runge–Kutta method's stability for this drive); export with more --fixed-substeps or use shorter communication steps",
                span / f64::from(m)
            ));
        }
        run.t = target;
        run.stats.steps += u64::from(m);
        Ok(())
    }

    /// The sampling period of the exported controller when it runs sampled [s].
    fn sampling_period(&self) -> Option<f64> {
        let ctl = self.run.as_ref()?.sys.ctl.as_ref()?;
        ctl.is_sampled().then_some(ctl.cfg.period)
    }

    /// The configuration with the host's parameter values.
    fn current_config(&self) -> Result<SimConfig, String> {
        let cfg = SimConfig { params: self.params.clone(), ..self.cfg.clone() };
        cfg.validate().map_err(|e| e.to_string())?;
        Ok(cfg)
    }

    /// Assemble the run, or rebuild its system after a parameter change (from rest if no
    /// step was taken yet; otherwise keeping the state and a sampled controller's hold).
    fn ensure_run(&mut self) -> Result<(), String> {
        let fresh = self.run.as_ref().is_none_or(|r| r.t == 0.0);
        if self.run.is_some() && !self.params_changed {
            return Ok(());
        }
        let cfg = self.current_config()?;
        if self.fixed_substeps.is_some() {
            self.fixed = Some(fixed_drive(&cfg)?);
        }
        if fresh {
            self.run = Some(Stepper::new(&cfg).map_err(|e| e.to_string())?);
        } else if let Some(run) = self.run.as_mut() {
            let hold = run.sys.hold;
            run.sys = cfg.system().map_err(|e| e.to_string())?;
            run.sys.hold = hold;
        }
        self.params_changed = false;
        Ok(())
    }

    /// Set the first time derivatives of inputs `vrs` for the next step (FMI 2
    /// `fmi2SetRealInputDerivatives`; orders above 1 are refused).
    pub fn set_input_rates(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        values: &[f64],
    ) -> Result<(), String> {
        for ((&vr, &order), &v) in vrs.iter().zip(orders).zip(values) {
            let var = self.variable(vr)?;
            if !matches!(var.role, Role::Input) {
                return Err(format!("'{}' is not an input: it has no input derivative", var.name));
            }
            if order != 1 {
                return Err(format!(
                    "input derivative of order {order} for '{}': expected order 1",
                    var.name
                ));
            }
            if !v.is_finite() {
                return Err(format!(
                    "input derivative of '{}' = {v}: expected a finite rate",
                    var.name
                ));
            }
            self.rates[usize::from(vr == VR_T_LOAD)] = v;
        }
        Ok(())
    }

    /// Put the inputs into the run's system for a step of `h` [s]: held, or ramped at the
    /// rates the host gave.
    fn hold_inputs(&mut self, h: f64) {
        let Some(run) = self.run.as_mut() else {
            return;
        };
        let t0 = run.t;
        let held = |value: f64, rate: f64| {
            if rate == 0.0 || h <= 0.0 {
                Input::Constant { amplitude: value }
            } else {
                // A two-point profile is the ramp over the step, held after it.
                Input::Recorded(Profile { t: vec![t0, t0 + h], u: vec![value, value + rate * h] })
            }
        };
        run.sys.input = held(self.u, self.rates[0]);
        run.sys.load = if self.t_load == 0.0 && self.rates[1] == 0.0 {
            LoadTorque::default()
        } else {
            LoadTorque::new(held(self.t_load, self.rates[1]))
        };
    }
}

#[cfg(test)]
#[path = "instance_tests.rs"]
mod tests;
