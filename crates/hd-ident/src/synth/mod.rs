//! Synthetic data from the model, for checking identifiability before an experiment:
//! an imposed excitation drives the same hd-model laws the simulator and the fits use,
//! and Gaussian noise of a chosen size relative to the RMS torque is added.

mod excitation;
mod friction;
mod hysteresis;
mod laws;
mod noise;
mod truth;

pub use excitation::{GrowingSine, PlateauProfile, QuasiStatic, SumOfSines};
pub use friction::{
    SteadySweep, TransientExcitation, synth_plateaus, synth_steady, synth_transient,
};
pub use hysteresis::{HysteresisExcitation, synth_hysteresis};
pub use laws::{Schedule, StiffnessTruth, synth_stiffness};
pub use noise::{Noise, add_noise};
pub use truth::{bouc_wen_truth, is_law_name, maxwell_slip_truth};

/// A synthetic data set: named columns ready to write, and how it was made.
#[derive(Clone, Debug, PartialEq)]
pub struct Synthetic {
    /// Column names (the conventional names the fits read).
    pub names: Vec<&'static str>,
    /// Columns, same order and length.
    pub columns: Vec<Vec<f64>>,
    /// Standard deviation of the added noise [N·m].
    pub noise_std: f64,
    /// One paragraph: excitation, parameters, noise.
    pub description: String,
}
