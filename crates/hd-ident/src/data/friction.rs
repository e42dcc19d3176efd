//! Friction records: a steady-state velocity sweep, or a time series with transients.

use super::check;
use crate::error::DataError;

/// A steady-state sweep: sliding speed `omega` [rad/s] and the friction torque `torque`
/// [N·m] measured once the torque has settled at that speed. Rows need no order; zero
/// speeds are rejected (the steady torque is undefined at rest).
#[derive(Clone, Debug, PartialEq)]
pub struct SteadyData {
    omega: Vec<f64>,
    torque: Vec<f64>,
    load: Option<Vec<f64>>,
}

impl SteadyData {
    /// Check and wrap the columns.
    pub fn new(omega: Vec<f64>, torque: Vec<f64>) -> Result<Self, DataError> {
        if omega.is_empty() {
            return Err(DataError::Empty);
        }
        let n = omega.len();
        check::column("omega", &omega, "omega", n)?;
        check::column("torque", &torque, "omega", n)?;
        if let Some(i) = omega.iter().position(|&w| w == 0.0) {
            return Err(DataError::ZeroSpeed { row: i + 1 });
        }
        check::varies("omega", &omega)?;
        Ok(Self { omega, torque, load: None })
    }

    /// Add the torque the gear transmitted at each row, Tb [N·m], which raises the
    /// friction levels when the load factors μ are fitted (docs/model.md §2.3).
    pub fn with_load(mut self, load: Vec<f64>) -> Result<Self, DataError> {
        check::column("load", &load, "omega", self.omega.len())?;
        self.load = Some(load);
        Ok(self)
    }

    /// Transmitted torque Tb [N·m] per row, when the data carries it.
    pub fn load(&self) -> Option<&[f64]> {
        self.load.as_deref()
    }

    /// Sliding speed [rad/s].
    pub fn omega(&self) -> &[f64] {
        &self.omega
    }
    /// Friction torque [N·m].
    pub fn torque(&self) -> &[f64] {
        &self.torque
    }
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.omega.len()
    }
    /// Whether there are no samples (never true for a constructed data set).
    pub fn is_empty(&self) -> bool {
        self.omega.is_empty()
    }
}

/// A friction time series: time `t` [s], imposed sliding speed `omega` [rad/s] and the
/// friction torque `torque` [N·m]. Between samples the speed is taken as linear in time.
/// The bristle state starts at the first measured torque, held inside the bristles' range.
#[derive(Clone, Debug, PartialEq)]
pub struct TransientData {
    t: Vec<f64>,
    omega: Vec<f64>,
    torque: Vec<f64>,
}

impl TransientData {
    /// Check and wrap the columns: equal lengths, finite values, strictly increasing
    /// time, a speed that varies.
    pub fn new(t: Vec<f64>, omega: Vec<f64>, torque: Vec<f64>) -> Result<Self, DataError> {
        if t.is_empty() {
            return Err(DataError::Empty);
        }
        let n = t.len();
        check::column("t", &t, "t", n)?;
        check::column("omega", &omega, "t", n)?;
        check::column("torque", &torque, "t", n)?;
        check::increasing_time(&t)?;
        check::varies("omega", &omega)?;
        check::varies("torque", &torque)?;
        Ok(Self { t, omega, torque })
    }

    /// Time [s].
    pub fn t(&self) -> &[f64] {
        &self.t
    }
    /// Sliding speed [rad/s].
    pub fn omega(&self) -> &[f64] {
        &self.omega
    }
    /// Friction torque [N·m].
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
}
