//! Metrics every run reports (docs/model.md §2.10). Undefined metrics are NaN (null in
//! JSON), never a made-up zero.

mod buffers;
mod collector;
mod extrema;
mod limit_cycle;
mod periodic;
mod reasons;
mod schema;
mod step;
mod tracking;
mod transfer;
mod window;

pub use collector::Collector;
pub use extrema::cubic_extrema;
pub use periodic::fit_fundamental;
pub use reasons::{Notes, notes};
pub use schema::{METRICS, MetricColumn};
pub use transfer::{gain_phase, gain_phase_of, to_db, unwrap_deg};
pub use window::periodic_window;

use serde::{Deserialize, Serialize};

/// How the metrics are computed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MetricSettings {
    /// Whole drive cycles at the end of a periodic run used for the periodic metrics;
    /// default 5 (fewer if the run is shorter).
    pub cycles: usize,
    /// Uniform samples per cycle for the ripple fit; default 512.
    pub samples_per_cycle: usize,
    /// Uniform samples over the whole run for step and limit-cycle metrics; default 20 000.
    pub run_samples: usize,
    /// Fraction of the run at its end used as the final window (step final value,
    /// limit-cycle detection); default 0.2.
    pub final_fraction: f64,
    /// Settling band as a fraction of the final value; default 0.02.
    pub settle_band: f64,
    /// Window after each reversal of the reference speed in which `reversal_peak` looks
    /// [s]; 0 (the default) takes a tenth of the reference period (0.1 s for references
    /// without a period).
    pub reversal_window: f64,
}

impl Default for MetricSettings {
    fn default() -> Self {
        Self {
            cycles: 5,
            samples_per_cycle: 512,
            run_samples: 20_000,
            final_fraction: 0.2,
            settle_band: 0.02,
            reversal_window: 0.0,
        }
    }
}

/// The metrics of one run. Names, units, descriptions and serialisation come from
/// [`METRICS`], the one table of metric columns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    /// Half peak-to-peak of θz over the window [rad] (periodic runs).
    pub thz_amp: f64,
    /// Mean of θz over the window [rad] (periodic runs).
    pub thz_mean: f64,
    /// RMS of θz after removing the mean and the fundamental at the drive frequency [rad].
    pub thz_ripple: f64,
    /// Energy dissipated per cycle by the hysteresis memory, ∮ z dθ [J].
    pub hyst_loss_per_cycle: f64,
    /// Energy dissipated per cycle by friction, ∮ Tf·v dt [J].
    pub friction_loss_per_cycle: f64,
    /// Positive output work over positive input work at the wave generator [–]: over the
    /// periodic window, or over the final fraction of a non-periodic run.
    pub efficiency: f64,
    /// Gain of θz's fundamental over the drive's (u open loop, θz_ref closed loop) [dB].
    pub gain_db: f64,
    /// Phase of θz's fundamental minus the drive's, wrapped to (−180, 180] [°].
    pub phase_deg: f64,
    /// Number of whole cycles the periodic metrics used [–].
    pub cycles_used: f64,
    /// 10 %–90 % rise time of the load speed after a step [s].
    pub rise_time: f64,
    /// Peak load speed above its final value, as a fraction of it [–] (0.05 = 5 %).
    pub overshoot: f64,
    /// Time after the step until the load speed stays within the settling band [s].
    pub settling_time: f64,
    /// Damping ratio from the logarithmic decrement of the deflection oscillation [–].
    pub damping_ratio: f64,
    /// Mean load speed over the final window [rad/s] (step and constant inputs).
    pub final_speed: f64,
    /// 1 if a persistent oscillation of the load speed remains in the final window, else 0
    /// (constant and step inputs) [–].
    pub limit_cycle: f64,
    /// Half peak-to-peak of that oscillation [rad/s].
    pub lc_amplitude: f64,
    /// Its period [s].
    pub lc_period: f64,
    /// Largest |θz| over the run [rad].
    pub thz_peak: f64,
    /// Largest |Tb| over the run [N·m].
    pub tb_peak: f64,
    /// Largest |Tf| over the run [N·m] (the break-away peak after a start from rest).
    pub tf_peak: f64,
    /// Largest |s|, the LuGre bristle (pre-sliding) deflection, over the run [rad].
    pub s_peak: f64,
    /// Energy-balance residual over the run, relative to the energy turned over [–].
    pub energy_residual: f64,
    /// RMS of the tracking error θz_ref − θz after the first reference period [rad].
    pub track_rms: f64,
    /// Largest |θz_ref − θz| after the first reference period [rad].
    pub track_max: f64,
    /// Largest |error| within the window after each reversal of the reference speed [rad].
    pub reversal_peak: f64,
    /// RMS of the voltage command [V].
    pub u_rms: f64,
    /// Fraction of the time the command is clipped at ±u_max [–].
    pub saturation_fraction: f64,
    /// RMS error of the transmitted-torque estimate with the friction model [N·m].
    pub torque_est_rms: f64,
    /// RMS error of the transmitted-torque estimate without the friction model [N·m].
    pub torque_est_rms_nofric: f64,
    /// Mean tracking error over the final window of a regulation run [rad].
    pub steady_error: f64,
    /// 1 if the tracking error keeps oscillating in the final window (hunting), else 0 [–].
    pub hunting: f64,
    /// Half peak-to-peak of the error over the final window [rad].
    pub hunt_amplitude: f64,
    /// Period of the hunting oscillation [s].
    pub hunt_period: f64,
}

impl Metrics {
    /// All metrics undefined.
    pub fn undefined() -> Self {
        let n = f64::NAN;
        Self {
            thz_amp: n,
            thz_mean: n,
            thz_ripple: n,
            hyst_loss_per_cycle: n,
            friction_loss_per_cycle: n,
            efficiency: n,
            gain_db: n,
            phase_deg: n,
            cycles_used: n,
            rise_time: n,
            overshoot: n,
            settling_time: n,
            damping_ratio: n,
            final_speed: n,
            limit_cycle: n,
            lc_amplitude: n,
            lc_period: n,
            thz_peak: n,
            tb_peak: n,
            tf_peak: n,
            s_peak: n,
            energy_residual: n,
            track_rms: n,
            track_max: n,
            reversal_peak: n,
            u_rms: n,
            saturation_fraction: n,
            torque_est_rms: n,
            torque_est_rms_nofric: n,
            steady_error: n,
            hunting: n,
            hunt_amplitude: n,
            hunt_period: n,
        }
    }

    /// Metric names and values in [`METRICS`] order (the column order of outputs).
    pub fn to_pairs(&self) -> Vec<(&'static str, f64)> {
        METRICS.iter().map(|m| (m.name, m.get(self))).collect()
    }
}
