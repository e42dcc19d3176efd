//! Whole-drive identification from a logged closed loop (`hdw fit drive`).
//!
//! A rigid drive ([`model::Rigid`]: inertia or mass, Coulomb + viscous friction, symmetric or
//! direction-dependent, an offset, force = gain × command; or [`lugre::LuGreDrive`]: LuGre
//! friction with a bristle state) runs in its logged loop under the
//! record's own discrete controller ([`controller::Controller`]), advanced exactly over each
//! sample ([`model::Rigid::step`]). The fit starts from the inverse model ([`idim::idim_ls`])
//! and refines by Levenberg–Marquardt on the simulation error ([`fit::fit_drive`]) with the
//! exact Jacobian of the recursion ([`dual`]); it reports standard errors, correlations and
//! the parameter combinations the record leaves undetermined.

pub mod compliant;
pub mod config;
pub mod controller;
pub mod disturbance;
/// The dual numbers the fits carry sensitivities on (hd-model's).
pub use hd_model::dual;
pub mod error;
pub mod filter;
pub mod fit;
pub mod frf;
pub mod identifiability;
pub mod idim;
pub mod lugre;
pub mod model;
pub mod nested;
pub mod record;
pub mod residual_analysis;
pub mod score;
pub mod score_rule;
pub mod setup;
pub mod simulate;

pub use config::DriveConfig;
pub use controller::{Controller, Reproduction, reproduce};
pub use disturbance::{DisturbanceCheck, settle_units};
pub use error::DriveError;
pub use fit::{DriveFit, ExperimentScore, FitSpec, OutputKind, fit_drive, score_all};
pub use idim::{IdimFit, IdimOptions, idim_ls};
pub use lugre::LuGreDrive;
pub use model::{Axis, Drive, FrictionLaw, Motion, Rigid};
pub use record::Experiment;
pub use score::{Score, score};
pub use simulate::{Simulated, simulate};

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_lugre;
#[cfg(test)]
mod tests_open_loop;
