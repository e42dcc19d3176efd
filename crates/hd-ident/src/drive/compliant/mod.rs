//! The compliant drive fitted to voltage tests (`hdw fit drive` with `transmission =
//! "compliant"`): the simulator's motor–gear–load system with a hysteretic gear and LuGre
//! friction ([`model::Compliant`]), re-run under each record's voltage
//! ([`simulate::simulate`]) and fitted by output error on the motor and load encoders and
//! the current, with the exact Jacobian of the integration ([`fit::fit_compliant`]).

pub mod accuracy;
pub mod closed_loop;
pub mod config;
pub mod correlated;
pub mod creeping;
pub mod determined;
pub mod diagnose;
pub mod fit;
pub mod jacobian;
pub mod loop_config;
/// The drive's generic assembly (hd-model's).
pub use hd_model::compliant::model;
/// The drive's parameter vector (hd-model's).
pub use hd_model::compliant::params;
pub mod passes;
pub mod ratio_check;
pub mod record;
pub mod requantised;
pub mod sampling;
pub mod scale_check;
pub mod sentences;
pub mod simulate;
pub mod split;
pub mod stages;
pub mod structured;
/// What the generic assembly can stand for (hd-model's).
pub use hd_model::compliant::supported;
pub mod synth_loop;
pub mod units;

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_both;
#[cfg(test)]
mod tests_deflection;
#[cfg(test)]
mod tests_doubt;
#[cfg(test)]
mod tests_laws;
#[cfg(test)]
mod tests_load;
#[cfg(test)]
mod tests_loop;

pub use closed_loop::{Amplifier, ClosedLoop, Feedback};
pub use config::CompliantConfig;
pub use fit::{CompliantFit, CompliantSpec, RecordScore, Signal, substeps_for, substeps_of};
pub use model::{Compliant, NAMES};
pub use record::{Between, CurrentSampled, VoltageRecord};
pub use simulate::{Outputs, on_encoder_zeros, simulate};
pub use stages::fit_compliant;
