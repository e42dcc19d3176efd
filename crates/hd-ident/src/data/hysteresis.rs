//! Torque–deflection records for the hysteresis fit.

use super::check;
use crate::error::DataError;

/// A hysteresis record: time `t` [s], deflection `theta` [rad] and transmitted torque
/// `torque` [N·m], sampled together. The memory state starts from z = 0 at the first
/// sample (docs/model.md §2.1), so a record should begin at rest or be long compared
/// with 1/B.
#[derive(Clone, Debug, PartialEq)]
pub struct HysteresisData {
    t: Vec<f64>,
    theta: Vec<f64>,
    torque: Vec<f64>,
}

impl HysteresisData {
    /// Check and wrap the three columns: equal lengths, finite values, strictly
    /// increasing time, a deflection that varies.
    pub fn new(t: Vec<f64>, theta: Vec<f64>, torque: Vec<f64>) -> Result<Self, DataError> {
        if t.is_empty() {
            return Err(DataError::Empty);
        }
        let n = t.len();
        check::column("t", &t, "t", n)?;
        check::column("theta", &theta, "t", n)?;
        check::column("torque", &torque, "t", n)?;
        check::increasing_time(&t)?;
        check::varies("theta", &theta)?;
        check::varies("torque", &torque)?;
        Ok(Self { t, theta, torque })
    }

    /// Time [s].
    pub fn t(&self) -> &[f64] {
        &self.t
    }
    /// Deflection θ [rad].
    pub fn theta(&self) -> &[f64] {
        &self.theta
    }
    /// Transmitted torque [N·m].
    pub fn torque(&self) -> &[f64] {
        &self.torque
    }
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }
    /// Whether there are no samples (never true for a constructed data set).
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
    /// The columns t, θ, torque, handed back without a copy.
    pub fn into_columns(self) -> [Vec<f64>; 3] {
        [self.t, self.theta, self.torque]
    }
}
