//! Why a metric is missing from a run, and what a user should know about the ones that are
//! there: the words `hdw simulate` prints and writes beside metrics.json's nulls.

use super::{METRICS, Metrics, periodic_window};
use crate::laws::input::Input;
use crate::simulate::SimConfig;

/// Metrics of the periodic window.
const PERIODIC: &[&str] = &[
    "thz_amp",
    "thz_mean",
    "thz_ripple",
    "hyst_loss_per_cycle",
    "friction_loss_per_cycle",
    "gain_db",
    "phase_deg",
    "cycles_used",
];
/// Metrics of a step response.
const STEP: &[&str] = &["rise_time", "overshoot", "settling_time", "damping_ratio"];
/// Metrics of a persistent oscillation in the final window.
const LIMIT_CYCLE: &[&str] = &["limit_cycle", "lc_amplitude", "lc_period"];
/// Metrics of the closed loop.
const CLOSED_LOOP: &[&str] = &[
    "track_rms",
    "track_max",
    "reversal_peak",
    "u_rms",
    "saturation_fraction",
    "torque_est_rms",
    "torque_est_rms_nofric",
    "steady_error",
    "hunting",
    "hunt_amplitude",
    "hunt_period",
];

/// What to tell a user about a run's metrics.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Notes {
    /// `(metric, reason)` for every metric that is undefined (NaN) for this run.
    pub undefined: Vec<(&'static str, String)>,
    /// Cautions about metrics that are defined (for example a periodic window that includes
    /// the start-up transient).
    pub warnings: Vec<String>,
}

/// The notes on metrics `m` of a run configured by `cfg`.
pub fn notes(cfg: &SimConfig, m: &Metrics) -> Notes {
    let open_input = cfg.controller.is_none().then_some(&cfg.input);
    let window = periodic_window(cfg.drive_frequency(), open_input, cfg.t_end, cfg.metrics.cycles);
    let step_input = match open_input {
        Some(Input::Step { .. }) => Some(true),
        Some(Input::Constant { .. }) => Some(false),
        _ => None,
    };
    let mut out = Notes::default();
    for col in METRICS {
        if !col.get(m).is_nan() {
            continue;
        }
        let name = col.name;
        let reason = if PERIODIC.contains(&name) {
            match &window {
                Err(why) => why.clone(),
                Ok(_) if name == "gain_db" || name == "phase_deg" => {
                    "the drive's fundamental over the window is zero".to_string()
                }
                Ok(_) => "the run stopped before its periodic window was complete".to_string(),
            }
        } else if STEP.contains(&name) {
            match step_input {
                Some(true) => "the response does not rise, or does not settle, inside the run \
                               (see final_speed)"
                    .to_string(),
                _ => "not a step input".to_string(),
            }
        } else if name == "final_speed" {
            "needs a step or constant input".to_string()
        } else if LIMIT_CYCLE.contains(&name) {
            limit_cycle_reason(name, m, window.is_ok(), open_input)
        } else if CLOSED_LOOP.contains(&name) {
            if cfg.controller.is_none() {
                "open loop (no controller)".to_string()
            } else {
                "not defined for this reference (see docs/columns.md)".to_string()
            }
        } else if name == "efficiency" {
            "no net input work over the window".to_string()
        } else {
            "not defined for this run".to_string()
        };
        out.undefined.push((name, reason));
    }
    if let Ok((f, tw, cycles)) = window {
        // The window should start after at least one whole cycle, so the start-up transient
        // stays out of amplitude, ripple and losses.
        if tw < 1.0 / f - 1e-12 {
            out.warnings.push(format!(
                "the periodic metrics use the last {cycles} cycle(s) from t = {tw:.6} s, which \
                 include the start-up transient; run at least {:.6} s (--t-end) to leave one \
                 cycle before the window",
                (cycles as f64 + 1.0) / f
            ));
        }
    }
    out
}

fn limit_cycle_reason(name: &str, m: &Metrics, periodic: bool, open: Option<&Input>) -> String {
    if periodic {
        return "the drive is periodic: the response is forced, not a limit cycle".to_string();
    }
    if m.limit_cycle == 0.0 && name != "limit_cycle" {
        return "no limit cycle".to_string();
    }
    match open {
        Some(i) => format!(
            "the input ({}) varies over the final window: an oscillation there is forced",
            i.kind_name()
        ),
        None => "not defined for this run".to_string(),
    }
}

#[cfg(test)]
mod tests;
