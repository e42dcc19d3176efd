//! Fleet monitoring: many logs of the same test, one per unit and day, reduced to a
//! verdict on which unit's friction is drifting.
//!
//! - [`plateaus`]: the cheap per-log fit a rig runs every shift, the static friction law
//!   from speed plateaus;
//! - [`normalise`]: each parameter regressed on covariates (temperature, load) over a
//!   baseline, the model chosen by BIC among fleet-wide and per-unit ones;
//! - [`cusum`]: Page's two-sided test, its threshold set by a false-alarm probability;
//! - [`drift`]: the two together, per unit and parameter, with the change at the end;
//! - [`synth`]: a synthetic fleet with known temperature effects and wear.

pub mod cusum;
pub mod drift;
pub mod normalise;
pub mod plateaus;
pub mod synth;

pub use drift::{
    DriftOptions, DriftRow, ParameterDrift, UnitDrift, UnitSeries, drift, median_threshold,
    test_unit,
};
pub use normalise::{
    Model, Normalisation, Normalise, Normalised, Reason, Sample, baseline_flags, fit_normalisation,
};
pub use plateaus::{PlateauFit, PlateauOptions, fit_plateaus};

use crate::error::FitError;
use thiserror::Error;

/// Why one log of a fleet could not be fitted.
#[derive(Debug, Error)]
pub enum FleetError {
    /// The fit itself failed.
    #[error(transparent)]
    Fit(#[from] FitError),
    /// The log is not a plateau test.
    #[error("{0}")]
    Plateaus(String),
}
