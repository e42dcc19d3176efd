//! Measured data sets, validated on construction: equal column lengths, finite values,
//! strictly increasing time; the fits check the sample count against their free
//! parameters with [`require_samples`].

mod check;
mod friction;
mod hysteresis;

pub use check::{SAMPLES_PER_PARAMETER, require_samples};
pub use friction::{SteadyData, TransientData};
pub use hysteresis::HysteresisData;
