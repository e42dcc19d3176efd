//! The compliant drive as one generic assembly: its parameter vector ([`params`]) and its
//! rates ([`model`]), written once over [`crate::dual::Scalar`], so plain runs (`f64`) and
//! runs that carry exact sensitivities to the parameters (dual numbers) evaluate the same
//! code. Its fixed-step integration is [`crate::solver::fixed_step`].

pub mod bridge;
pub mod model;
pub mod params;
pub mod supported;

pub use bridge::{FixedDrive, fixed_drive};
pub use model::{Compliant, State};
